"""Edit ▸ Leave a camera out…: a camera taken out of the session opened, from the window."""

from __future__ import annotations

from pathlib import Path

from speechcal_core.session.store import load_session


def test_a_camera_left_out_from_the_window_goes_and_the_decisions_stay(
        open_window, truth_session_file: Path, qtbot) -> None:
    window = open_window(truth_session_file)
    assert window.leave_out_action.isEnabled()
    cameras = list(window.model.streams)
    window.model.decide("rejected")
    decided = {s.id: s.decision for s in window.model.session.sets}
    window.leave_out_action.ask = lambda streams: streams[-1]
    window.leave_out_action.trigger()
    qtbot.waitUntil(lambda: window.model is not None
                    and window.model.streams == cameras[:-1], timeout=30_000)
    assert sorted(window.grid.tiles) == sorted(cameras[:-1])
    assert f"left out {cameras[-1]}" in window.status_text.text()
    session = load_session(truth_session_file)
    assert session.extra["streams"] == cameras[:-1]
    assert {s.id: s.decision for s in session.sets} == decided
    # the decision made before is still taken back by Ctrl+Z
    assert "undo steps were dropped" not in window.status_text.text()
    rejected = next(i for i, d in decided.items() if d == "rejected")
    assert window.model.undo_label == f"decision on set {rejected}"
    window.model.undo()
    assert window.model.session.set_by_id(rejected).decision == "undecided"
    # asked and answered with nothing: nothing happens
    window.leave_out_action.ask = lambda streams: None
    window.leave_out_action.trigger()
    assert window.model.streams == cameras[:-1]


def test_a_camera_left_out_keeps_the_set_and_filter_the_review_was_at(
        open_window, truth_session_file: Path, qtbot) -> None:
    """Moving about saves nothing, so the session opened again without the camera went
    back to the set of the last decision (or the first), and to its filter."""
    from PySide6.QtCore import Qt

    window = open_window(truth_session_file)
    cameras = list(window.model.streams)
    qtbot.keyClick(window, Qt.Key.Key_K)
    qtbot.keyClick(window, Qt.Key.Key_K)
    qtbot.keyClick(window, Qt.Key.Key_F)  # undecided: every set still
    here = window.model.current_set.id
    window.leave_out_action.ask = lambda streams: streams[-1]
    window.leave_out_action.trigger()
    qtbot.waitUntil(lambda: window.model is not None
                    and window.model.streams == cameras[:-1], timeout=30_000)
    assert window.model.current_set.id == here and window.model.filter == "undecided"
    assert f"set #{here} (3/" in window.info_line.full_text
