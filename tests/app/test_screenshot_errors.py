"""``speechcal review --screenshot`` to a place it cannot write: one line, no traceback."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtWidgets import QLabel

from app.main import ScreenshotError, save_screenshot
from speechcal_core.cli import main


def test_unwritable_screenshot_is_one_line_naming_the_path(
    truth_session_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "file").write_text("not a folder")
    shot = tmp_path / "file" / "x.png"
    code = main(["review", str(truth_session_file), "--screenshot", str(shot)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1 and err[0].startswith("speechcal review: error: ")
    assert str(shot) in err[0] and "writable" in err[0]


def test_screenshot_that_cannot_be_written_raises_the_cli_error(qtbot, tmp_path: Path) -> None:
    widget = QLabel("shot")
    qtbot.addWidget(widget)
    shot = tmp_path / "folder.png"
    shot.mkdir()
    with pytest.raises(ScreenshotError, match="cannot write the screenshot"):
        save_screenshot(widget, str(shot))
    good = tmp_path / "sub" / "ok.png"
    save_screenshot(widget, str(good))
    assert good.read_bytes()[:4] == b"\x89PNG"


def test_session_that_fails_to_open_writes_no_screenshot(
    truth_session_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A screenshot of the first page saying "Could not open" is no picture of the session:
    no PNG, the error on stderr, exit 1 (a script must not take the file for success)."""
    damaged = tmp_path / "damaged.json"
    damaged.write_text(truth_session_file.read_text()[:-40])  # cut short: not valid JSON
    shot = tmp_path / "x.png"
    code = main(["review", str(damaged), "--screenshot", str(shot)])
    err = capsys.readouterr().err
    assert code == 1
    assert not shot.exists()
    assert f"speechcal review: error: {damaged}: not valid JSON" in err
    assert "wrote" not in err
