"""The waveform under a real mouse: press, move and release as the operator's hand does
(pyqtgraph picks the item to drag by what lies under the pointer, so signals emitted by
hand would not show which line a drag grabs)."""

from __future__ import annotations

from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QApplication

from app.waveform import WaveformView


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
