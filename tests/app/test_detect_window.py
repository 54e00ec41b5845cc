"""Find trigger words in the window (Edit ▸ Find trigger words…, Ctrl+F): a session
detected with the wrong word gets its sets from the word the operator types, found off
the UI thread; a word the detector cannot look for keeps the dialog open and says why."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox


def _find(qtbot, dialog, text: str) -> None:
    dialog.words_edit.setText(text)
    qtbot.mouseClick(dialog.buttons.button(QDialogButtonBox.StandardButton.Ok),
                     Qt.MouseButton.LeftButton)


def test_the_word_typed_fills_the_empty_list(qtbot, open_window,
                                             wrong_word_session_file: Path) -> None:
    window = open_window(wrong_word_session_file)
    assert window.table.model().rowCount() == 0
    assert "Edit ▸ Find trigger words… (Ctrl+F) looks for it" in window.no_sets_label.text()
    assert window.detect_action.isEnabled()
    qtbot.keyClick(window, Qt.Key.Key_F, Qt.KeyboardModifier.ControlModifier)
    dialog = window.detector.dialog
    assert dialog is not None and dialog.isVisible()
    assert dialog.words_edit.text() == "capture" and dialog.sensitivity == 0.5
    assert dialog.words_edit.selectedText() == "capture"  # typing replaces it

    _find(qtbot, dialog, "snapshot, kalibrr")  # a word the dictionary lacks
    assert dialog.isVisible() and dialog.problem.isVisible()
    assert "“kalibrr” is not in the pocketsphinx dictionary" in dialog.problem.text()
    assert not window.detector.busy()

    dialog.slider.setValue(60)
    assert dialog.value_label.text() == "0.60"
    _find(qtbot, dialog, "Snapshot!")
    assert not dialog.isVisible()
    assert window.status.running("detect")
    qtbot.waitUntil(lambda: window.detector.last is not None, timeout=60_000)

    result, added = window.detector.last
    assert window.table.model().rowCount() == len(added) >= 2
    assert not window.no_sets_label.isVisible()
    # the line under the grid counts the new sets
    qtbot.waitUntil(lambda: f"/{len(added)}) · skew" in window.info_line.full_text,
                    timeout=5_000)
    assert f"found {len(result.words)} × “snapshot” at sensitivity 0.60: " \
        f"{len(added)} new undecided sets" in window.status_text.text()
    window.detect_action.trigger()  # the next search starts from this one's settings
    assert window.detector.dialog.words_edit.text() == "snapshot, capture"
    assert window.detector.dialog.sensitivity == 0.6
    window.detector.dialog.reject()
    window.run_action("undo")  # one undo takes them all back
    assert window.table.model().rowCount() == 0


def test_a_detection_can_be_cancelled(qtbot, open_window,
                                      wrong_word_session_file: Path) -> None:
    from speechcal_core.review.detect_again import detect_request

    window = open_window(wrong_word_session_file)
    window.detector.start(detect_request(window.model.session, "snapshot", 0.5))
    window.cancel_task()
    qtbot.waitUntil(lambda: not window.detector.busy(), timeout=60_000)
    assert "finding trigger words cancelled" in window.status_text.text()
    assert window.table.model().rowCount() == 0 and window.detector.last is None


def test_a_dialog_left_open_closes_when_another_session_opens(
        qtbot, open_window, wrong_word_session_file: Path, truth_session_file: Path) -> None:
    """Its words were for the other session's audio: they never land in this one."""
    from speechcal_core.review.detect_again import detect_request

    window = open_window(wrong_word_session_file)
    window.detect_action.trigger()
    assert window.detector.dialog.isVisible()
    first = window.model
    stale = detect_request(first.session, "snapshot", 0.5)  # what the dialog would start
    window.open(session_path=str(truth_session_file))
    qtbot.waitUntil(lambda: window.model is not first, timeout=30_000)
    assert window.detector.dialog is None  # closed with the session it was for
    sets = [s.id for s in window.model.session.sets]
    window.detector.start(stale)
    assert not window.detector.busy()  # another session's audio: refused
    assert [s.id for s in window.model.session.sets] == sets
