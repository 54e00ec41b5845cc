"""Min/max envelope pyramid of an audio signal, for instant waveform display at any zoom."""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

import numpy as np

from speechcal_core.audio.errors import AudioError

BASE = 16  # samples per bucket at level 0
#: below this many samples per pixel the samples themselves are drawn; above it, a pixel's
#: min and max (24 000 raw points for half a second of 48 kHz audio took 200 ms to draw)
RAW_BELOW_PER_PX = 2
FACTOR = 4  # buckets merged per level
#: samples per bucket of the finest level kept; finer views (up to ``2 * KEPT`` samples
#: per pixel: 20 s of 48 kHz audio over 1920 pixels) read their stretch from the source
KEPT = BASE * FACTOR * FACTOR


class Stretches(Protocol):
    """Samples read by slice, ``x[a:b]`` (a numpy array, or a ``FileSamples``)."""

    def __getitem__(self, key: slice) -> np.ndarray: ...


class EnvelopePyramid:
    """Per-level min/max of ``BASE * FACTOR**k``-sample buckets over a mono signal.

    Only levels of ``KEPT`` samples per bucket and coarser are stored (a 24th of the
    signal's bytes); views finer than those, down to the raw waveform, are computed from a
    short stretch of ``source`` (the samples themselves when none is given; a
    :class:`~speechcal_core.audio.file_samples.FileSamples` keeps them in the file).
    :meth:`envelope` answers any (range, width) query in time proportional to the pixel
    width, not to the number of samples, with the same values at every zoom.
    """

    def __init__(self, samples: np.ndarray, rate: float, *,
                 source: Stretches | None = None) -> None:
        x = np.asarray(samples, dtype=np.float32)
        self.rate = float(rate)
        self.size = int(x.size)
        self.source: Stretches = x if source is None else source
        self.unreadable: str | None = None  # why the source failed, if it did
        self._cache: tuple[int, np.ndarray] | None = None
        mn, mx = _buckets(x, KEPT)
        self.levels = _levels(mn, mx, self.size)

    @classmethod
    def from_file(cls, path: str | Path, *,
                  channel: int | None = None) -> EnvelopePyramid:
        """The pyramid of an audio file's samples (as :func:`load_audio` gives them at the
        file's own rate), built block by block so the whole audio is never in memory."""
        from speechcal_core.audio.file_samples import FileSamples
        from speechcal_core.audio.loader import NumberCheck, mono_blocks, open_audio

        mins, maxs, n = [], [], 0
        numbers = NumberCheck(path)
        with open_audio(path, channel) as f:
            rate = int(f.samplerate)
            for block in map(numbers.clean, mono_blocks(f, path, channel)):
                mn, mx = _buckets(block, KEPT)  # blocks are whole buckets but the last
                mins.append(mn)
                maxs.append(mx)
                n += block.size
        if n == 0:
            raise AudioError(f"{path}: holds no audio samples; record or copy the audio again")
        numbers.check()
        pyramid = cls.__new__(cls)
        pyramid.rate = float(rate)
        pyramid.size = n
        pyramid.source = FileSamples(path, rate, rate_in=rate, size_in=n, channel=channel)
        pyramid.unreadable = None
        pyramid._cache = None
        pyramid.levels = _levels(np.concatenate(mins), np.concatenate(maxs), n)
        return pyramid

    @property
    def duration_s(self) -> float:
        """Length of the signal in seconds."""
        return self.size / self.rate

    @property
    def nbytes(self) -> int:
        """Bytes held: the stored levels, the last stretch read, an in-memory source."""
        held = sum(a.nbytes + b.nbytes for _, a, b in self.levels)
        held += self._cache[1].nbytes if self._cache is not None else 0
        return held + getattr(self.source, "nbytes", 0)

    def envelope(self, t0: float, t1: float,
                 width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, min, max) for ``width`` pixels spanning audio seconds ``[t0, t1]``.

        When a pixel spans fewer samples than a bucket, the raw samples are returned
        instead (``min == max``), so at deep zoom the curve is the waveform itself.
        """
        n = self.size
        width = max(int(width), 1)
        i0 = int(np.clip(np.floor(t0 * self.rate), 0, n))
        i1 = int(np.clip(np.ceil(t1 * self.rate), 0, n))
        if i1 <= i0:
            empty = np.empty(0, np.float32)
            return np.empty(0), empty, empty
        per_px = (i1 - i0) / width
        if (per_px < 2 * KEPT or not self.levels) and self.unreadable is None:
            try:
                return self._from_samples(i0, i1, per_px, width)
            except AudioError as exc:  # the file moved or changed: coarse levels only
                self.unreadable = str(exc)
                self._cache = None
            if not self.levels:
                empty = np.empty(0, np.float32)
                return np.empty(0), empty, empty
        size, mn, mx = self.levels[0]
        for lv in self.levels:
            if lv[0] * 2 > per_px:
                break
            size, mn, mx = lv
        b0, b1 = i0 // size, min(-(-i1 // size), mn.size)
        starts, ends = _pixels(b0, b1, width)
        out_mn = np.minimum.reduceat(mn[b0:b1], starts - b0)
        out_mx = np.maximum.reduceat(mx[b0:b1], starts - b0)
        t = (starts * size + (ends - starts) * size / 2) / self.rate
        return t, out_mn, out_mx

    def _from_samples(self, i0: int, i1: int, per_px: float,
                      width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What the finer levels (or the raw samples) give, from a stretch of the source."""
        s = self._stretch(i0, i1) if per_px < 2 * BASE else None
        if s is not None and per_px < RAW_BELOW_PER_PX:
            return np.arange(i0, i1) / self.rate, s, s
        if s is not None:  # each pixel's min and max over its own samples
            starts, ends = _pixels(i0, i1, width)
            t = (starts + (ends - starts) / 2) / self.rate
            return t, np.minimum.reduceat(s, starts - i0), np.maximum.reduceat(s, starts - i0)
        size = BASE
        while size * FACTOR < KEPT and size * FACTOR * 2 <= per_px:
            size *= FACTOR
        b0, b1 = i0 // size, min(-(-i1 // size), -(-self.size // size))
        s = self._stretch(b0 * size, min(b1 * size, self.size))
        starts, ends = _pixels(b0, b1, width)
        at = (starts - b0) * size  # bucket mins of mins: the same as over the samples
        t = (starts * size + (ends - starts) * size / 2) / self.rate
        return t, np.minimum.reduceat(s, at), np.maximum.reduceat(s, at)

    def _stretch(self, a: int, b: int) -> np.ndarray:
        """Samples ``a`` .. ``b``; from a file, read with room either side for panning."""
        if isinstance(self.source, np.ndarray):
            return self.source[a:b]
        if self._cache is not None:
            c0, held = self._cache
            if c0 <= a and b <= c0 + held.size:
                return held[a - c0:b - c0]
        self._cache = None  # the old stretch goes before the new one is read
        room = (b - a) // 2
        c0, c1 = max(0, a - room), min(self.size, b + room)
        held = np.asarray(self.source[c0:c1], dtype=np.float32)
        self._cache = (c0, held)
        return held[a - c0:b - c0]


