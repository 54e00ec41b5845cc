"""Exporting from the review window: dialog, worker thread, replace prompt, status line."""

from __future__ import annotations

import json
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from app.main_window import ReviewWindow


def test_export_is_disabled_until_a_session_is_open(qtbot) -> None:
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    assert not win.export_button.isEnabled()


def _export_through_dialog(qtbot, win: ReviewWindow, fmt: str, out: Path) -> None:
    qtbot.mouseClick(win.export_button, Qt.MouseButton.LeftButton)
    dialog = win.exporter.dialog
    assert dialog is not None and dialog.isVisible()
    dialog.set_format(fmt)
    dialog.set_folder(out)
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)


def test_export_button_writes_the_accepted_sets_off_the_ui_thread(
    qtbot, window: ReviewWindow, tmp_path: Path
) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)  # accept the first set
    out = tmp_path / "kalibr"
    _export_through_dialog(qtbot, window, "kalibr", out)
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    assert window.exporter.last_error == ""
    assert (out / "target.yaml").exists() and (out / "manifest.json").exists()
    first = window.model.session.sets[0]
    names = {p.name for p in (out / "cam0").iterdir()}
    assert names == {f"{first.t_ns}.png"}
    assert {p.name for p in (out / "cam2").iterdir()} == names
    text = window.status_text.text()
    assert text.startswith("Exported 1 frame set (") and str(out) in text
    # the core's notes reach the status line: this session holds no board of its own
    assert window.exporter.last_result.notes
    assert f"; note: {window.exporter.last_result.notes[0]}" in text
    assert not window.progress.isVisible() and window.export_button.isEnabled()
    window.exporter.choose()  # the next export offers the format chosen before
    assert window.exporter.dialog.format == "kalibr"
    window.exporter.dialog.reject()
    _export_through_dialog(qtbot, window, "folders", tmp_path / "folders")
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    window.exporter.choose()
    assert window.exporter.dialog.format == "folders"
    assert window.exporter.dialog.choice()[1].name.endswith("-folders")
    window.exporter.dialog.reject()


