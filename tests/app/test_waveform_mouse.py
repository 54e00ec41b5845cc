"""The waveform under a real mouse: press, move and release as the operator's hand does
(pyqtgraph picks the item to drag by what lies under the pointer, so signals emitted by
hand would not show which line a drag grabs)."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent, QWheelEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from app.offset_text import clap_drag_text, shift_text
from app.waveform import MIN_SPAN_S, WaveformView
from speechcal_core.session.store import load_session, save_session


def _point(wave: WaveformView, x: float, y: float = 0.0) -> QPointF:
    """Viewport pixel of the view point (``x`` seconds, ``y`` level)."""
    scene = wave.getViewBox().mapViewToScene(QPointF(x, y))
    return QPointF(wave.mapFromScene(scene))


def _send(wave: WaveformView, kind: QEvent.Type, pos: QPointF,
          buttons: Qt.MouseButton = Qt.MouseButton.NoButton) -> None:
    viewport = wave.viewport()
    button = (Qt.MouseButton.LeftButton
              if kind in (QEvent.Type.MouseButtonPress, QEvent.Type.MouseButtonRelease,
                          QEvent.Type.MouseButtonDblClick)
              else Qt.MouseButton.NoButton)
    event = QMouseEvent(kind, pos, QPointF(viewport.mapToGlobal(pos.toPoint())), button,
                        buttons, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(viewport, event)
    if kind == QEvent.Type.MouseMove:
        QTest.qWait(15)  # pyqtgraph drops moves closer together than its rate limit


def click(qtbot, wave: WaveformView, x: float, y: float = 0.0) -> None:
    """Move to (x, y) and click the left button there."""
    pos = _point(wave, x, y)
    _send(wave, QEvent.Type.MouseMove, pos)
    _send(wave, QEvent.Type.MouseButtonPress, pos, Qt.MouseButton.LeftButton)
    _send(wave, QEvent.Type.MouseButtonRelease, pos)
    qtbot.wait(10)


def double_click(qtbot, wave: WaveformView, x: float, y: float = 0.0) -> None:
    """Two clicks in quick succession at (x, y), as Qt delivers a double-click."""
    pos = _point(wave, x, y)
    _send(wave, QEvent.Type.MouseMove, pos)
    _send(wave, QEvent.Type.MouseButtonPress, pos, Qt.MouseButton.LeftButton)
    _send(wave, QEvent.Type.MouseButtonRelease, pos)
    _send(wave, QEvent.Type.MouseButtonDblClick, pos, Qt.MouseButton.LeftButton)
    _send(wave, QEvent.Type.MouseButtonRelease, pos)
    qtbot.wait(10)


def drag(qtbot, wave: WaveformView, x0: float, x1: float, y: float = 0.0,
         steps: int = 10) -> None:
    """Press at ``x0``, move in steps to ``x1`` with the button held, release there."""
    p0, p1 = _point(wave, x0, y), _point(wave, x1, y)
    _send(wave, QEvent.Type.MouseMove, p0)
    _send(wave, QEvent.Type.MouseButtonPress, p0, Qt.MouseButton.LeftButton)
    for k in range(1, steps + 1):
        _send(wave, QEvent.Type.MouseMove, p0 + (p1 - p0) * (k / steps),
              Qt.MouseButton.LeftButton)
    _send(wave, QEvent.Type.MouseButtonRelease, p1)
    qtbot.wait(10)


def wheel(qtbot, wave: WaveformView, x: float, steps: int) -> None:
    """Turn the wheel ``steps`` notches at ``x`` (positive: zoom in)."""
    pos = _point(wave, x)
    viewport = wave.viewport()
    for _ in range(abs(steps)):
        event = QWheelEvent(pos, QPointF(viewport.mapToGlobal(pos.toPoint())), QPoint(0, 0),
                            QPoint(0, 120 if steps > 0 else -120), Qt.MouseButton.NoButton,
                            Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase,
                            False)
        QApplication.sendEvent(viewport, event)
    qtbot.wait(10)


def _view(wave: WaveformView) -> tuple[float, float]:
    x0, x1 = wave.getViewBox().viewRange()[0]
    return x0, x1


def test_the_clap_handle_is_dragged_when_the_playhead_sits_on_it(window, qtbot) -> None:
    wave = window.waveform
    clap_x = wave.clap.value()
    wave.setXRange(clap_x - 2, clap_x + 2, padding=0)
    offset = window.model.session.sync.offset_ns
    click(qtbot, wave, clap_x)  # to listen from the clap: the playhead lands on it
    assert abs(wave.playhead.value() - clap_x) < 0.01
    drag(qtbot, wave, wave.playhead.value(), clap_x + 0.2)
    shift_ns = window.model.session.sync.offset_ns - offset
    assert abs(shift_ns - 200_000_000) < 10_000_000  # the clap moved, not the playhead
    assert abs(wave.clap.value() - (clap_x + 0.2)) < 0.01


def test_a_playhead_on_the_clap_rides_with_the_handle_and_stays_on_it(window, qtbot) -> None:
    """Put on the clap to refine the offset, the playhead goes with the sound under it:
    while the handle is dragged (the grid shows the frames the clap would land on) and
    once it is released; it jumped to the current set, far from the clap."""
    wave, model = window.waveform, window.model
    clap_x = wave.clap.value()
    wave.setXRange(clap_x - 2, clap_x + 2, padding=0)
    click(qtbot, wave, clap_x)
    on_clap = wave.playhead.value() - clap_x  # within a pixel
    p0, p1 = _point(wave, wave.playhead.value()), _point(wave, clap_x + 0.3)
    _send(wave, QEvent.Type.MouseMove, p0)
    _send(wave, QEvent.Type.MouseButtonPress, p0, Qt.MouseButton.LeftButton)
    for k in range(1, 6):
        _send(wave, QEvent.Type.MouseMove, p0 + (p1 - p0) * (k / 5), Qt.MouseButton.LeftButton)
    assert wave.clap.value() == pytest.approx(clap_x + 0.3, abs=0.01)
    assert wave.playhead.value() - wave.clap.value() == pytest.approx(on_clap, abs=1e-6)
    assert not any(tile.caption == "chosen frame" for tile in window.grid.tiles.values())
    _send(wave, QEvent.Type.MouseButtonRelease, p1)
    qtbot.wait(10)
    assert wave.playhead.value() - wave.clap.value() == pytest.approx(on_clap, abs=1e-6)
    assert model.set_at_playhead() is None  # the sets lie seconds away


def _right_click(wave: WaveformView, pos: QPointF) -> None:
    """The right button pressed and released at ``pos`` with the left one held."""
    viewport = wave.viewport()
    for kind, held in ((QEvent.Type.MouseButtonPress,
                        Qt.MouseButton.LeftButton | Qt.MouseButton.RightButton),
                       (QEvent.Type.MouseButtonRelease, Qt.MouseButton.LeftButton)):
        QApplication.sendEvent(viewport, QMouseEvent(
            kind, pos, QPointF(viewport.mapToGlobal(pos.toPoint())),
            Qt.MouseButton.RightButton, held, Qt.KeyboardModifier.NoModifier))


def test_while_the_clap_handle_is_dragged_the_word_band_says_how_far_the_audio_moves(
        window, qtbot) -> None:
    """It said "between frame sets": the preview puts the playhead off the sets' times.
    A right-click cancels the drag, as the band says, and gives the word back."""
    wave, model = window.waveform, window.model
    band = window.grid.word_band
    word = band.text()
    assert "CAPTURE" in word
    clap_x = wave.clap.value()
    wave.setXRange(clap_x - 2, clap_x + 2, padding=0)
    offset, playhead = model.session.sync.offset_ns, model.playhead_ns
    p0, p1 = _point(wave, clap_x), _point(wave, clap_x + 0.3)
    _send(wave, QEvent.Type.MouseMove, p0)
    _send(wave, QEvent.Type.MouseButtonPress, p0, Qt.MouseButton.LeftButton)
    for k in range(1, 6):
        _send(wave, QEvent.Type.MouseMove, p0 + (p1 - p0) * (k / 5), Qt.MouseButton.LeftButton)
        assert band.text() == clap_drag_text(wave.clap_shift_ns())
    assert band.text().startswith("◂ clap ▸ audio +3") and "between" not in band.text()
    _right_click(wave, p1)
    qtbot.wait(10)
    assert band.text() == word and wave.clap.value() == clap_x
    assert (model.session.sync.offset_ns, model.playhead_ns) == (offset, playhead)
    _send(wave, QEvent.Type.MouseButtonRelease, p1)
    drag(qtbot, wave, clap_x, clap_x + 0.3)  # released: the word of the set, moved
    assert model.session.sync.offset_ns != offset and band.text() == word


def test_a_clap_handle_drag_says_how_far_the_audio_moved(window, qtbot) -> None:
    """Only the offset line changed: the status line said nothing, as it does for C."""
    wave = window.waveform
    clap_x = wave.clap.value()
    wave.setXRange(clap_x - 2, clap_x + 2, padding=0)
    offset = window.model.session.sync.offset_ns
    drag(qtbot, wave, clap_x, clap_x + 0.2)
    shift_ns = window.model.session.sync.offset_ns - offset
    assert abs(shift_ns - 200_000_000) < 10_000_000
    assert f"clap handle dragged: audio moved {shift_text(shift_ns)} · Ctrl+Z takes it " \
        "back" in window.status_text.text()
    drag(qtbot, wave, wave.clap.value(), wave.clap.value() + 0.2)  # the same again
    assert window.status_text.text().count("clap handle dragged") == 1


def test_the_word_marks_and_the_envelope_slide_with_the_clap_handle_while_dragged(
        window, qtbot) -> None:
    wave, model = window.waveform, window.model
    set_id = model.current_set.id
    mark = wave.mark_extent(set_id)
    envelope_x = wave._upper.pos().x()
    clap_x = wave.clap.value()
    wave.setXRange(clap_x - 2, clap_x + 2, padding=0)
    offset = model.session.sync.offset_ns
    p0, p1 = _point(wave, clap_x), _point(wave, clap_x + 0.3)
    _send(wave, QEvent.Type.MouseMove, p0)
    _send(wave, QEvent.Type.MouseButtonPress, p0, Qt.MouseButton.LeftButton)
    for k in range(1, 6):
        _send(wave, QEvent.Type.MouseMove, p0 + (p1 - p0) * (k / 5), Qt.MouseButton.LeftButton)
    # held: the offset is not edited yet, but the audio is drawn where it would go
    assert model.session.sync.offset_ns == offset
    shift_s = wave.clap.value() - clap_x
    assert shift_s == pytest.approx(0.3, abs=0.01)
    assert wave.mark_extent(set_id) == pytest.approx((mark[0] + shift_s, mark[1] + shift_s))
    assert wave._upper.pos().x() == pytest.approx(envelope_x + shift_s)
    # the playhead previews the set at its shifted time, inside its shifted mark
    assert wave.mark_extent(set_id)[0] - 0.5 < wave.playhead.value() < \
        wave.mark_extent(set_id)[1] + 0.5
    _send(wave, QEvent.Type.MouseButtonRelease, p1)
    qtbot.wait(10)
    # released: the offset moved, and the marks stand where the new sync puts them
    moved_s = (model.session.sync.offset_ns - offset) / 1e9
    assert moved_s == pytest.approx(shift_s, abs=0.001)
    assert wave.mark_extent(set_id) == pytest.approx((mark[0] + moved_s, mark[1] + moved_s),
                                                     abs=0.001)
    assert wave.mark_extent(set_id) == pytest.approx(wave.marks.region(set_id),
                                                     abs=1e-9)


def test_the_playhead_line_is_dragged_away_from_the_clap(window, qtbot) -> None:
    wave = window.waveform
    x0, x1 = wave.getViewBox().viewRange()[0]
    start = x0 + 0.6 * (x1 - x0)
    click(qtbot, wave, start)
    offset = window.model.session.sync.offset_ns
    drag(qtbot, wave, wave.playhead.value(), start + 0.1 * (x1 - x0))
    pixel_s = (x1 - x0) / wave.width()
    assert abs(wave.playhead.value() - (start + 0.1 * (x1 - x0))) <= 3 * pixel_s
    assert window.model.session.sync.offset_ns == offset


def test_zoom_and_pan_stay_within_the_whole_session(window, qtbot) -> None:
    wave = window.waveform
    w0, w1 = wave.whole
    assert _view(wave) == pytest.approx((w0, w1))
    # the audio starts before the first frame: the view may take it in (a wrong clap
    # can put the real one there), no more
    a0, a1 = wave._audio_x()
    assert a0 < w0 - 1.0
    wheel(qtbot, wave, (w0 + w1) / 2, -30)  # far out: no further than the whole and audio
    assert _view(wave) == pytest.approx((a0, max(a1, w1)))
    wave.show_whole()
    wheel(qtbot, wave, (w0 + w1) / 2, 3)
    v0, v1 = _view(wave)
    assert w0 < v0 < v1 < w1
    w0 = a0  # where panning ends
    drag(qtbot, wave, v0 + 0.2 * (v1 - v0), v0 + 0.9 * (v1 - v0), y=0.8)  # pan left, far
    drag(qtbot, wave, v0 + 0.2 * (v1 - v0), v0 + 0.9 * (v1 - v0), y=0.8)
    drag(qtbot, wave, v0 + 0.2 * (v1 - v0), v0 + 0.9 * (v1 - v0), y=0.8)
    p0, p1 = _view(wave)
    assert p0 == pytest.approx(w0) and p1 - p0 == pytest.approx(v1 - v0)
    wheel(qtbot, wave, (p0 + p1) / 2, 60)  # far in: no narrower than MIN_SPAN_S
    z0, z1 = _view(wave)
    assert z1 - z0 == pytest.approx(MIN_SPAN_S, rel=0.05)


def test_a_double_click_on_the_waveform_shows_the_whole_session(window, qtbot) -> None:
    wave = window.waveform
    whole = wave.whole
    assert not wave.whole_button.isVisible()
    wave.setXRange(10.0, 12.0, padding=0)
    double_click(qtbot, wave, 11.0, 0.8)
    assert _view(wave) == pytest.approx(whole)
    assert abs(wave.playhead.value() - 11.0) < 0.05  # its first click is a click


def test_the_whole_button_shows_the_whole_session_while_zoomed_in(window, qtbot) -> None:
    wave = window.waveform
    whole = wave.whole
    wheel(qtbot, wave, (whole[0] + whole[1]) / 2, 2)
    assert wave.whole_button.isVisible()
    assert wave.whole_button.geometry().right() <= wave.width()
    qtbot.mouseClick(wave.whole_button, Qt.MouseButton.LeftButton)
    assert _view(wave) == pytest.approx(whole)
    assert not wave.whole_button.isVisible()


def test_the_limits_follow_the_whole_view_when_an_offset_edit_widens_it(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    session = load_session(truth_session_file)
    first = session.sync_evidence["claps"][0]
    session.sync_evidence["claps"] = [first, {"audio_s": first["audio_s"] + 9.5}]
    path = tmp_path / "two_claps.json"
    save_session(session, path)
    window = open_window(path)
    wave = window.waveform
    w0, w1 = wave.whole
    wheel(qtbot, wave, (w0 + w1) / 2, 3)  # zoomed in: the edit keeps the zoom
    zoom = _view(wave)
    window.model.nudge_offset(5_000_000_000)  # clap 2 and the last words past the end
    (mark,) = wave.later_claps
    assert mark.value() > w1
    assert _view(wave) == pytest.approx(zoom)
    assert wave.whole[1] > mark.value()
    wheel(qtbot, wave, (zoom[0] + zoom[1]) / 2, -30)  # the wheel reaches the new whole
    v0, v1 = _view(wave)
    assert v0 <= wave.clap.value() and mark.value() <= v1
    audio = wave._audio_x()  # and the audio, moved 5 s later
    assert (v0, v1) == pytest.approx((min(wave.whole[0], audio[0]),
                                      max(wave.whole[1], audio[1])))


def test_a_click_on_a_word_mark_shows_its_set(window, qtbot) -> None:
    """The mark covers the spoken word; the set's frames are often later (its stillest
    moment), yet a click on the word goes to the set, and then within the word."""
    wave, model = window.waveform, window.model
    target = model.session.sets[-1]
    assert model.current != len(model.session.sets) - 1
    a, b = wave.marks.region(target.id)
    wave.setXRange(a - 1.0, b + 1.0, padding=0)
    click(qtbot, wave, (a + b) / 2, 0.8)
    assert model.current_set is target
    assert all(tile.chosen for tile in model.tiles())
    click(qtbot, wave, a + 0.25 * (b - a), 0.8)  # its own word: the playhead goes there
    assert model.current_set is target
    assert abs(wave.playhead.value() - (a + 0.25 * (b - a))) < 0.01
    click(qtbot, wave, a - 0.5, 0.8)  # off every word: the playhead moves, nothing else
    assert model.current_set is target
    assert abs(wave.playhead.value() - (a - 0.5)) < 0.01
