"""The waveform in the window: a click or a drag of the playhead line moves the playhead
(session nanoseconds, beyond 32 bits); an audio file moved during the session is named on
the status line, once, with what to do."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from PySide6.QtCore import QPoint, QPointF, QRect, QRectF, Qt
from truth_sessions import truth_session

from app.main_window import ReviewWindow
from app.word_marks import LABEL_TOP_Y
from speechcal_core.session.store import save_session


def test_moved_audio_file_is_named_once_on_the_status_line(qtbot, tiny_synth,
                                                          tmp_path: Path) -> None:
    folder, truth = tiny_synth
    copy = tmp_path / "session"
    shutil.copytree(folder, copy)  # the shared session's audio stays where it is
    session = truth_session(copy, truth)
    session.sync_evidence = {"claps": truth["claps"]}
    save_session(session, tmp_path / "review.json")
    window = ReviewWindow()
    window.setProperty("headless", True)
    qtbot.addWidget(window)
    window.resize(900, 600)  # the whole view drawn from the envelope's levels: no samples
    window.show()            # read yet (a wide view of this short audio reads them all)
    window.open(session_path=str(tmp_path / "review.json"))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    waveform = window.waveform
    audio = waveform.pyramid.source.path
    assert str(copy) in str(audio)
    window.status.say("")
    audio.rename(audio.with_name("moved-" + audio.name))
    x0, x1 = waveform.getViewBox().viewRange()[0]
    x0 = (x0 + x1) / 2  # within the audio
    waveform.setXRange(x0, x0 + 0.05, padding=0)  # raw samples: read from the file
    assert waveform.pyramid.unreadable
    text = window.status_text.text()
    assert str(audio) in text and "coarse levels only" in text
    assert "put it back" in text and "reopen the session" in text
    window.status.end("waveform")  # the operator read it
    waveform.setXRange(x0 - 1.0, x0 - 0.95, padding=0)
    waveform.setXRange(x0 + 0.5, x0 + 1.0, padding=0)
    assert "coarse levels" not in window.status_text.text()  # said once only


def test_the_envelope_has_a_column_per_pixel_of_the_laid_out_view(window, qtbot) -> None:
    wave = window.waveform

    def columns() -> int:
        return len(wave._upper.xData)

    for size in ((1400, 900), (1024, 640)):
        window.resize(*size)
        width = int(wave.getViewBox().width())
        qtbot.waitUntil(lambda w=width: abs(columns() - w) <= 0.1 * w, timeout=5_000)


def test_a_click_on_the_waveform_moves_the_playhead_there(window, qtbot) -> None:
    waveform = window.waveform
    x0, x1 = waveform.getViewBox().viewRange()[0]
    target_x = x0 + 0.6 * (x1 - x0)
    scene_pos = waveform.getViewBox().mapViewToScene(QPointF(target_x, 0.0))
    point = waveform.mapFromScene(scene_pos)
    for press in (qtbot.mousePress, qtbot.mouseRelease):  # a click, as pyqtgraph sees one
        press(waveform.viewport(), Qt.MouseButton.LeftButton, pos=QPoint(point.x(), point.y()))
        qtbot.wait(20)
    expected_ns = waveform.origin_ns + round(target_x * 1e9)
    pixel_ns = (x1 - x0) / waveform.width() * 1e9
    assert abs(window.model.playhead_ns - expected_ns) <= 2 * pixel_ns
    assert abs(waveform.playhead.value() - target_x) <= 2 * pixel_ns / 1e9


def test_dragging_the_playhead_line_moves_the_playhead(window) -> None:
    waveform = window.waveform
    x0, x1 = waveform.getViewBox().viewRange()[0]
    target_x = x0 + 0.3 * (x1 - x0)
    waveform.playhead.setValue(target_x)
    waveform.playhead.sigDragged.emit(waveform.playhead)  # what a mouse drag emits
    assert abs(window.model.playhead_ns - (waveform.origin_ns + round(target_x * 1e9))) <= 1


def test_a_hovered_playhead_keeps_its_colour(window) -> None:
    """Hovered, the playhead turned pyqtgraph's red, the colour of a rejected set."""
    from app.style import PLAYHEAD_COLOUR

    line = window.waveform.playhead
    assert line.hoverPen.color() == PLAYHEAD_COLOUR
    assert line.hoverPen.widthF() > line.pen.widthF()


def _with_a_word_close_after_the_first(window):
    """The waveform marking the sets plus set 99, 0.15 s after the first set's word."""
    from dataclasses import replace

    wave = window.waveform
    first = window.model.session.sets[0]
    near = replace(first, id=99, trigger=replace(first.trigger,
                                                 start_s=first.trigger.start_s + 0.15,
                                                 end_s=first.trigger.end_s + 0.15))
    wave.set_sets([first, near, *window.model.session.sets[1:]])
    return wave, first


