"""An export asked for while another session opens belongs to the session it was asked
for: the export dialog (or its replace prompt) still open when the other session is
shown is closed unanswered, writes nothing, and says why."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from app.main_window import ReviewWindow

NOT_WRITTEN = "Export not written: another session was opened"


def _opened(qtbot, win: ReviewWindow, path: Path) -> None:
    qtbot.waitUntil(lambda: win.inputs is not None and win.inputs.session_path == path,
                    timeout=30_000)


def test_an_export_dialog_open_when_another_session_opens_is_closed_unanswered(
        qtbot, open_window, truth_session_file: Path, searched_session_file: Path,
        tmp_path: Path) -> None:
    win = open_window(truth_session_file)
    qtbot.keyClick(win, Qt.Key.Key_A)  # one accepted set in this session
    win.open(session_path=str(searched_session_file))  # a minute for a recording
    win.exporter.choose()  # meanwhile: export the session shown
    dialog = win.exporter.dialog
    assert dialog is not None and dialog.isVisible()
    out = tmp_path / "first-session-export"
    dialog.set_format("folders")
    dialog.set_folder(out)
    _opened(qtbot, win, searched_session_file)
    # its "1 frame set will be written" was the first session's: its OK exported the
    # other session's sets into the folder chosen for the first
    assert not dialog.isVisible()
    qtbot.wait(200)
    assert win.exporter.task is None and not out.exists()
    assert win.status_text.text().startswith(NOT_WRITTEN)


def test_a_replace_prompt_open_when_another_session_opens_is_closed_unanswered(
        qtbot, open_window, truth_session_file: Path, searched_session_file: Path,
        tmp_path: Path) -> None:
    win = open_window(truth_session_file)
    qtbot.keyClick(win, Qt.Key.Key_A)
    out = tmp_path / "folders"
    for _ in range(2):  # an export, then the same folder again: replace it?
        win.exporter.choose()
        dialog = win.exporter.dialog
        dialog.set_format("folders")
        dialog.set_folder(out)
        qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                         Qt.MouseButton.LeftButton)
        qtbot.waitUntil(lambda: win.exporter.task is None, timeout=30_000)
    box = win.exporter.replace_box
    assert box is not None and box.isVisible()
    earlier = (out / "manifest.json").read_text()
    win.open(session_path=str(searched_session_file))
    _opened(qtbot, win, searched_session_file)
    assert not box.isVisible()
    qtbot.wait(200)
    assert win.exporter.task is None and (out / "manifest.json").read_text() == earlier
    assert win.status_text.text().startswith(NOT_WRITTEN)
