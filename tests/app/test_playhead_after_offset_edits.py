"""Where the playhead is after an offset edit in the review window. Away from the current
set it stays on the sound it was on, which the edit moved (C puts it on the cameras'
clap): refining the clap with [ ] { } or another C needs no click back on it, as it did
when the playhead jumped back to the set. At the current set it goes with the set."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt

from speechcal_core.review.model import set_time_ns


def _view(window) -> tuple[float, float]:
    x0, x1 = window.waveform.getViewBox().viewRange()[0]
    return x0, x1


def test_c_and_the_nudges_after_it_keep_the_playhead_on_the_clap(qtbot, window) -> None:
    model, wave = window.model, window.waveform
    seen = model.camera_clap_ns()
    heard = seen + 700_000_000  # the real clap, heard later than the sound taken for it
    model.set_playhead(heard)
    qtbot.keyClick(window, Qt.Key.Key_C)
    # the sound named the clap now lies where the cameras saw it, and so does the
    # playhead: on the clap handle, the grid showing the clap's frames
    assert model.playhead_ns == seen
    assert wave.playhead.value() == pytest.approx(wave._to_x(seen), abs=1e-9)
    assert wave.clap.value() == pytest.approx(wave.playhead.value(), abs=1e-6)
    assert "t = " in window.info_line.full_text and "set #" not in window.info_line.full_text
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # the audio a millisecond later
    assert model.playhead_ns == pytest.approx(seen + 1_000_000, abs=1)
    assert wave.clap.value() == pytest.approx(wave.playhead.value(), abs=1e-6)
    frame = window.model.session.sync.offset_ns
    qtbot.keyClick(window, Qt.Key.Key_BraceLeft)  # a frame earlier
    frame -= window.model.session.sync.offset_ns
    assert frame > 10_000_000
    assert model.playhead_ns == pytest.approx(seen + 1_000_000 - frame, abs=2)
    assert wave.clap.value() == pytest.approx(wave.playhead.value(), abs=1e-6)
    for _ in range(2):  # undone, the nudges give the playhead back on the clap ...
        qtbot.keyClick(window, Qt.Key.Key_U)
    assert model.playhead_ns == pytest.approx(seen, abs=2)
    qtbot.keyClick(window, Qt.Key.Key_U)  # ... and C the sound where it was heard
    assert model.playhead_ns == pytest.approx(heard, abs=2)
    assert wave.clap.value() != pytest.approx(wave.playhead.value(), abs=1e-3)


def test_a_nudge_between_sets_leaves_the_playhead_on_its_sound(qtbot, window) -> None:
    model = window.model
    model.go_to_set(1)
    a, b = (set_time_ns(s) for s in model.session.sets[1:3])
    between = (a + b) // 2
    model.set_playhead(between)
    qtbot.keyClick(window, Qt.Key.Key_BracketLeft)  # the audio a millisecond earlier
    assert model.playhead_ns == pytest.approx(between - 1_000_000, abs=1)
    assert model.current == 1 and model.set_at_playhead() is None
    assert window.grid.word_band.text().startswith("between frame sets")


def test_at_the_current_set_a_nudge_takes_the_playhead_with_the_set(qtbot, window) -> None:
    model = window.model
    model.go_to_set(2)
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # the audio a frame later
    assert model.playhead_ns == set_time_ns(model.current_set)
    assert model.set_at_playhead() is model.current_set
    assert window.grid.word == model.current_set.trigger.word


def test_zoomed_in_c_takes_the_view_along_with_the_playhead(qtbot, window) -> None:
    """The real clap seconds from the sound taken for it: the view, zoomed in on the real
    one, follows it to where the cameras saw the clap (it showed neither)."""
    model, wave = window.model, window.waveform
    seen = model.camera_clap_ns()
    heard = seen + 2_500_000_000
    model.set_playhead(heard)
    x = wave._to_x(heard)
    wave.setXRange(x - 0.5, x + 0.5, padding=0)
    qtbot.keyClick(window, Qt.Key.Key_C)
    x0, x1 = _view(window)
    assert x0 < wave.playhead.value() < x1
    assert (wave.playhead.value() - x0) / (x1 - x0) == pytest.approx(0.5, abs=0.01)
    assert x1 - x0 == pytest.approx(1.0, abs=1e-6)  # the zoom kept
