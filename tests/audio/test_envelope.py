"""The min/max envelope pyramid answers any zoom quickly and never hides a peak."""

from __future__ import annotations

import time

import numpy as np

from speechcal_core.audio import EnvelopePyramid


def _signal(n: int = 2_000_003) -> np.ndarray:
    rng = np.random.default_rng(1)
    return (0.1 * rng.standard_normal(n)).astype(np.float32)


def test_zoomed_out_envelope_keeps_extremes() -> None:
    x = _signal()
    x[1_234_567] = 0.99
    x[77] = -0.98
    pyr = EnvelopePyramid(x, 16000)
    t, mn, mx = pyr.envelope(0.0, pyr.duration_s, 800)
    assert t.size <= 800 and mn.size == mx.size == t.size
    assert np.all(np.diff(t) > 0)
    assert mx.max() == np.float32(0.99) and mn.min() == np.float32(-0.98)
    assert np.all(mn <= mx)


def test_partial_range_bounds_the_samples() -> None:
    x = _signal()
    pyr = EnvelopePyramid(x, 16000)
    t, mn, mx = pyr.envelope(10.0, 20.0, 500)
    assert t[0] >= 9.9 and t[-1] <= 20.1
    around = x[159000:321000]  # buckets may reach a little past the range
    assert around.min() <= mn.min() and mx.max() <= around.max()
    assert abs(mx.max() - x[160000:320000].max()) < 0.05


def test_deep_zoom_returns_raw_samples() -> None:
    x = _signal(10_000)
    pyr = EnvelopePyramid(x, 1000)
    t, mn, mx = pyr.envelope(1.0, 1.1, 1000)
    assert np.array_equal(mn, mx)
    assert np.array_equal(mn, x[1000:1100])
    assert np.allclose(t, np.arange(1000, 1100) / 1000)


def test_queries_are_fast_and_memory_small() -> None:
    x = np.zeros(20_000_000, np.float32)
    pyr = EnvelopePyramid(x, 48000)
    stored = sum(a.nbytes + b.nbytes for _, a, b in pyr.levels)
    assert stored < x.nbytes / 2
    t0 = time.perf_counter()
    for k in range(100):
        pyr.envelope(k, pyr.duration_s, 1920)
    assert (time.perf_counter() - t0) / 100 < 0.01


def test_empty_range_and_short_signal() -> None:
    pyr = EnvelopePyramid(np.zeros(5, np.float32), 100)
    t, _, _ = pyr.envelope(0, 1, 10)
    assert t.size == 5
    t, _, _ = pyr.envelope(2.0, 3.0, 10)
    assert t.size == 0
