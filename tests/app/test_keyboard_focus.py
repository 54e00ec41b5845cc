"""Where the keyboard focus is once a session opens: on the camera grid, where the
operator works, and Tab goes from there through the review page's controls in the order
the eyes go (frames, sound, the list's box), never to a hidden widget."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication


def _tab_stops(qtbot, window, count: int) -> list:
    """The widgets Tab gives the focus to, ``count`` presses from where it is."""
    stops = []
    for _ in range(count):
        qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Tab)
        stops.append(QApplication.focusWidget())
    return stops


def test_a_session_opens_with_the_focus_on_the_grid_not_the_hidden_cancel(
        qtbot, window, truth_session_file: Path) -> None:
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5_000)
    assert not window.cancel_button.isVisible()
    assert window.focusWidget() is window.grid  # it was the status line's hidden Cancel
    assert QApplication.focusWidget() is window.grid

    stops = _tab_stops(qtbot, window, 3)
    assert stops == [window.waveform, window.advance_box, window.grid]
    assert all(w.isVisible() for w in stops)

    window.open(session_path=str(truth_session_file))  # another session over this one
    old_grid = window.grid
    qtbot.waitUntil(lambda: window.grid is not old_grid and not window.status.running(),
                    timeout=30_000)
    assert window.focusWidget() is window.grid and window.grid.isVisible()
