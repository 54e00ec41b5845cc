"""The backend interface: every recogniser returns timed words in audio seconds."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from speechcal_core.audio import Audio
    from speechcal_core.speech.matching import TriggerSpec


@dataclass(frozen=True)
class Word:
    """One recognised word: audio-time bounds, a 0..1 score and the backend that found it."""

    word: str
    start_s: float
    end_s: float
    score: float = 1.0
    source: str = ""

    @property
    def t(self) -> float:
        """The word's time: the mean of its start and end."""
        return (self.start_s + self.end_s) / 2.0

    def to_json(self) -> dict[str, float | str]:
        """The ``detect`` JSON entry (DESIGN.md §2)."""
        return {"word": self.word, "start": round(self.start_s, 4), "end": round(self.end_s, 4),
                "t": round(self.t, 4), "score": round(self.score, 4)}


@runtime_checkable
class SpeechBackend(Protocol):
    """A recogniser: audio in, timed words out.

    Backends that search for the trigger words (pocketsphinx, query by example) use
    ``spec``; full transcribers (Whisper, transcripts) may ignore it and return every word.
    """

    name: str

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        """Timed words found in ``audio`` (16 kHz mono float32 preferred)."""
        ...
