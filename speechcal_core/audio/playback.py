"""Stretches of the session's audio as 16-bit mono PCM, for the review window to play.

:class:`PlaybackAudio` reads a stretch back from the audio file when asked for (through
:class:`~speechcal_core.audio.file_samples.FileSamples`, so the recording is never held
whole): by audio seconds, by session time through the sync model, or a frame set's
trigger word with a margin. Stretches are clipped to the file; a file that cannot be read
raises :class:`~speechcal_core.audio.errors.AudioError` naming it.

Two small pieces of arithmetic for playing them, kept here without Qt so they are tested
without a sound device: :func:`heard_s` (how far into a stretch the sound has got, from
what the audio output reports) and :class:`RestartThrottle` (a playhead dragged while
playing restarts the sound at most once per interval).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.audio.file_samples import FileSamples
from speechcal_core.audio.loader import decoded_frames, header_frames, open_audio

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
#: a playhead moved while playing restarts the sound at most this often
RESTART_INTERVAL_S = 0.12


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
    """The audio file at ``path``, mixed to mono (or its ``channel``), read back as int16
    at ``rate`` Hz (by default the file's own rate)."""

    def __init__(self, path: str | Path, rate: int | None = None,
                 channel: int | None = None) -> None:
        self.path = Path(path)
        with open_audio(self.path, channel) as f:  # AudioError naming the file
            self.rate_in = int(f.samplerate)
            frames = header_frames(f)
            if frames is None:
                frames = decoded_frames(f, self.path)
        self.rate = int(rate or self.rate_in)
        self.samples = FileSamples(self.path, self.rate, rate_in=self.rate_in, size_in=frames,
                                   channel=channel)

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

    def start_index(self, start_s: float, lead_in: bool = False) -> int:
        """The first sample to play from ``start_s``: clipped to the file; with
        ``lead_in`` one before the file's start is kept (negative: silence to play until
        the file starts, so the sound keeps time with a playhead there)."""
        if lead_in:
            return min(round(start_s * self.rate), self.samples.size)
        return self.index(start_s)

    def end_index(self, end_s: float | None) -> int:
        """The sample after the last to play up to ``end_s`` (None: the file's end)."""
        return self.samples.size if end_s is None else self.index(end_s)

    def blocks(self, start_s: float, end_s: float | None = None,
               block_s: float = BLOCK_S, *, lead_in: bool = False) -> Iterator[Clip]:
        """``start_s`` .. ``end_s`` (default: the file's end) in consecutive clips of
        ``block_s``, read from the file one at a time (for playing as it goes); with
        ``lead_in``, a start before the file begins with silence (see
        :meth:`start_index`)."""
        a = self.start_index(start_s, lead_in)
        b = max(a, self.end_index(end_s))
        step = max(1, round(block_s * self.rate))
        for i in range(a, b, step):
            j = min(i + step, b)
            silent = max(min(j, 0) - i, 0)  # samples before the file's start
            pcm = (to_pcm16(self.samples.read(i + silent, j)) if j > i + silent
                   else np.zeros(0, np.int16))
            if silent:
                pcm = np.concatenate([np.zeros(silent, np.int16), pcm])
            yield Clip(pcm, self.rate, i / self.rate)


def heard_s(start_s: float, rate: int, written: int, buffered: int,
            processed_us: int) -> float:
    """Audio seconds the sound of a stretch has got to: the stretch's first sample at
    ``start_s``, ``written`` samples (at ``rate`` Hz) handed to the output so far,
    ``buffered`` of them still in its buffer, and ``processed_us`` what the output says
    it has processed (``QAudioSink.processedUSecs``).

    The output's figure, but never past what has left its buffer: backends differ in
    whether they count what they hold (PySide6 6.11 on PulseAudio counts exactly what
    left the buffer, so the figure is used as it is there).
    """
    left = max(written - buffered, 0) / rate
    return start_s + min(max(processed_us, 0) / 1e6, left)


class RestartThrottle:
    """When to restart the sound for a playhead that keeps moving while playing (a drag
    of the playhead or the clap handle): the first move at once, moves within
    ``interval_s`` of the last restart together once that interval is over, from where
    the playhead then is. Times are the caller's clock (``time.monotonic()``)."""

    def __init__(self, interval_s: float = RESTART_INTERVAL_S) -> None:
        self.interval_s = interval_s
        self._last = -float("inf")
        #: a restart is waiting for the interval to end
        self.pending = False

    def request(self, now: float) -> float | None:
        """The playhead moved at ``now``: seconds until the restart (0: restart now,
        then call :meth:`done`), or None when one is already waiting (it will start
        from the latest position)."""
        if self.pending:
            return None
        wait = self._last + self.interval_s - now
        if wait <= 0:
            return 0.0
        self.pending = True
        return wait

    def done(self, now: float) -> None:
        """The sound was (re)started at ``now``."""
        self._last = now
        self.pending = False

    def cancel(self) -> None:
        """Play stopped: nothing is waiting any more."""
        self.pending = False
