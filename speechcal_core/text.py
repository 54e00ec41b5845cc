"""Small helpers for the words SpeechCal shows (command line and window alike)."""

from __future__ import annotations

import re

#: what marks a warning in words (the window gives it a warning colour wherever it shows)
WARNING_SYMBOL = "▲"


def counted(n: int, word: str, plural: str | None = None) -> str:
    """``n`` and ``word``, in the plural unless ``n`` is 1: "1 camera", "3 cameras",
    "2 frame sets"; ``plural`` for words that do not just add an s."""
    return f"{n} {word if n == 1 else plural or word + 's'}"


def new_undecided(n: int, with_count: bool = True) -> tuple[str, str]:
    """What ``n`` sets just added for review are called, and the pronoun for them:
    ("a new undecided set", "it"), ("3 new undecided sets", "them"); without the count
    ("new undecided sets") where the message gave it already."""
    if n == 1:
        return "a new undecided set", "it"
    return (f"{n} new undecided sets" if with_count else "new undecided sets"), "them"


def listed(names: list[str], at_most: int = 3) -> str:
    """The first ``at_most`` names, comma-separated, "…" when there are more."""
    return ", ".join(names[:at_most]) + (", …" if len(names) > at_most else "")


def shown_name(name: str) -> str:
    """A file name as a window can show it: bytes that are not UTF-8 (held as lone
    surrogates) become "�" instead of vanishing."""
    return name.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


#: units a figure is given in; a wrapping line keeps each with its figure
_UNITS = "px|ms|s|ppm|%"
_FIGURE_AND_UNIT = re.compile(rf"(\d) ({_UNITS})(?![\w])")
_SIGN_AND_FIGURE = re.compile(r"([≤≥<>=±~]) ([-+−]?\d)")


def unbroken_figures(text: str) -> str:
    """``text`` with no-break spaces between a figure and its unit or sign ("RMS ≤ 0.22
    px"), so that a wrapping label does not leave "px" alone on the next line."""
    text = _FIGURE_AND_UNIT.sub("\\1\u00a0\\2", text)
    return _SIGN_AND_FIGURE.sub("\\1\u00a0\\2", text)