def test_labels_of_sets_too_close_to_read_are_stacked_until_zoomed_in(window) -> None:
    """Two words 0.15 s apart in the whole session's view: their labels would print over
    each other ("?20?21"), so the second one goes in the row under the first until
    zooming in makes room beside it."""
    wave, first = _with_a_word_close_after_the_first(window)
    marks = wave.marks
    assert {first.id, 99} <= {m.set_id for m in marks.shown_labels()}
    assert (marks.label_row(first.id), marks.label_row(99)) == (0, 1)
    a, b = wave.mark_extent(first.id)
    x = (a + b) / 2
    wave.setXRange(x - 0.5, x + 0.5, padding=0)
    assert {first.id, 99} <= {m.set_id for m in marks.shown_labels()}
    assert marks.label_row(first.id) == marks.label_row(99) == 0
    # labels that never crowd each other all show in the whole view
    wave.set_sets(window.model.session.sets)
    wave.show_whole()
    assert len(wave.marks.shown_labels()) == len(window.model.session.sets)


def test_a_playhead_out_of_the_zoomed_view_has_a_button_that_goes_to_it(window,
                                                                        qtbot) -> None:
    """Zoomed in elsewhere, nothing showed where the playhead was."""
    waveform = window.waveform
    x = waveform.playhead.value()
    assert waveform.playhead_button.isHidden()
    waveform.setXRange(x + 2.0, x + 3.0, padding=0)  # the view after the playhead
    qtbot.waitUntil(lambda: waveform.playhead_button.isVisible())
    assert waveform.playhead_button.text() == "◀ playhead"
    assert waveform.playhead_button.x() < waveform.width() // 2
    qtbot.mouseClick(waveform.playhead_button, Qt.MouseButton.LeftButton)
    x0, x1 = waveform.getViewBox().viewRange()[0]
    assert x0 < x < x1 and x1 - x0 == pytest.approx(1.0, rel=0.05)
    assert waveform.playhead_button.isHidden()
    waveform.setXRange(x - 3.0, x - 2.0, padding=0)  # before it
    qtbot.waitUntil(lambda: waveform.playhead_button.isVisible())
    assert waveform.playhead_button.text() == "playhead ▶"


def _hidden_labels(wave) -> list[int]:
    """The sets whose label (as drawn along the top) a button of the view covers."""
    box = wave.getViewBox()
    buttons = [b.geometry() for b in (wave.whole_button, wave.playhead_button)
               if b.isVisible()]
    hidden = []
    for mark in wave.marks.shown_labels():
        scene = box.mapViewToScene(QPointF(mark.middle, LABEL_TOP_Y))
        top = wave.viewport().mapTo(wave, wave.mapFromScene(scene))
        width, height = wave.marks.label_width(mark), wave.marks.label_height()
        label = QRect(round(top.x() - width / 2), top.y(), round(width), round(height))
        if any(label.intersects(b) for b in buttons):
            hidden.append(mark.set_id)
    return hidden


def _view_with_label_near_the_edge(wave, set_id: int, side: int, span_s: float = 3.0,
                                   edge_px: float = 30.0) -> None:
    """Zoom to ``span_s`` with the set's label middle ``edge_px`` from the right (``side``
    1) or left (-1) edge of the view."""
    a, b = wave.mark_extent(set_id)
    middle = (a + b) / 2
    margin = span_s * edge_px / wave.getViewBox().width()
    if side > 0:
        wave.setXRange(middle + margin - span_s, middle + margin, padding=0)
    else:
        wave.setXRange(middle - margin, middle - margin + span_s, padding=0)


def test_the_view_buttons_leave_the_sets_labels_and_the_sound_uncovered(qtbot, window) -> None:
    """Zoomed in, "whole session" and "playhead ▶" stood over the labels at the top right
    of the view (and "◀ playhead" over those at the top left)."""
    wave, model = window.waveform, window.model
    sets = model.session.sets
    model.go_to_set(len(sets) - 1)  # the playhead after the view
    _view_with_label_near_the_edge(wave, sets[-2].id, side=1)
    qtbot.waitUntil(lambda: wave.playhead_button.isVisible())
    assert wave.whole_button.isVisible() and wave.playhead_button.text() == "playhead ▶"
    assert sets[-2].id in {m.set_id for m in wave.marks.shown_labels()}
    assert _hidden_labels(wave) == []
    model.go_to_set(0)  # the playhead before the view
    _view_with_label_near_the_edge(wave, sets[1].id, side=-1)
    qtbot.waitUntil(lambda: wave.playhead_button.text() == "◀ playhead")
    assert sets[1].id in {m.set_id for m in wave.marks.shown_labels()}
    assert _hidden_labels(wave) == []
    # nor do they stand on the waveform itself: they sit beside the axis's name
    plot = wave.mapFromScene(wave.getViewBox().sceneBoundingRect()).boundingRect()
    for button in (wave.whole_button, wave.playhead_button):
        assert button.isVisible() and not button.geometry().intersects(plot)
        assert wave.rect().contains(button.geometry())


