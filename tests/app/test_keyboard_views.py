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
    qtbot.keyClick(window, Qt.Key.Key_9)  # no ninth camera: nothing changes but the words
    assert all(t.isVisible() for t in grid.tiles.values())
    assert window.status_text.text() == \
        f"no camera 9: this session has {len(names)} cameras (keys 1-{len(names)} show one alone)"
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


def test_j_k_home_and_end_say_why_when_they_go_nowhere(qtbot, window) -> None:
    """K on the last listed set (or J on the first) left the window as it was, with
    nothing to tell a key that works from one that went unheard."""
    model = window.model
    sets = model.session.sets
    qtbot.keyClick(window, Qt.Key.Key_J)
    assert window.status_text.text() == f"no set listed before set #{sets[0].id}"
    qtbot.keyClick(window, Qt.Key.Key_End)
    qtbot.keyClick(window, Qt.Key.Key_K)
    assert model.current == len(sets) - 1
    assert window.status_text.text() == f"no set listed after set #{sets[-1].id}"
    qtbot.keyClick(window, Qt.Key.Key_K)  # again: the key was heard
    assert window.status_text.text() == f"no set listed after set #{sets[-1].id} (×2)"
    qtbot.keyClick(window, Qt.Key.Key_A)  # "then next set" finds none either
    assert window.status_text.text() == \
        f"set #{sets[-1].id} accepted · no set listed after set #{sets[-1].id}"
    qtbot.keyClick(window, Qt.Key.Key_F)  # undecided: the accepted set hidden, the last
    qtbot.keyClick(window, Qt.Key.Key_K)
    assert window.status_text.text() == f"no undecided set listed after set #{sets[-1].id}"
    qtbot.keyClick(window, Qt.Key.Key_J)  # goes on: nothing to say
    assert model.current == len(sets) - 2 and window.status_text.text() == ""
    qtbot.keyClick(window, Qt.Key.Key_F)
    qtbot.keyClick(window, Qt.Key.Key_F)  # rejected: none
    qtbot.keyClick(window, Qt.Key.Key_Home)
    assert window.status_text.text() == \
        "no rejected sets listed: F steps through the filters (“all” lists every set)"
