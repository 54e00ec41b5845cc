"""The wheel: built from this checkout, installed on its own, it runs with its resources."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("dist")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                    "--quiet", "-w", str(out), str(ROOT)], check=True)
    (built,) = out.glob("speechcal-*.whl")
    return built


def test_the_wheel_holds_both_packages_the_resources_and_the_command(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "speechcal_core/cli/__init__.py" in names
    assert "app/main_window.py" in names
    assert "speechcal_core/_resources/voices/index.json" in names
    assert "speechcal_core/_resources/icons/speechcal.svg" in names  # the window's icon
    index = json.loads(zipfile.ZipFile(wheel).read("speechcal_core/_resources/voices/index.json"))
    clips = {f"speechcal_core/_resources/voices/{c['file']}" for c in index["clips"]}
    assert clips <= names, "every clip the index lists is packed"
    (entry_points,) = [n for n in names if n.endswith(".dist-info/entry_points.txt")]
    assert "speechcal = speechcal_core.cli:main" in zipfile.ZipFile(wheel).read(
        entry_points).decode()
    assert not any(n.startswith("tests/") for n in names)


@pytest.mark.slow
def test_the_installed_wheel_makes_a_session_from_its_own_resources(
        wheel: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--quiet",
                    "--target", str(site), str(wheel)], check=True)
    script = (
        "import json, sys\n"
        "import speechcal_core, app.main_window\n"
        "from speechcal_core.resources import resource\n"
        "from speechcal_core.cli import main\n"
        "print(json.dumps([speechcal_core.__file__, app.main_window.__file__,"
        " str(resource('voices'))]))\n"
        "sys.exit(main(['synth', sys.argv[1], '--cameras', '1', '--duration', '12',"
        " '--triggers', '2', '--size', '160x120', '--seed', '3']))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(site), "QT_QPA_PLATFORM": "offscreen"}
    run = subprocess.run([sys.executable, "-c", script, str(tmp_path / "session")],
                         env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    paths = json.loads(run.stdout.splitlines()[0])
    assert all(Path(p).is_relative_to(site) for p in paths), paths
    assert (tmp_path / "session").is_dir() and any((tmp_path / "session").iterdir())