def test_an_offset_edit_moves_the_envelope_then_draws_it_anew(window, qtbot) -> None:
    """A held ``]`` moves the envelope as drawn (no recomputing on every step); once the
    edits pause it is drawn anew for the new offset, where it lies the same."""
    import numpy as np

    wave = window.waveform
    before = np.array(wave._upper.getData()[0])
    for _ in range(5):
        window.run_action("offset_plus_ms")
    assert wave._upper.pos().x() == pytest.approx(0.005)
    assert np.array_equal(wave._upper.getData()[0], before)  # moved, not recomputed
    qtbot.waitUntil(lambda: wave._upper.pos().x() == 0.0, timeout=5_000)
    xs = np.array(wave._upper.getData()[0])
    assert not np.array_equal(xs, before)  # columns for the new offset
    assert wave._drawn_sync == window.model.session.sync  # drawn with the sync in force


def test_the_current_sets_label_shows_even_where_labels_crowd(window) -> None:
    """Thinning dropped the label of the set under the playhead when another word lay
    close before it; the current set's label now always shows (bold) in the top row,
    and the crowding neighbour's gives way to the row under it."""
    wave, first = _with_a_word_close_after_the_first(window)
    marks = wave.marks
    marks.set_current(99)
    assert {first.id, 99} <= {m.set_id for m in marks.shown_labels()}
    assert (marks.label_row(99), marks.label_row(first.id)) == (0, 1)
    marks.set_current(None)
    assert (marks.label_row(first.id), marks.label_row(99)) == (0, 1)


def _drawn_label_rects(wave) -> dict[int, QRectF]:
    """Where each shown label is drawn in the waveform's pixels (its row included)."""
    from app.word_marks import LABEL_ROW_GAP_PX

    box, marks = wave.getViewBox(), wave.marks
    rects = {}
    for mark in marks.shown_labels():
        scene = box.mapViewToScene(QPointF(mark.middle + marks.shift_s, LABEL_TOP_Y))
        top = wave.viewport().mapTo(wave, wave.mapFromScene(scene))
        width, height = marks.label_width(mark), marks.label_height()
        y = top.y() + marks.label_row(mark.set_id) * (height + LABEL_ROW_GAP_PX)
        rects[mark.set_id] = QRectF(top.x() - width / 2, y, width, height)
    return rects


def test_a_set_added_beside_a_heard_one_leaves_both_labels_readable(qtbot, window) -> None:
    """A set added with T just after set 3 (set 13, current): its bold "?13" took the
    row, and "?3" was left out over its own band, as if "?13" had been drawn over it.
    At half a 1920 px screen both show, the current one in the top row, no two labels
    touch, and each is drawn where it is placed."""
    window.resize(960, 1040)
    qtbot.waitUntil(lambda: window.width() == 960)
    wave, first = _with_a_word_close_after_the_first(window)
    marks = wave.marks
    marks.set_current(99)
    neighbour = first.id
    assert {99, neighbour} <= {m.set_id for m in marks.shown_labels()}
    assert marks.label_row(99) == 0
    rects = list(_drawn_label_rects(wave).values())
    for n, a in enumerate(rects):
        for b in rects[n + 1:]:
            assert not a.intersects(b)
    image = wave.grab().toImage()  # the neighbour's label is drawn where it is placed
    rect = _drawn_label_rects(wave)[neighbour].toRect()
    lit = [image.pixelColor(x, y).lightness() > 120
           for x in range(rect.left(), rect.right()) for y in range(rect.top(), rect.bottom())]
    assert sum(lit) > 10  # its text


