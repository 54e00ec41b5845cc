"""Where the keyboard focus is once a session opens: on the camera grid, where the
operator works, and Tab goes from there through the review page's controls in the order
the eyes go (frames, sound, the list's box), never to a hidden widget."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication

from app.style import FOCUS_COLOUR


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
    # the new page's widgets are shown by a queued call once the opening has ended: on a
    # busy machine the wait below saw the new grid before that call had run, hidden
    qtbot.waitUntil(lambda: window.grid is not old_grid and not window.status.running()
                    and window.grid.isVisible(), timeout=30_000)
    assert window.focusWidget() is window.grid


def _edge(widget) -> tuple[int, int, int]:
    """The colour of the widget's left edge, halfway down, as drawn."""
    colour = widget.grab().toImage().pixelColor(0, widget.height() // 2)
    return colour.red(), colour.green(), colour.blue()


def test_the_grid_and_the_waveform_show_which_of_them_has_the_focus(qtbot, window) -> None:
    """Neither drew a focus frame: a keyboard user could not tell which one Tab had
    reached. The one with the focus has a frame of the focus colour round it."""
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5_000)
    grid, wave = window.grid, window.waveform
    ring = FOCUS_COLOUR.red(), FOCUS_COLOUR.green(), FOCUS_COLOUR.blue()
    assert grid.focus_ring.isVisible() and not wave.focus_ring.isVisible()
    assert _edge(grid) == ring and _edge(wave) != ring
    assert grid.focus_ring.geometry() == grid.rect()
    # the frame hides no tile: the decision borders lie inside it
    for tile in grid.tiles.values():
        assert grid.focus_ring.geometry().adjusted(2, 2, -2, -2).contains(
            tile.geometry().translated(tile.parentWidget().pos()))
    assert _tab_stops(qtbot, window, 1) == [wave]
    assert wave.focus_ring.isVisible() and not grid.focus_ring.isVisible()
    assert _edge(wave) == ring and _edge(grid) != ring
    assert wave.focus_ring.geometry() == wave.rect()
    assert _tab_stops(qtbot, window, 1) == [window.advance_box]  # it draws its own
    assert not wave.focus_ring.isVisible() and not grid.focus_ring.isVisible()
    assert _tab_stops(qtbot, window, 1) == [grid]
    assert grid.focus_ring.isVisible()


def test_space_ticks_the_then_next_set_box_when_tab_has_reached_it(qtbot, window) -> None:
    """The box is the one Tab stop besides the grid and the waveform, yet Space on it
    played the sound (the window's key) and nothing else ticked it: the box could not be
    changed from the keyboard. With the focus on it Space ticks it, as on any check box;
    back on the grid, Space plays again."""
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5_000)
    assert _tab_stops(qtbot, window, 2)[-1] is window.advance_box
    assert window.advance_box.isChecked()
    qtbot.keyClick(window.advance_box, Qt.Key.Key_Space)
    assert not window.advance_box.isChecked()
    assert not window.advance_after_decision
    assert not window.transport.playing
    qtbot.keyClick(window.advance_box, Qt.Key.Key_Space)
    assert window.advance_box.isChecked() and not window.transport.playing

    window.grid.setFocus()
    qtbot.keyClick(window.grid, Qt.Key.Key_Space)
    assert window.transport.playing
    qtbot.keyClick(window.grid, Qt.Key.Key_Space)
    assert not window.transport.playing


def test_space_presses_the_status_lines_cancel_while_a_recording_is_processed(
        qtbot, new_window, tiny_synth, tmp_path: Path) -> None:
    """While a recording is processed (a minute or two) the focus rests on the status
    line's Cancel, the one control shown; Space, the key that presses a button, was
    the window's play key and did nothing there: the opening could not be cancelled
    from the keyboard."""
    import shutil

    source, _truth = tiny_synth
    folder = tmp_path / "rec"
    shutil.copytree(source, folder)
    window = new_window()
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5_000)
    window.open(recording=[str(folder / "recording.bag")], audio=str(folder / "audio.ogg"))
    qtbot.waitUntil(window.cancel_button.isVisible, timeout=5_000)
    window.cancel_button.setFocus()  # where Tab, or the opening, puts it
    qtbot.keyClick(window.cancel_button, Qt.Key.Key_Space)
    qtbot.waitUntil(lambda: window.task is None, timeout=60_000)
    assert window.model is None
    assert "opening cancelled" in window.status_text.text()


def test_a_click_on_the_box_leaves_the_focus_where_it_was_so_space_still_plays(
        qtbot, window) -> None:
    """Space presses the button Tab has reached; the box clicked with the mouse took the
    focus too, and the operator's next Space, meant to play, unticked it instead."""
    window.activateWindow()
    qtbot.waitUntil(window.isActiveWindow, timeout=5_000)
    assert QApplication.focusWidget() is window.grid
    qtbot.mouseClick(window.advance_box, Qt.MouseButton.LeftButton)
    assert not window.advance_box.isChecked()
    assert QApplication.focusWidget() is window.grid
    qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Space)
    assert window.transport.playing and not window.advance_box.isChecked()
    qtbot.keyClick(QApplication.focusWidget(), Qt.Key.Key_Space)
    assert not window.transport.playing
