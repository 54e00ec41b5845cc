"""The demo never replaces a folder that holds something other than an earlier demo."""

from __future__ import annotations

from pathlib import Path

import pytest

from speechcal_core.cli import main
from speechcal_core.synth.demo import DemoFolderError, ensure_demo_session


def test_a_folder_with_user_files_is_refused_and_kept(tmp_path: Path) -> None:
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("precious")
    with pytest.raises(DemoFolderError, match="not empty") as err:
        ensure_demo_session(folder)
    assert str(folder) in str(err.value)
    assert (folder / "notes.txt").read_text() == "precious"
    assert sorted(p.name for p in folder.iterdir()) == ["notes.txt"]


def test_a_file_given_as_the_folder_is_refused(tmp_path: Path) -> None:
    target = tmp_path / "demo"
    target.write_text("not a folder")
    with pytest.raises(DemoFolderError, match="is a file"):
        ensure_demo_session(target)
    assert target.read_text() == "not a folder"


def test_the_cli_reports_the_refusal_in_one_line(tmp_path: Path,
                                                 capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "recording.bag").write_bytes(b"user data")
    assert main(["demo", "--workdir", str(tmp_path), "--screenshot",
                 str(tmp_path / "x.png")]) == 1
    err = capsys.readouterr().err
    assert "holds no demo session" in err and "Traceback" not in err
    assert "making" not in err  # refused before anything is announced
    assert (tmp_path / "recording.bag").read_bytes() == b"user data"


def test_an_unwritable_screenshot_fails_before_the_demo_is_made(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "file").write_text("not a folder")
    workdir = tmp_path / "demo"
    assert main(["demo", "--workdir", str(workdir), "--screenshot",
                 str(tmp_path / "file" / "x.png")]) == 1
    assert "cannot write the screenshot" in capsys.readouterr().err
    assert not workdir.exists()