def _buckets(x: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Min and max of each ``size``-sample bucket of ``x``, the ragged tail one more."""
    n = x.size - x.size % size
    mn = x[:n].reshape(-1, size).min(axis=1)
    mx = x[:n].reshape(-1, size).max(axis=1)
    if n < x.size:
        mn = np.append(mn, x[n:].min())
        mx = np.append(mx, x[n:].max())
    return mn.astype(np.float32, copy=False), mx.astype(np.float32, copy=False)


def _levels(mn: np.ndarray, mx: np.ndarray,
            n: int) -> list[tuple[int, np.ndarray, np.ndarray]]:
    """``KEPT``-sample buckets and every coarser level up to one bucket (none under BASE)."""
    if n < BASE:
        return []
    size = KEPT
    levels = [(size, mn, mx)]
    while mn.size > 1:
        pad = (-mn.size) % FACTOR
        if pad:
            mn = np.concatenate([mn, np.full(pad, mn[-1], np.float32)])
            mx = np.concatenate([mx, np.full(pad, mx[-1], np.float32)])
        mn = mn.reshape(-1, FACTOR).min(axis=1)
        mx = mx.reshape(-1, FACTOR).max(axis=1)
        size *= FACTOR
        levels.append((size, mn, mx))
    return levels


def _pixels(b0: int, b1: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """First bucket of each pixel (non-empty ones) and where the next one starts."""
    edges = np.unique(np.linspace(b0, b1, width + 1).astype(np.int64))
    return edges[:-1], edges[1:]
