"""The window tiled to half a 1920 px screen (960 px across) with many cameras: the grid's
least width held it wider than the half."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.main_window import ReviewWindow
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.session import generate_session

HALF_SCREEN = (960, 1040)


@pytest.mark.parametrize("cameras", [6, 12])
def test_a_window_of_many_cameras_fits_half_a_1920_px_screen(
        qtbot, tmp_path: Path, cameras: int) -> None:
    """Six cameras (a grid of three columns at its least) made the window 990 px wide at
    least, twelve 994 px: tiled to half a 1920 px screen it stuck out of its half. Every
    camera still shows, all of the list's columns too."""
    folder = tmp_path / "rec"
    generate_session(folder, SynthOptions(cameras=cameras, fisheye=0, duration=10.0,
                                          width=96, height=72, seed=4, claps=1))
    window = ReviewWindow()
    window.setProperty("headless", True)
    qtbot.addWidget(window)
    window.show()
    window.open(recording=[str(folder / "recording.bag")], audio=str(folder / "audio.ogg"))
    qtbot.waitUntil(lambda: window.model is not None, timeout=120_000)
    assert len(window.grid.tiles) == cameras and window.model.session.sets

    assert window.minimumSizeHint().width() <= HALF_SCREEN[0]
    window.resize(*HALF_SCREEN)
    qtbot.waitUntil(lambda: window.size().toTuple() == HALF_SCREEN, timeout=5_000)
    area = window.grid.rect()
    for tile in window.grid.tiles.values():
        assert tile.isVisible()
        assert area.contains(tile.geometry().translated(tile.parentWidget().pos()))
    table = window.table  # every column of the list in view
    qtbot.waitUntil(lambda: table.horizontalScrollBar().maximum() == 0, timeout=5_000)


def test_a_10_pt_window_of_12_cameras_fits_half_a_1920_px_screen(
        qtbot, tmp_path: Path) -> None:
    """At a 10 pt system font (KDE's) the list's least width, 70 average characters,
    held the window of 12 cameras 968 px wide: measured from its columns, it fits the
    half, every column of the list in view."""
    from PySide6.QtGui import QFont
    from PySide6.QtWidgets import QApplication

    folder = tmp_path / "rec"
    generate_session(folder, SynthOptions(cameras=12, fisheye=0, duration=10.0,
                                          width=96, height=72, seed=4, claps=1))
    before = QApplication.font()
    font = QFont(before)
    font.setPointSizeF(10.0)
    QApplication.setFont(font)
    try:
        window = ReviewWindow()
        window.setProperty("headless", True)
        qtbot.addWidget(window)
        window.show()
        window.open(recording=[str(folder / "recording.bag")],
                    audio=str(folder / "audio.ogg"))
        qtbot.waitUntil(lambda: window.model is not None, timeout=120_000)
        assert window.minimumSizeHint().width() <= HALF_SCREEN[0]
        window.resize(*HALF_SCREEN)
        qtbot.waitUntil(lambda: window.size().toTuple() == HALF_SCREEN, timeout=5_000)
        table = window.table
        qtbot.waitUntil(lambda: table.horizontalScrollBar().maximum() == 0, timeout=5_000)
    finally:
        QApplication.setFont(before)