def test_changing_set_takes_a_zoomed_in_view_along(window, qtbot) -> None:
    """Zoomed in on one set, K left the view on it: the next set was off screen."""
    wave = window.waveform
    model = window.model
    model.go_to_set(0)
    a, b = wave.mark_extent(model.session.sets[0].id)
    wave.setXRange(a - 0.5, b + 0.5, padding=0)
    width = (b + 0.5) - (a - 0.5)
    qtbot.keyClick(window, Qt.Key.Key_K)
    current = model.current_set
    assert current is not None and current.id == model.session.sets[1].id
    assert wave.marks.current == current.id
    x0, x1 = wave.getViewBox().viewRange()[0]
    a, b = wave.mark_extent(current.id)
    assert x0 <= a and b <= x1 and x1 - x0 == pytest.approx(width, rel=0.01)
    # the whole view stays as it is
    wave.show_whole()
    whole = wave.getViewBox().viewRange()[0]
    qtbot.keyClick(window, Qt.Key.Key_K)
    assert wave.getViewBox().viewRange()[0] == pytest.approx(whole)


def test_without_its_audio_file_the_waveform_says_why_and_keeps_the_marks(
        open_window, tiny_synth, tmp_path: Path) -> None:
    """A session whose audio file is gone showed an empty pane, without its word marks
    or clap: the sets' words are in the session, so they still show, and the pane says
    why there is no waveform."""
    folder, truth = tiny_synth
    copy = tmp_path / "session"
    shutil.copytree(folder, copy)
    session = truth_session(copy, truth)
    session.sync_evidence = {"claps": truth["claps"]}
    save_session(session, tmp_path / "review.json")
    audio = Path(session.audio)
    audio.rename(tmp_path / "elsewhere.ogg")
    window = open_window(tmp_path / "review.json")
    wave = window.waveform
    assert wave.message.isVisible()
    assert wave.message.text().startswith("no waveform: ") and audio.name in wave.message.text()
    assert len(wave.marks) == len(window.model.session.sets) > 0
    assert wave.clap.isVisible()


def test_zoomed_in_the_loudest_sound_in_view_fills_the_height(window) -> None:
    """Scaled to the whole session's loudest sound (a clap), a word zoomed in on was a
    flat line."""
    wave = window.waveform
    a, b = wave.mark_extent(window.model.session.sets[0].id)
    wave.show_whole()
    whole = wave._upper.yData[(wave._upper.xData >= a) & (wave._upper.xData <= b)].max()
    wave.setXRange(a - 0.2, b + 0.2, padding=0)
    zoomed = max(wave._upper.yData.max(), -wave._lower.yData.min())
    assert zoomed == pytest.approx(1.0, abs=1e-3) and zoomed > 1.5 * whole


def test_the_view_reaches_audio_before_the_first_frame(window, qtbot) -> None:
    """A knock taken for the clap put the real clap seconds before the first frame: the
    view stopped at the frames, so the operator could not see the clap to drag the
    handle onto it."""
    wave = window.waveform
    window.model.nudge_offset(-6_000_000_000)  # the audio 6 s earlier than it was
    audio_start, _ = wave._audio_x()
    assert audio_start < wave.whole[0] - 1.0  # the whole view stays the frames' and marks'
    wave.setXRange(audio_start, audio_start + 4.0, padding=0)
    x0 = wave.getViewBox().viewRange()[0][0]
    assert x0 == pytest.approx(audio_start, abs=0.01)
    assert wave.zoomed_in()  # the "whole session" button takes the view back
    wave.show_whole()
    assert wave.getViewBox().viewRange()[0] == pytest.approx(wave.whole)


def test_opening_draws_the_envelope_of_the_whole_view_only(
        qtbot, tiny_synth, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The waveform is drawn for the whole session once it is shown, not first for
    pyqtgraph's initial one-second view (which read that second's samples from the
    audio file on the UI thread while the session opened)."""
    from speechcal_core.audio.envelope import EnvelopePyramid

    folder, truth = tiny_synth
    save_session(truth_session(folder, truth), tmp_path / "review.json")
    spans: list[float] = []
    real = EnvelopePyramid.envelope

    def envelope(self, t0: float, t1: float, width: int):
        spans.append(t1 - t0)
        return real(self, t0, t1, width)

    monkeypatch.setattr(EnvelopePyramid, "envelope", envelope)
    read: list[tuple[int, int]] = []
    samples = EnvelopePyramid._from_samples
    monkeypatch.setattr(EnvelopePyramid, "_from_samples", lambda self, i0, i1, *a:
                        read.append((i0, i1)) or samples(self, i0, i1, *a))
    window = ReviewWindow()
    window.setProperty("headless", True)
    qtbot.addWidget(window)
    window.resize(900, 600)  # the whole view is drawn from the envelope's levels
    window.show()
    window.open(session_path=str(tmp_path / "review.json"))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    wave = window.waveform
    assert not wave.zoomed_in() and len(wave._upper.xData) > 0  # drawn, whole
    x0, x1 = wave.getViewBox().viewRange()[0]
    assert spans and min(spans) > 0.5 * (x1 - x0)
    assert read == []  # no stretch of the file read on the way
