"""The export dialog shows its whole summary, however long the notes under it grow."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtWidgets import QLabel

from app.export_dialog import ExportDialog


def _text_fits(label: QLabel) -> bool:
    """Whether every line of the label's text is drawn whole (none cut at its edge)."""
    area = label.contentsRect()
    if label.wordWrap():
        return label.heightForWidth(area.width()) <= area.height()
    metrics = label.fontMetrics()
    return (all(metrics.horizontalAdvance(line) <= area.width()
                for line in label.text().splitlines())
            and metrics.lineSpacing() * len(label.text().splitlines()) <= area.height())


@pytest.mark.parametrize("waiting", [0, 1])
def test_the_summary_is_readable_when_the_folder_exists(
        qtbot, tmp_path: Path, waiting: int) -> None:
    (tmp_path / "rec-kalibr").mkdir()
    dialog = ExportDialog(None, tmp_path, "rec", {"accepted": 1, "undecided": 13},
                          waiting=lambda _include: waiting)
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    dialog.set_folder(tmp_path / "rec-kalibr")  # the longest note: asked to replace it
    assert "asked before it is replaced" in dialog.summary.text()
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)  # laid out anew
    assert dialog.rect().contains(dialog.summary.geometry())
    dialog.undecided_box.setChecked(True)
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)
    dialog.resize(dialog.minimumWidth(), dialog.height())  # as narrow as it goes
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)
    assert dialog.rect().contains(dialog.summary.geometry())


def test_the_folder_checked_is_the_folder_written(qtbot, tmp_path: Path) -> None:
    dialog = ExportDialog(None, tmp_path, "rec", {"accepted": 1, "undecided": 0})
    qtbot.addWidget(dialog)
    dialog.path_edit.setText(f"  {tmp_path / 'out'} ")  # pasted with spaces around it
    assert dialog.choice()[1] == tmp_path / "out"


def test_one_set_is_one_set(qtbot, tmp_path: Path) -> None:
    dialog = ExportDialog(None, tmp_path, "rec", {"accepted": 1, "undecided": 0})
    qtbot.addWidget(dialog)
    assert dialog.summary.text().startswith("1 frame set will be written")


def _shown_refusing_data(qtbot, tmp_path: Path, repeats: int,
                         counts: dict[str, int]) -> ExportDialog:
    """The dialog on screen, refusing a folder named "data" with a reason of ``repeats``
    sentences, and that folder chosen."""
    long_reason = ("this folder holds files that are not an export (.bashrc, .cache, "
                   ".cargo, …); choose another output folder or empty it") * repeats
    dialog = ExportDialog(None, tmp_path, "rec", counts,
                          refusal=lambda out, _board: long_reason if out.name == "data" else "")
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    dialog.set_folder(tmp_path / "data")
    return dialog


def test_a_long_refusal_grows_the_dialog_and_squashes_no_field(qtbot, tmp_path: Path) -> None:
    dialog = _shown_refusing_data(qtbot, tmp_path, 2, {"accepted": 3, "undecided": 0})
    assert dialog.summary.text().startswith("Cannot export there:")
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)
    for field in (dialog.format_box, dialog.path_edit, dialog.undecided_box):
        assert field.height() >= field.sizeHint().height(), field
    assert dialog.rect().contains(dialog.summary.geometry())


def test_undecided_sets_are_offered_only_when_there_are_some(qtbot, tmp_path: Path) -> None:
    none = ExportDialog(None, tmp_path, "rec", {"accepted": 2, "undecided": 0})
    qtbot.addWidget(none)
    assert not none.undecided_box.isVisibleTo(none)  # not "also the 0 undecided sets"
    one = ExportDialog(None, tmp_path, "rec", {"accepted": 2, "undecided": 1})
    qtbot.addWidget(one)
    assert one.undecided_box.isVisibleTo(one)
    assert one.undecided_box.text() == "also the 1 undecided set"


def _needed_height(dialog: ExportDialog) -> int:
    layout = dialog.layout()
    return layout.totalHeightForWidth(dialog.width()) if layout.hasHeightForWidth() \
        else layout.totalSizeHint().height()


def test_a_shorter_summary_leaves_no_gap_where_its_lines_were(qtbot, tmp_path: Path) -> None:
    dialog = _shown_refusing_data(qtbot, tmp_path, 3, {"accepted": 2, "undecided": 13})
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)
    refused_height = dialog.height()
    dialog.set_folder(tmp_path / "fine")  # one line of summary again: the dialog shrinks
    qtbot.waitUntil(lambda: dialog.height() < refused_height, timeout=2_000)
    assert dialog.height() <= _needed_height(dialog) + 2  # no blank band over the summary
    dialog.set_folder(tmp_path / "data")  # back: room for the reason again
    qtbot.waitUntil(lambda: _text_fits(dialog.summary), timeout=2_000)
    assert dialog.height() >= _needed_height(dialog)
