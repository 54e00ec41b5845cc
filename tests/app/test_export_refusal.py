"""Exporting into what the export reads (the session's recording, audio, session file or
a folder holding them) is refused before any question about replacing it."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from app.main_window import ReviewWindow


def _inputs(win: ReviewWindow) -> dict[str, Path]:
    """The open session's recording, audio and session file, and the session's folder."""
    session = win.model.session
    session_file = Path(win.inputs.session_path)
    return {"recording": Path(session.recording[0]), "audio": Path(session.audio),
            "session file": session_file, "session folder": session_file.parent}


def test_the_dialog_refuses_the_sessions_inputs_and_their_folders(
        qtbot, window: ReviewWindow) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    ok = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
    for what, out in _inputs(window).items():
        dialog.set_folder(out)
        text = dialog.summary.text()
        assert text.startswith("Cannot export there:"), what
        assert "which the export reads" in text and "replaced" not in text, what
        assert not ok.isEnabled(), what
    dialog.set_folder(_inputs(window)["session folder"] / "new-export")
    assert ok.isEnabled() and "will be written to a new folder" in dialog.summary.text()
    dialog.reject()


def test_starting_an_export_into_an_input_refuses_without_asking_to_replace(
        qtbot, window: ReviewWindow) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the autosave's temporary file gone
    for what, out in _inputs(window).items():
        before = sorted(p.name for p in out.parent.iterdir())
        window.exporter.start("folders", out)
        assert window.exporter.replace_box is None, what
        assert window.exporter.task is None and not window.exporter.busy(), what
        text = window.status_text.text()
        assert text.startswith("Export not written:") and "which the export reads" in text, what
        assert "which the export reads" in window.exporter.last_error, what
        assert sorted(p.name for p in out.parent.iterdir()) == before, what
    assert window.export_button.isEnabled()
