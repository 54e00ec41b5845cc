"""Trigger words: normalising text and picking the words that match the configured triggers."""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechUsageError

DEFAULT_TRIGGERS = ("capture",)
DEFAULT_SENSITIVITY = 0.5

_EDGE_PUNCT = re.compile(r"^[^\w']+|[^\w']+$")


def normalize_word(text: str) -> str:
    """Case-fold and strip surrounding punctuation: ``"Capture!"`` -> ``"capture"``.

    Apostrophes inside a word are kept (``"that's"``); inflections stay distinct.
    """
    s = unicodedata.normalize("NFKC", text).strip().casefold()
    s = s.replace("\u2019", "'")
    s = _EDGE_PUNCT.sub("", s)
    return s.strip("'")


@dataclass(frozen=True)
class TriggerSpec:
    """What to look for: trigger words, optional pronunciations, one sensitivity (0..1).

    ``sensitivity`` 0.5 is the balanced default; higher finds more (and more false
    alarms), lower finds fewer. ``pronunciations`` maps a word to ARPAbet phones for words
    the pocketsphinx dictionary lacks, e.g. ``{"kalibr": "K AE L IH B ER"}``.
    """

    words: tuple[str, ...] = DEFAULT_TRIGGERS
    sensitivity: float = DEFAULT_SENSITIVITY
    pronunciations: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        words = tuple(dict.fromkeys(normalize_word(w) for w in self.words if normalize_word(w)))
        if not words:
            raise SpeechUsageError(
                "no trigger word given; pass at least one, e.g. --trigger capture")
        bad = [w for w in words if not re.fullmatch(r"[\w']+", w)]
        if bad:
            raise SpeechUsageError(
                f"trigger {bad[0]!r} is not a single word; give each word with its own --trigger"
            )
        if not 0.0 <= float(self.sensitivity) <= 1.0:
            raise SpeechUsageError(
                f"sensitivity {self.sensitivity} is outside 0..1; 0.5 is the balanced default"
            )
        prons = {normalize_word(k): " ".join(v.upper().split())
                 for k, v in dict(self.pronunciations).items()}
        object.__setattr__(self, "words", words)
        object.__setattr__(self, "sensitivity", float(self.sensitivity))
        object.__setattr__(self, "pronunciations", prons)

    def matches(self, text: str) -> str | None:
        """The configured trigger word ``text`` stands for, or None."""
        w = normalize_word(text)
        return w if w in self.words else None


def match_triggers(words: Iterable[Word], spec: TriggerSpec) -> list[Word]:
    """The words that are triggers, renamed to their configured form, in time order."""
    out = []
    for w in words:
        hit = spec.matches(w.word)
        if hit is not None:
            out.append(Word(hit, w.start_s, w.end_s, w.score, w.source))
    return sorted(out, key=lambda w: (w.start_s, w.end_s))
