"""The application's icon: the window shows it, and the desktop entry names the same one."""

from __future__ import annotations

import configparser
from pathlib import Path

from app.main_window import APP_ICON
from speechcal_core.resources import resource

REPO = Path(__file__).resolve().parents[2]


def test_the_window_shows_the_bundled_icon(new_window) -> None:
    window = new_window()
    pixmap = window.windowIcon().pixmap(64, 64)
    assert not pixmap.isNull()
    image = pixmap.toImage()
    assert len({image.pixel(x, y) for x in range(0, 64, 4) for y in range(0, 64, 4)}) > 3


def test_the_desktop_entry_names_the_bundled_icon() -> None:
    entry = configparser.ConfigParser(interpolation=None)
    entry.optionxform = str  # keys are case-sensitive
    entry.read(REPO / "packaging" / "speechcal.desktop")
    icon = entry["Desktop Entry"]["Icon"]
    assert resource("icons", f"{icon}.svg").is_file()
    assert f"{icon}.svg" == APP_ICON
