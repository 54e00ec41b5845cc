"""The export dialog names the board the export describes and takes a measured one from
a Kalibr target file, as ``speechcal export --target`` does."""

from __future__ import annotations

import json
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from app.main_window import ReviewWindow

MEASURED = ("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\ntagSize: 0.0588\n"
            "tagSpacing: 0.3\n")


def _open_dialog(qtbot, win: ReviewWindow, fmt: str, out: Path):
    qtbot.mouseClick(win.export_button, Qt.MouseButton.LeftButton)
    dialog = win.exporter.dialog
    dialog.set_format(fmt)
    dialog.set_folder(out)
    return dialog


def _ok(dialog):
    return dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)


def _export(qtbot, win: ReviewWindow, dialog) -> None:
    qtbot.mouseClick(_ok(dialog), Qt.MouseButton.LeftButton)
    box = win.exporter.replace_box
    if box is not None and box.isVisible():
        replace = next(b for b in box.buttons() if b.text() == "Replace")
        qtbot.mouseClick(replace, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: win.exporter.task is None and not win.exporter.busy(),
                    timeout=30_000)
    assert win.exporter.last_error == ""


def test_the_dialog_says_the_board_is_assumed_and_takes_a_measured_one(
        qtbot, window: ReviewWindow, tmp_path: Path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    measured = tmp_path / "measured.yaml"
    measured.write_text(MEASURED)
    out = tmp_path / "kalibr"
    dialog = _open_dialog(qtbot, window, "kalibr", out)
    assert dialog.board_row.isVisibleTo(dialog)
    assert dialog.board_label.text().startswith("6x6 AprilGrid of 0.055 m tags (assumed")
    dialog.set_target_file(measured)
    assert dialog.board_label.text() == f"6x6 AprilGrid of 0.0588 m tags (from {measured})"
    _export(qtbot, window, dialog)
    assert "tagSize: 0.0588" in (out / "target.yaml").read_text()
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["target"]["size"] == 0.0588 and manifest["target"]["from"] == "given"
    assert not any("assumes" in note for note in window.exporter.last_result.notes)


def test_an_edited_target_yaml_is_refused_until_it_is_chosen_as_the_board(
        qtbot, window: ReviewWindow, tmp_path: Path) -> None:
    """The refusal says what to do in the window, and doing it exports for that board."""
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "kalibr"
    _export(qtbot, window, _open_dialog(qtbot, window, "kalibr", out))
    target = out / "target.yaml"
    target.write_text(target.read_text().replace("tagSize: 0.055", "tagSize: 0.0588"))

    dialog = _open_dialog(qtbot, window, "kalibr", out)
    text = dialog.summary.text()
    assert text.startswith("Cannot export there: its target.yaml was changed")
    assert "Target file… in the window's export dialog" in text and not _ok(dialog).isEnabled()
    dialog.set_target_file(target)
    assert _ok(dialog).isEnabled() and "will be written to the folder above" in \
        dialog.summary.text()
    _export(qtbot, window, dialog)
    assert "tagSize: 0.0588" in target.read_text()
    assert json.loads((out / "manifest.json").read_text())["target"]["size"] == 0.0588


def test_an_unreadable_target_file_keeps_the_board_and_blocks_the_export(
        qtbot, window: ReviewWindow, tmp_path: Path) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    broken = tmp_path / "broken.yaml"
    broken.write_text("target_type: 'aprilgrid'\ntagCols: 6\n")
    dialog = _open_dialog(qtbot, window, "folders", tmp_path / "out")
    before = dialog.board_label.text()
    dialog.set_target_file(broken)
    assert dialog.board_label.text() == before
    assert dialog.summary.text().startswith(f"Cannot use that target file: {broken}: ")
    assert not _ok(dialog).isEnabled()
    assert dialog.choice()[3] is None
    dialog.set_format("rosbag1")  # a bag's target.yaml describes the board too
    assert dialog.board_row.isVisibleTo(dialog) and not _ok(dialog).isEnabled()
    dialog.reject()
