"""Colours and symbols shared by every widget (state is never shown by colour alone)."""

from __future__ import annotations

from PySide6.QtGui import QColor

DECISION_COLOURS = {
    "accepted": QColor(46, 160, 67),
    "rejected": QColor(215, 58, 73),
    "undecided": QColor(140, 149, 159),
}
DECISION_SYMBOLS = {"accepted": "✔", "rejected": "✘", "undecided": "?"}
WARNING_COLOUR = QColor(219, 154, 4)
WARNING_SYMBOL = "▲"  # with WARNING_COLOUR wherever a warning shows
PLAYHEAD_COLOUR = QColor(255, 210, 60)
BACKGROUND = QColor(30, 32, 36)
