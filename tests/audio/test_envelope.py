"""The min/max envelope pyramid answers any zoom quickly and never hides a peak."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from audio_files import write_gated_tone

from speechcal_core.audio import AudioError, EnvelopePyramid, load_audio
from speechcal_core.audio.file_samples import FileSamples


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


class CountingSamples:
    """A sample source (as a file is) that counts the samples read from it."""

    def __init__(self, x: np.ndarray) -> None:
        self.x, self.read = x, 0

    def __getitem__(self, key: slice) -> np.ndarray:
        out = self.x[key]
        self.read += out.size
        return out


def test_queries_cost_the_pixels_not_the_samples_and_memory_is_small() -> None:
    rate = 48000
    x = np.zeros(20_000_000, np.float32)
    source = CountingSamples(x)
    pyr = EnvelopePyramid(x, rate, source=source)
    stored = sum(a.nbytes + b.nbytes for _, a, b in pyr.levels)
    assert stored < x.nbytes / 2
    for k in range(100):
        t, mn, mx = pyr.envelope(k, pyr.duration_s, 1920)
        assert 0 < t.size <= 1920 and mn.size == mx.size == t.size
    assert source.read == 0  # wide views come from the stored levels alone
    pyr.envelope(10.0, 10.5, 1920)  # a zoomed view reads its stretch, with room to pan
    assert 0 < source.read <= 2 * rate
    read = source.read
    pyr.envelope(10.1, 10.4, 1920)  # panning and zooming within it reads nothing more
    assert source.read == read


def test_empty_range_and_short_signal() -> None:
    pyr = EnvelopePyramid(np.zeros(5, np.float32), 100)
    t, _, _ = pyr.envelope(0, 1, 10)
    assert t.size == 5
    t, _, _ = pyr.envelope(2.0, 3.0, 10)
    assert t.size == 0


def _expected(x: np.ndarray, rate: float, t0: float, t1: float,
              width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What a pyramid over every level from 16 samples up draws, straight from ``x``: the
    samples below 2 per pixel, each pixel's own min and max below 32."""
    i0, i1 = int(np.floor(t0 * rate)), int(np.ceil(t1 * rate))
    per_px = (i1 - i0) / width
    if per_px < 2:
        return np.arange(i0, i1) / rate, x[i0:i1], x[i0:i1]
    if per_px < 32:  # each pixel's own samples
        edges = np.unique(np.linspace(i0, i1, width + 1).astype(np.int64))
        mn = np.array([x[a:b].min() for a, b in pairwise(edges)])
        mx = np.array([x[a:b].max() for a, b in pairwise(edges)])
        return (edges[:-1] + np.diff(edges) / 2) / rate, mn, mx
    size = 16
    while size * 4 * 2 <= per_px and -(-x.size // size) > 1:
        size *= 4
    b0, b1 = i0 // size, min(-(-i1 // size), -(-x.size // size))
    edges = np.unique(np.linspace(b0, b1, width + 1).astype(np.int64))
    mn = np.array([x[a * size:b * size].min() for a, b in pairwise(edges)])
    mx = np.array([x[a * size:b * size].max() for a, b in pairwise(edges)])
    t = (edges[:-1] * size + np.diff(edges) * size / 2) / rate
    return t, mn, mx


def _write(path: Path, rate: int, seconds: float, channels: int, **kw) -> Path:
    return write_gated_tone(path, rate, seconds, channels, seed=5, tone_hz=220.0, gate_hz=0.3, **kw)


@pytest.mark.parametrize(("name", "channels", "kw"), [
    ("a.wav", 1, {}),
    ("a.ogg", 2, {"format": "OGG", "subtype": "VORBIS"}),  # stretches read after a seek
])
def test_file_pyramid_holds_no_samples_and_draws_the_loaded_ones(
        tmp_path: Path, name: str, channels: int, kw: dict) -> None:
    p = _write(tmp_path / name, 48000, 21.3, channels, **kw)  # several decode blocks
    loaded = load_audio(p).samples
    from_file = EnvelopePyramid.from_file(p)
    in_memory = EnvelopePyramid(loaded, 48000)
    after_load = EnvelopePyramid(loaded, 48000, source=FileSamples(
        p, 48000, rate_in=48000, size_in=loaded.size))
    assert from_file.size == loaded.size
    for pyr in (from_file, after_load):
        assert isinstance(pyr.source, FileSamples)
        assert not any(isinstance(v, np.ndarray) and v.size >= loaded.size / 100
                       for v in vars(pyr).values())
        assert pyr.nbytes < loaded.nbytes / 20
    for (_, a, b), (_, c, d) in zip(from_file.levels, in_memory.levels, strict=True):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(b, d)
    rng = np.random.default_rng(2)
    views = [(0.0, 21.3, 800), (3.0, 3.01, 1000), (20.9, 21.3, 1920), (5.0, 5.9, 300),
             (7.0, 9.5, 1000), (0.0, 1e-3, 100),  # raw, 16- and 64-sample buckets, kept
             (4.0, 4.5, 1400), (6.0, 6.1, 1200)]  # a pixel's own samples
    views += [(a, a + w, int(rng.integers(100, 2000)))
              for a, w in zip(rng.uniform(0, 20, 20), rng.uniform(1e-3, 4, 20),
                              strict=True)]
    for t0, t1, width in views:
        want = _expected(loaded, 48000, t0, t1, width)
        for pyr in (from_file, after_load, in_memory):
            got = pyr.envelope(t0, t1, width)
            for g, w in zip(got, want, strict=True):
                np.testing.assert_array_equal(g, w, err_msg=f"{name} {t0} {t1} {width}")
    assert from_file.unreadable is None


def test_moved_file_draws_coarse_levels_and_says_why(tmp_path: Path) -> None:
    p = _write(tmp_path / "a.wav", 16000, 10.0, 1)
    pyr = EnvelopePyramid.from_file(p)
    p.rename(tmp_path / "moved.wav")
    t, mn, mx = pyr.envelope(2.0, 2.05, 1000)  # raw samples asked
    assert pyr.unreadable and "a.wav" in pyr.unreadable
    assert 0 < t.size < 1000 and np.all(mn <= mx)
    t, _, _ = pyr.envelope(0.0, 10.0, 100)  # levels kept still draw
    assert t.size == 100


def test_empty_file_is_refused(tmp_path: Path) -> None:
    with pytest.raises(AudioError, match="empty"):
        EnvelopePyramid.from_file(_touch(tmp_path / "e.wav"))


def _touch(path: Path) -> Path:
    path.write_bytes(b"")
    return path