def test_an_earlier_export_is_replaced_after_asking(qtbot, window, tmp_path: Path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "bag"
    _export_through_dialog(qtbot, window, "folders", out)
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    earlier = sorted(p.name for p in out.iterdir())
    _export_through_dialog(qtbot, window, "rosbag1", out)
    box = window.exporter.replace_box
    assert box is not None and box.isVisible() and str(out) in box.text()
    assert window.exporter.task is None and sorted(p.name for p in out.iterdir()) == earlier
    replace = next(b for b in box.buttons() if b.text() == "Replace")
    qtbot.mouseClick(replace, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: (out / "calibration.bag").exists(), timeout=30_000)
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    assert not (out / "cam0_image_raw").exists()
    assert json.loads((out / "manifest.json").read_text())["format"] == "rosbag1"


def test_a_folder_of_other_files_is_refused_without_asking(qtbot, window, tmp_path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "data"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    dialog.set_folder(out)
    assert dialog.summary.text().startswith("Cannot export there:")
    assert "not an export (notes.txt)" in dialog.summary.text()
    assert not dialog.buttons.button(QDialogButtonBox.StandardButton.Ok).isEnabled()
    dialog.reject()
    window.exporter.start("folders", out)
    assert window.exporter.replace_box is None and window.exporter.task is None
    assert "not an export (notes.txt)" in window.status_text.text()
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_declining_the_replace_keeps_the_folder(qtbot, window, tmp_path: Path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "kept"
    out.mkdir()
    window.exporter.start("folders", out)
    box = window.exporter.replace_box
    qtbot.mouseClick(box.button(box.StandardButton.Cancel), Qt.MouseButton.LeftButton)
    assert [p.name for p in out.iterdir()] == []
    assert "already exists" in window.status_text.text()


def test_without_accepted_sets_the_dialog_says_to_accept_first(qtbot, window) -> None:
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    assert not dialog.buttons.button(QDialogButtonBox.StandardButton.Ok).isEnabled()
    assert "accept sets" in dialog.summary.text()
    dialog.undecided_box.setChecked(True)
    assert dialog.buttons.button(QDialogButtonBox.StandardButton.Ok).isEnabled()
    dialog.reject()


def test_a_failed_export_is_shown_in_the_status_line(qtbot, window, tmp_path: Path) -> None:
    window.exporter.start("kalibr", tmp_path / "none")  # nothing accepted
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    assert "no accepted frame sets" in window.exporter.last_error
    assert window.status_text.text().startswith("Export failed:")
    assert not (tmp_path / "none").exists()


def test_a_folder_under_a_file_is_refused_in_the_dialog(qtbot, window, tmp_path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    (tmp_path / "notes.txt").write_text("mine")
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    dialog.set_folder(tmp_path / "notes.txt" / "export")
    text = dialog.summary.text()
    assert text.startswith("Cannot export there: cannot write there")
    assert f"{tmp_path / 'notes.txt'} is a file, not a folder" in text
    assert not dialog.buttons.button(QDialogButtonBox.StandardButton.Ok).isEnabled()
    dialog.reject()


def test_declining_the_replace_goes_back_to_the_dialog_with_its_choices(
        qtbot, window, tmp_path: Path) -> None:
    """No to "Replace it?" closed the dialog: format, folder and the undecided box had to
    be chosen again to write anywhere else."""
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "earlier"
    out.mkdir()
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    dialog.set_format("folders")
    dialog.set_folder(out)
    dialog.undecided_box.setChecked(True)
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)
    box = window.exporter.replace_box
    qtbot.mouseClick(box.button(box.StandardButton.Cancel), Qt.MouseButton.LeftButton)
    assert "already exists" in window.status_text.text()
    assert window.exporter.dialog is dialog and dialog.isVisible()
    assert dialog.choice()[:3] == ("folders", out, True)
    assert dialog.focusWidget() is dialog.path_edit  # selected, to type another name
    assert dialog.path_edit.selectedText() == str(out)
    other = tmp_path / "other"
    dialog.set_folder(other)
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.exporter.task is None and (other / "manifest.json").exists(),
                    timeout=30_000)
    assert [p.name for p in out.iterdir()] == []
    window.exporter.start("folders", other)  # asked outside the dialog: no dialog again
    box = window.exporter.replace_box
    qtbot.mouseClick(box.button(box.StandardButton.Cancel), Qt.MouseButton.LeftButton)
    assert not dialog.isVisible()


def test_a_folder_typed_without_its_path_lies_beside_the_session(
        qtbot, window, truth_session_file: Path, tmp_path: Path, monkeypatch) -> None:
    """The dialog offers a folder beside the session; a name typed in its place went to
    the program's working folder, wherever the window was started from."""
    elsewhere = tmp_path / "started_here"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    dialog.set_format("folders")
    dialog.path_edit.clear()
    qtbot.keyClicks(dialog.path_edit, "calib out")
    beside = truth_session_file.parent / "calib out"
    assert dialog.choice()[1] == beside
    assert dialog.summary.text().endswith(f"to a new folder, {beside}")
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    assert (beside / "manifest.json").exists()
    assert list(elsewhere.iterdir()) == []


def test_a_session_opened_by_a_relative_path_offers_its_folder_whole(
        qtbot, open_window, truth_session_file: Path, monkeypatch) -> None:
    """``speechcal review session.json`` from the session's folder: the dialog offered
    "session-kalibr" and said the sets go "to a new folder, session-kalibr", never where
    that is."""
    monkeypatch.chdir(truth_session_file.parent)
    window = open_window(Path(truth_session_file.name))
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    dialog = window.exporter.dialog
    dialog.set_format("kalibr")
    offered = Path(dialog.path_edit.text())
    assert offered.is_absolute()
    assert offered == truth_session_file.parent.absolute() / \
        f"{truth_session_file.name.split('.')[0]}-kalibr"
    assert dialog.summary.text() == "1 frame set will be written to a new folder"
    dialog.reject()
