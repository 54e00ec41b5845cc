"""The demo session: a synthetic recording made once in the user's cache folder."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

from speechcal_core.errors import SpeechCalError
from speechcal_core.synth.options import SynthOptions


class DemoFolderError(SpeechCalError):
    """The demo's folder holds something else; nothing was changed."""


DEMO_OPTIONS = SynthOptions(cameras=4, fisheye=1, duration=45.0, seed=7, claps=2)


def default_demo_dir() -> Path:
    """``$XDG_CACHE_HOME/speechcal/demo`` (``~/.cache/speechcal/demo`` by default)."""
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(cache) / "speechcal" / "demo"


def ensure_demo_session(
    workdir: str | Path | None = None,
    progress: Callable[[str, float], None] | None = None,
) -> tuple[str, str]:
    """Make the demo session unless it exists; return its recording and audio paths.

    A complete earlier demo (and the review work saved beside it) is reused.
    """
    from speechcal_core.synth.session import generate_session

    folder = Path(workdir) if workdir else default_demo_dir()
    truth_path = folder / "truth.json"
    if not truth_path.exists():
        check_demo_folder(folder)
        report = progress or (lambda _t, _f: None)
        generate_session(folder, DEMO_OPTIONS, force=folder.exists(),
                         progress=lambda stage, f: report(f"making the demo session: {stage}",
                                                          0.5 * f))
    truth = json.loads(truth_path.read_text(encoding="utf-8"))
    return str(folder / truth["recording"]), str(folder / truth["audio"])


def check_demo_folder(folder: Path) -> None:
    """Refuse a folder that holds anything but an earlier demo: making the demo replaces
    the folder, and it may be the user's (``--workdir .``). Raises DemoFolderError."""
    if (folder / "truth.json").exists():
        return
    if folder.exists() and not folder.is_dir():
        raise DemoFolderError(f"{folder} is a file, not a folder; give --workdir a new or "
                              f"empty folder")
    if folder.is_dir() and any(folder.iterdir()):
        raise DemoFolderError(
            f"{folder} is not empty and holds no demo session (no truth.json); the demo "
            f"would replace it. Give --workdir a new or empty folder")
