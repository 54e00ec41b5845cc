"""The review window opened on the truth session, as an operator sees it after loading."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from app.main_window import ReviewWindow


@pytest.fixture
def open_window(qtbot) -> Callable[[Path], ReviewWindow]:
    """Opens a session file in a shown window and waits for every tile's frame."""

    def open_(path: Path) -> ReviewWindow:
        win = ReviewWindow()
        win.setProperty("headless", True)
        qtbot.addWidget(win)
        win.show()
        win.open(session_path=str(path))
        qtbot.waitUntil(lambda: win.model is not None, timeout=30_000)
        qtbot.waitUntil(lambda: all(t.image is not None for t in win.grid.tiles.values()),
                        timeout=30_000)
        return win

    return open_


@pytest.fixture
def window(open_window, truth_session_file: Path) -> ReviewWindow:
    return open_window(truth_session_file)
