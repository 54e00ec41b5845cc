"""What the mouse does to the views, from the keyboard too: 1-9 shows one camera alone
(as a double-click on it), = and - zoom the waveform around the playhead (as the wheel)."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt


def test_a_number_shows_that_camera_alone_and_again_all_of_them(qtbot, window) -> None:
    grid = window.grid
    names = list(grid.tiles)
    qtbot.keyClick(window, Qt.Key.Key_2)
    assert [n for n, t in grid.tiles.items() if t.isVisible()] == [names[1]]
    qtbot.keyClick(window, Qt.Key.Key_1)  # another camera alone takes its place
    assert [n for n, t in grid.tiles.items() if t.isVisible()] == [names[0]]
    qtbot.keyClick(window, Qt.Key.Key_1)
    assert all(t.isVisible() for t in grid.tiles.values())
    qtbot.keyClick(window, Qt.Key.Key_9)  # no ninth camera: nothing changes
    assert all(t.isVisible() for t in grid.tiles.values())
    # camera names count from 0, the keys from 1: each tile's tooltip names its key
    assert [t.key for t in grid.tiles.values()] == [str(n + 1) for n in range(len(names))]


def test_equals_and_minus_zoom_the_waveform_around_the_playhead(qtbot, window) -> None:
    wave = window.waveform
    w0, w1 = wave.getViewBox().viewRange()[0]
    window.model.go_to_set(1)
    x = wave.playhead.value()
    qtbot.keyClick(window, Qt.Key.Key_Equal)
    qtbot.keyClick(window, Qt.Key.Key_Equal)
    v0, v1 = wave.getViewBox().viewRange()[0]
    assert v1 - v0 == pytest.approx((w1 - w0) / 4, rel=0.01)
    assert v0 < x < v1 and wave.zoomed_in()
    for _ in range(3):
        qtbot.keyClick(window, Qt.Key.Key_Minus)
    assert not wave.zoomed_in()  # out no further than the whole session
