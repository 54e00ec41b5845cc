"""What the waveform repaints on a review action, as the screen shows it: a decision
repaints its mark's column only (every mark painted again cost 10 ms of the window's
thread at 300 sets), an offset edit every mark where it moved to; in every case the
screen shows what a fresh drawing of the view shows (nothing stale is left)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QObject, QPoint, QPointF, QRect, Qt
from PySide6.QtGui import QColor, QImage, QTransform
from truth_sessions import truth_session

from app.main_window import ReviewWindow
from app.waveform import WaveformView
from app.word_marks import screen_x
from speechcal_core.frames.nearest import nearest_frame_sets
from speechcal_core.session.store import save_session
from speechcal_core.sources import open_recording


def on_screen(wave: WaveformView) -> QImage:
    """The waveform as the screen shows it: the window's backing store, which a repaint
    changes only where something asked for one (``grab`` draws the widget afresh)."""
    window = wave.window()
    corner = wave.mapTo(window, QPoint(0, 0))
    return window.screen().grabWindow(window.winId(), corner.x(), corner.y(),
                                      wave.width(), wave.height()).toImage()


def shows_what_it_draws(wave: WaveformView) -> bool:
    """Whether the screen shows the waveform as a fresh drawing of it does."""
    screen = on_screen(wave)
    return screen == wave.grab().toImage().convertToFormat(screen.format())


class Repaints(QObject):
    """The areas of a widget repainted (its pixels) by the next key press."""

    def __init__(self, widget) -> None:
        super().__init__()
        self.rects: list[QRect] = []
        widget.installEventFilter(self)

    def eventFilter(self, _watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Paint:
            self.rects.append(event.region().boundingRect())
        return False

    def after(self, qtbot, window: ReviewWindow, key: Qt.Key) -> list[QRect]:
        """Press ``key`` in ``window``: the areas repainted until the window is idle."""
        self.rects = []
        qtbot.keyClick(window, key)
        qtbot.waitUntil(lambda: bool(self.rects), timeout=5_000)
        qtbot.wait(50)  # (nothing else asked for is left undone)
        return list(self.rects)


def band_colour(image: QImage, wave: WaveformView, set_id: int) -> QColor:
    """The colour ``image`` of the waveform has low in a set's word mark."""
    a, b = wave.mark_extent(set_id)
    return image.pixelColor(_to_pixel(wave, a + 0.2 * (b - a)))


def _to_pixel(wave: WaveformView, x: float) -> QPoint:
    scene = wave.getViewBox().mapViewToScene(QPointF(x, -0.95))
    return wave.mapFromScene(scene)


def looks_accepted(colour: QColor) -> bool:
    return colour.green() > colour.red() + 20


def settled(qtbot, wave: WaveformView) -> None:
    qtbot.waitUntil(lambda: shows_what_it_draws(wave), timeout=5_000)


def test_a_decision_repaints_its_marks_column_only(qtbot, window) -> None:
    window.advance_box.setChecked(False)  # the current set (its bold label) stays
    wave = window.waveform
    model = window.model
    settled(qtbot, wave)
    first = model.current_set
    assert not looks_accepted(band_colour(on_screen(wave), wave, first.id))
    repaints = Repaints(wave.viewport())
    repainted = repaints.after(qtbot, window, Qt.Key.Key_A)
    settled(qtbot, wave)
    assert looks_accepted(band_colour(on_screen(wave), wave, first.id))
    a, b = (_to_pixel(wave, x).x() for x in wave.mark_extent(first.id))
    view = wave.viewport().width()
    for rect in repainted:
        assert rect.left() <= a and b <= rect.right()
        assert rect.width() < view / 4
    repainted = repaints.after(qtbot, window, Qt.Key.Key_U)
    settled(qtbot, wave)
    assert not looks_accepted(band_colour(on_screen(wave), wave, first.id))
    assert all(rect.width() < view / 4 for rect in repainted)


@pytest.fixture
def crowded_session_file(tiny_synth, tmp_path: Path) -> Path:
    """The tiny session with a set every 0.2 s: in the whole view their labels crowd,
    and some are left out."""
    folder, truth = tiny_synth
    session = truth_session(folder, truth)
    first, last = session.sets[0].trigger, session.sets[-1].trigger
    step = (last.start_s - first.start_s) / 39
    triggers = [replace(first, start_s=first.start_s + step * k,
                        end_s=first.start_s + step * k + 0.12) for k in range(40)]
    with open_recording(session.recording) as source:
        session.sets = nearest_frame_sets(source, session.sync, triggers)
    session.sync_evidence = {"claps": truth["claps"]}
    path = tmp_path / "crowded.json"
    save_session(session, path)
    return path


def test_crowded_labels_on_screen_follow_decisions_and_set_changes(
        qtbot, crowded_session_file) -> None:
    """A decision or another current set changes a label's width (✔, bold), and so which
    of the crowded labels after it show: the screen shows each as a fresh drawing does."""
    window = ReviewWindow()
    window.setProperty("headless", True)
    qtbot.addWidget(window)
    window.resize(900, 600)
    window.show()
    window.open(session_path=str(crowded_session_file))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    wave = window.waveform
    model = window.model
    model.go_to_set(10)
    settled(qtbot, wave)
    assert len(wave.marks.shown_labels()) < len(model.session.sets)
    shown = []
    for key in (Qt.Key.Key_A, Qt.Key.Key_R, Qt.Key.Key_K, Qt.Key.Key_A, Qt.Key.Key_J,
                Qt.Key.Key_U, Qt.Key.Key_U, Qt.Key.Key_R):
        qtbot.keyClick(window, key)
        settled(qtbot, wave)
        shown.append([m.set_id for m in wave.marks.shown_labels()])
    assert len({tuple(ids) for ids in shown}) > 1  # the labels shown did change


def test_an_offset_edit_moves_the_marks_on_screen(qtbot, window) -> None:
    wave = window.waveform
    model = window.model
    window.advance_box.setChecked(False)
    qtbot.keyClick(window, Qt.Key.Key_A)
    settled(qtbot, wave)
    first = model.current_set.id
    before = wave.mark_extent(first)
    assert looks_accepted(band_colour(on_screen(wave), wave, first))
    model.nudge_offset(1_000_000_000)  # far enough to leave the band's old place
    after = wave.mark_extent(first)
    assert after == pytest.approx((before[0] + 1.0, before[1] + 1.0), abs=1e-6)
    settled(qtbot, wave)
    screen = on_screen(wave)
    assert looks_accepted(band_colour(screen, wave, first))
    old_place = screen.pixelColor(_to_pixel(wave, before[0] + 0.2 * (before[1] - before[0])))
    assert not looks_accepted(old_place)


def test_marks_are_placed_on_screen_to_the_bit_as_qtransform_maps_them() -> None:
    """The bands are placed without a QPointF mapped per mark: the same pixels only if
    the arithmetic is QTransform's own, to the last bit."""
    rng = np.random.default_rng(5)
    for _ in range(50):
        m11, dx = rng.uniform(1.0, 5000.0), rng.uniform(-1e5, 1e5)
        for transform in (QTransform(m11, 0, 0, -rng.uniform(10, 100), dx, 80.0),
                          QTransform.fromTranslate(dx, 3.0), QTransform()):
            to_x = screen_x(transform)
            for x in rng.uniform(-200.0, 4000.0, 40).tolist():
                assert to_x(x) == transform.map(QPointF(x, 0.0)).x()
    rotated = QTransform().rotate(30)
    assert screen_x(rotated)(2.0) == rotated.map(QPointF(2.0, 0.0)).x()
