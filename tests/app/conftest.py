"""The review window opened on the truth session, as an operator sees it after loading."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.main_window import ReviewWindow


@pytest.fixture
def window(qtbot, truth_session_file: Path) -> ReviewWindow:
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    win.open(session_path=str(truth_session_file))
    qtbot.waitUntil(lambda: win.model is not None, timeout=30_000)
    qtbot.waitUntil(lambda: all(t.image is not None for t in win.grid.tiles.values()),
                    timeout=30_000)
    return win
