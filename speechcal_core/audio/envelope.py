"""Min/max envelope pyramid of an audio signal, for instant waveform display at any zoom."""

from __future__ import annotations

import numpy as np

BASE = 16  # samples per bucket at level 0
FACTOR = 4  # buckets merged per level


class EnvelopePyramid:
    """Per-level min/max of ``BASE * FACTOR**k``-sample buckets over a mono signal.

    Memory is about a third of the signal; :meth:`envelope` answers any (range, width)
    query in time proportional to the pixel width, not to the number of samples.
    """

    def __init__(self, samples: np.ndarray, rate: float) -> None:
        self.samples = np.asarray(samples, dtype=np.float32)
        self.rate = float(rate)
        self.levels: list[tuple[int, np.ndarray, np.ndarray]] = []
        x = self.samples
        n = x.size - x.size % BASE
        if n == 0:
            return
        mn = x[:n].reshape(-1, BASE).min(axis=1)
        mx = x[:n].reshape(-1, BASE).max(axis=1)
        if n < x.size:  # the ragged tail becomes one last bucket
            mn = np.append(mn, x[n:].min())
            mx = np.append(mx, x[n:].max())
        size = BASE
        self.levels.append((size, mn, mx))
        while mn.size > 1:
            pad = (-mn.size) % FACTOR
            if pad:
                mn = np.concatenate([mn, np.full(pad, mn[-1], np.float32)])
                mx = np.concatenate([mx, np.full(pad, mx[-1], np.float32)])
            mn = mn.reshape(-1, FACTOR).min(axis=1)
            mx = mx.reshape(-1, FACTOR).max(axis=1)
            size *= FACTOR
            self.levels.append((size, mn, mx))

    @property
    def duration_s(self) -> float:
        """Length of the signal in seconds."""
        return self.samples.size / self.rate

    def envelope(self, t0: float, t1: float,
                 width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, min, max) for ``width`` pixels spanning audio seconds ``[t0, t1]``.

        When a pixel spans fewer samples than a bucket, the raw samples are returned
        instead (``min == max``), so at deep zoom the curve is the waveform itself.
        """
        n = self.samples.size
        width = max(int(width), 1)
        i0 = int(np.clip(np.floor(t0 * self.rate), 0, n))
        i1 = int(np.clip(np.ceil(t1 * self.rate), 0, n))
        if i1 <= i0:
            empty = np.empty(0, np.float32)
            return np.empty(0), empty, empty
        per_px = (i1 - i0) / width
        if per_px < 2 * BASE or not self.levels:
            s = self.samples[i0:i1]
            return np.arange(i0, i1) / self.rate, s, s
        size, mn, mx = self.levels[0]
        for lv in self.levels:
            if lv[0] * 2 > per_px:
                break
            size, mn, mx = lv
        b0, b1 = i0 // size, min(-(-i1 // size), mn.size)
        edges = np.linspace(b0, b1, width + 1).astype(np.int64)
        edges = np.unique(edges)
        starts = edges[:-1]
        out_mn = np.minimum.reduceat(mn[b0:b1], starts - b0)
        out_mx = np.maximum.reduceat(mx[b0:b1], starts - b0)
        t = (starts * size + (edges[1:] - starts) * size / 2) / self.rate
        return t, out_mn, out_mx
