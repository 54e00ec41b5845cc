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
    # asked and answered with nothing: nothing happens
    window.leave_out_action.ask = lambda streams: None
    window.leave_out_action.trigger()
    assert window.model.streams == cameras[:-1]
