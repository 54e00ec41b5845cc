"""Stretches of the session's audio as 16-bit mono PCM, for the review window to play.

:class:`PlaybackAudio` reads a stretch back from the audio file when asked for (through
:class:`~speechcal_core.audio.file_samples.FileSamples`, so the recording is never held
whole): by audio seconds, by session time through the sync model, or a frame set's
trigger word with a margin. Stretches are clipped to the file; a file that cannot be read
raises :class:`~speechcal_core.audio.errors.AudioError` naming it.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.audio.file_samples import FileSamples
from speechcal_core.audio.loader import open_audio

if TYPE_CHECKING:
    from speechcal_core.session.model import Trigger
    from speechcal_core.sync.model import SyncModel

#: heard before and after a trigger word's bounds
WORD_MARGIN_S = 0.25
#: heard around a trigger without word bounds (a set added by hand)
BY_HAND_SPAN_S = 1.0
#: a trigger shorter than this has no word bounds worth playing
MIN_WORD_S = 0.05
#: block length of :meth:`PlaybackAudio.blocks`
BLOCK_S = 0.25


@dataclass(frozen=True)
class Clip:
    """Mono int16 samples at ``rate`` Hz, the first at ``start_s`` seconds of audio time."""

    pcm: np.ndarray
    rate: int
    start_s: float

    @property
    def duration_s(self) -> float:
        return self.pcm.size / self.rate

    @property
    def end_s(self) -> float:
        return self.start_s + self.duration_s

    def to_bytes(self) -> bytes:
        """Little-endian 16-bit samples, as an audio output takes them."""
        return self.pcm.astype("<i2", copy=False).tobytes()


@dataclass(frozen=True)
class WordSpan:
    """The audio seconds to play for a trigger; ``by_hand``: it has no word bounds, so
    this is :data:`BY_HAND_SPAN_S` around its time."""

    start_s: float
    end_s: float
    by_hand: bool


def word_span(trigger: Trigger, margin_s: float = WORD_MARGIN_S,
              by_hand_s: float = BY_HAND_SPAN_S) -> WordSpan:
    """What to play for ``trigger``: its word with ``margin_s`` either side, or
    ``by_hand_s`` around its time when it has no word bounds (added with ``T``)."""
    if trigger.end_s - trigger.start_s < MIN_WORD_S:
        half = by_hand_s / 2
        return WordSpan(trigger.t_s - half, trigger.t_s + half, True)
    return WordSpan(trigger.start_s - margin_s, trigger.end_s + margin_s, False)


def to_pcm16(x: np.ndarray) -> np.ndarray:
    """Float samples in -1..1 as int16 (rounded, clipped)."""
    return np.clip(np.rint(x * 32768.0), -32768, 32767).astype(np.int16)


class PlaybackAudio:
    """The audio file at ``path``, mixed to mono, read back as int16 at ``rate`` Hz (by
    default the file's own rate)."""

    def __init__(self, path: str | Path, rate: int | None = None) -> None:
        self.path = Path(path)
        with open_audio(self.path) as f:  # AudioError naming the file
            self.rate_in = int(f.samplerate)
            frames = int(f.frames) if f.frames and f.frames > 0 else 0
        self.rate = int(rate or self.rate_in)
        self.samples = FileSamples(self.path, self.rate, rate_in=self.rate_in, size_in=frames)

    @property
    def duration_s(self) -> float:
        return self.samples.size / self.rate

    def index(self, t_s: float) -> int:
        """The sample at ``t_s`` audio seconds, clipped to the file."""
        return int(min(max(round(t_s * self.rate), 0), self.samples.size))

    def clip(self, start_s: float, end_s: float) -> Clip:
        """Audio seconds ``start_s`` .. ``end_s``, clipped to the file (empty outside it)."""
        a = self.index(start_s)
        b = max(a, self.index(end_s))
        return Clip(to_pcm16(self.samples.read(a, b)), self.rate, a / self.rate)

    def session_clip(self, start_ns: int, end_ns: int, sync: SyncModel) -> Clip:
        """Session time ``start_ns`` .. ``end_ns`` (camera clock), through ``sync``."""
        return self.clip(float(sync.to_audio(start_ns)), float(sync.to_audio(end_ns)))

    def word(self, trigger: Trigger) -> tuple[Clip, WordSpan]:
        """A trigger's word with its margin (see :func:`word_span`), and that span."""
        span = word_span(trigger)
        return self.clip(span.start_s, span.end_s), span

    def blocks(self, start_s: float, end_s: float | None = None,
               block_s: float = BLOCK_S) -> Iterator[Clip]:
        """``start_s`` .. ``end_s`` (default: the file's end) in consecutive clips of
        ``block_s``, read from the file one at a time (for playing as it goes)."""
        a = self.index(start_s)
        b = self.samples.size if end_s is None else max(a, self.index(end_s))
        step = max(1, round(block_s * self.rate))
        for i in range(a, b, step):
            j = min(i + step, b)
            yield Clip(to_pcm16(self.samples.read(i, j)), self.rate, i / self.rate)
