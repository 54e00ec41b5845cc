"""Colours and symbols shared by every widget (state is never shown by colour alone)."""

from __future__ import annotations

from PySide6.QtGui import QColor, QPalette

from speechcal_core.text import WARNING_SYMBOL  # noqa: F401  (the window's, with a colour)

DECISION_COLOURS = {
    "accepted": QColor(46, 160, 67),
    "rejected": QColor(215, 58, 73),
    "undecided": QColor(140, 149, 159),
}
#: the same, darker, for text on the light list (the grey of "? undecided" was faint there)
DECISION_TEXT_COLOURS = {
    "accepted": QColor(26, 127, 55),
    "rejected": QColor(190, 35, 50),
    "undecided": QColor(87, 96, 106),
}
DECISION_SYMBOLS = {"accepted": "✔", "rejected": "✘", "undecided": "?"}
WARNING_COLOUR = QColor(219, 154, 4)
#: the same, darker, for text on the light window and list (contrast 5:1 against its
#: grey; the bright amber's was 2:1)
WARNING_TEXT_COLOUR = QColor(135, 90, 0)
PLAYHEAD_COLOUR = QColor(255, 210, 60)
#: the clap handle on the waveform, and its label (and what the word band says while it
#: is dragged)
CLAP_COLOUR = QColor(255, 120, 40)
CLAP_LABEL_COLOUR = QColor(255, 160, 90)
BACKGROUND = QColor(30, 32, 36)
#: the frame around the grid or the waveform while it has the keyboard focus: the Fusion
#: style's highlight (the list's selection), 3:1 against the light window and 4:1
#: against the dark views
FOCUS_COLOUR = QColor(48, 140, 198)


def hint_text_colour(palette: QPalette) -> QColor:
    """The colour of a hint (the key help line): the text's, 40 % of the way to the
    window's, so that it reads as secondary yet holds 5:1 against the window (Qt's
    "gray" gave 3.4:1 on the light window)."""
    text, window = palette.color(QPalette.ColorRole.WindowText), \
        palette.color(QPalette.ColorRole.Window)
    return QColor(*(round(0.6 * a + 0.4 * b) for a, b in (
        (text.red(), window.red()), (text.green(), window.green()),
        (text.blue(), window.blue()))))
