"""The clap search in bounded memory: block by block it finds the very same claps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sync_recordings import make_session

import speechcal_core.sync.clap_video as clap_video
import speechcal_core.sync.pipeline as sync_pipeline
from speechcal_core.sources import open_recording
from speechcal_core.sync.pipeline import SEARCH_S, video_clap_candidates


def _candidates(out: Path, truth: dict) -> dict[str, list]:
    with open_recording(out / truth["recording"]) as src:
        return {s.name: video_clap_candidates(src, s.name, s.first_ns,
                                              s.first_ns + int(SEARCH_S * 1e9))
                for s in src.streams}


def test_clap_search_in_tiny_blocks_finds_the_same_claps(
        session_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Frame differences, backgrounds, residuals and their median are worked out a block
    (and a band of rows) at a time so that a region as large as the picture never needs
    all its frames as floats; a block of one frame, a band of a few rows and a cache of
    one frame must give the claps, scores and sub-frame times of one block, bit for bit."""
    out, truth = make_session(session_root, seed=0)
    whole = _candidates(out, truth)
    assert all(whole.values())
    monkeypatch.setattr(clap_video, "BLOCK_BYTES", 1 << 12)
    monkeypatch.setattr(sync_pipeline, "DETAIL_CACHE_BYTES", 0)
    assert _candidates(out, truth) == whole


@pytest.mark.parametrize("n", [1, 2, 5, 1000, 4097])
def test_median_of_chunks_is_numpys_median(n: int) -> None:
    """The residuals' median is counted from the values' bit patterns, chunk by chunk; it
    is np.median exactly (even counts: the mean of the middle two), ties and zeros too."""
    rng = np.random.default_rng(n)
    for values in (np.abs(rng.normal(0, 3, n)), np.zeros(n), rng.integers(0, 3, n),
                   -rng.random(n)):  # negative values: np.median itself
        x = values.astype(np.float32)
        parts = np.array_split(x, 3)
        assert clap_video._median_of(lambda parts=parts: parts) == float(np.median(x))


def test_full_resolution_frames_are_kept_within_a_byte_budget(
        session_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The frames kept for the clap timing were 160 float32 frames (590 MB at 1280x720);
    now 8-bit frames stay uint8 gray and the most recently read are kept up to a byte
    budget (here ten frames)."""
    out, truth = make_session(session_root, seed=0)
    with open_recording(out / truth["recording"]) as src:
        stream = src.streams[0].name
        reads: list[int] = []

        class CountingSource:
            """The recording, counting the frames read from it."""

            def frame(self, name: str, i: int) -> np.ndarray:
                reads.append(i)
                return src.frame(name, i)

        height, width = src.frame(stream, 0).shape[:2]
        monkeypatch.setattr(sync_pipeline, "DETAIL_CACHE_BYTES", 10 * width * height)
        index = list(range(100, 140))
        info = src.streams[0]
        detail = sync_pipeline._detail_reader(CountingSource(), info, index, None)
        frames = [detail(j) for j in range(40)]
        assert all(f.dtype == np.uint8 and f.shape == (height, width) for f in frames)
        assert all(np.array_equal(f, clap_video.gray_full(src.frame(stream, i)))
                   for f, i in zip(frames, index, strict=True))
        for j in range(30, 40):  # the last ten are kept
            assert detail(j) is frames[j]
        detail(0)
    assert reads == [*index, 100]  # the first was let go, and is read again
