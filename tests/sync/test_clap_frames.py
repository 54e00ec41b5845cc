"""The clap search reads a JPEG frame's luma alone (no colour) for both its passes, every
other kind of frame as before."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sync_recordings import make_session

import speechcal_core.sync.pipeline as sync_pipeline
from speechcal_core.audio import load_audio
from speechcal_core.sources import open_recording
from speechcal_core.sources.decode import compressed_payload
from speechcal_core.sources.depth import stream_depth
from speechcal_core.sync.clap_frames import full_gray, small_gray
from speechcal_core.sync.clap_video import gray_full, to_gray_small
from speechcal_core.sync.pipeline import SEARCH_S, sync_recording, video_clap_candidates


class CountingSource:
    """A recording that counts the frames decoded in full (``frame``)."""

    def __init__(self, source) -> None:
        self.source, self.decoded = source, []

    def __getattr__(self, name: str):
        return getattr(self.source, name)

    def frame(self, stream: str, i: int) -> np.ndarray:
        self.decoded.append(i)
        return self.source.frame(stream, i)


def _search(source) -> list:
    return [c for s in source.streams
            for c in video_clap_candidates(source, s.name, s.first_ns,
                                           s.first_ns + int(SEARCH_S * 1e9))]


def test_jpeg_clap_search_decodes_no_frame_in_full_colour(session_root: Path) -> None:
    """Full-colour decoding of every frame of the search window took most of a sync's
    time; JPEG frames are now decoded to their luma alone."""
    out, truth = make_session(session_root, seed=0)
    with open_recording(out / truth["recording"]) as src:
        counting = CountingSource(src)
        for s in src.streams:
            stream_depth(counting, s.name)  # one frame read to learn the stream is 8-bit
        counting.decoded.clear()
        found = _search(counting)
    assert len(found) >= 2  # each camera saw the clap
    assert counting.decoded == []


def test_a_folder_of_jpeg_files_is_read_as_luma_and_finds_the_bags_clap(
        session_root: Path, tmp_path: Path) -> None:
    """JPEG image files (``<stamp_ns>.jpg``) are read as luma as bag payloads are: the
    same bytes in a folder give the same clap, with no frame decoded in full colour."""
    out, truth = make_session(session_root, seed=0)
    with open_recording(out / truth["recording"]) as bag:
        info = bag.streams[0]
        folder = tmp_path / "cam0"
        folder.mkdir()
        for i, stamp in enumerate(bag.stamps(info.name)):
            payload = compressed_payload(bag.raw(info.name, i))
            (folder / f"{int(stamp)}.jpg").write_bytes(bytes(payload))
        end = info.first_ns + int(SEARCH_S * 1e9)
        from_bag = video_clap_candidates(bag, info.name, info.first_ns, end)
    with open_recording(folder) as files:
        counting = CountingSource(files)
        (name,) = [s.name for s in files.streams]
        stream_depth(counting, name)
        counting.decoded.clear()
        from_files = video_clap_candidates(counting, name, info.first_ns, end)
    assert from_bag and counting.decoded == []
    assert [(c.clap_ns, c.sigma_ns, c.method) for c in from_files] == \
        [(c.clap_ns, c.sigma_ns, c.method) for c in from_bag]


def test_jpeg_frames_read_as_luma_find_the_same_claps(
        session_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The claps found from JPEG frames read as luma are those found from full-colour
    decoding: the same cameras, frames and clap stamps. The V fits' standard errors (from
    the fine pass's luma instead of gray made from colour) move by a few hundred ns at
    most, and with them the drift (its cameras weighted by them) by about 0.0004 ppm."""
    out, truth = make_session(session_root, seed=1, claps=2, duration=20.0)
    with open_recording(out / truth["recording"]) as src:
        audio = out / "audio.ogg"
        now = sync_recording(src, load_audio(audio))
        monkeypatch.setattr(sync_pipeline, "small_gray", lambda source, info, i, depth:
                            to_gray_small(source.frame(info.name, i), depth=depth))
        monkeypatch.setattr(sync_pipeline, "full_gray", lambda source, info, i, depth:
                            gray_full(source.frame(info.name, i), depth))
        before = sync_recording(src, load_audio(audio))
    assert len(now.claps) == len(before.claps) == 2
    assert abs(now.model.offset_ns - before.model.offset_ns) <= 10
    assert now.model.drift == pytest.approx(before.model.drift, abs=1e-9)
    pairs = [(a, b) for x, y in zip(now.claps, before.claps, strict=True)
             for a, b in zip(x.cameras, y.cameras, strict=True)]
    assert all((a.name, a.clap_ns, a.frame_index, a.method)
               == (b.name, b.clap_ns, b.frame_index, b.method) for a, b in pairs)
    assert all(a.sigma_ns == pytest.approx(b.sigma_ns, rel=0.01) for a, b in pairs)


def test_jpeg_frames_read_as_luma_match_the_full_decoding(session_root: Path) -> None:
    """A coarse-pass frame read from a JPEG's luma has the work size, scale and values of
    one decoded in full colour and made small (an area average keeps fractions of a level:
    libjpeg's reduced decoding, in whole levels, was 0.25 off on average and moved a weak
    clap's coarse V fit); the fine pass's luma nearly the full decoding's gray."""
    out, truth = make_session(session_root, seed=0)
    with open_recording(out / truth["recording"]) as src:
        info = src.streams[0]
        for i in (0, info.count // 2, info.count - 1):
            small, scale = small_gray(src, info, i, None)
            want, want_scale = to_gray_small(src.frame(info.name, i))
            assert small.dtype == np.float32 and small.shape == want.shape
            assert scale == want_scale
            off = np.abs(small - want)
            # luma and gray made from colour differ by a level in a few pixels at most
            assert np.mean(off) < 0.01 and np.mean(off > 0.3) < 0.01
            full = full_gray(src, info, i, None)
            assert full.dtype == np.uint8 and full.shape == (info.height, info.width)
            assert np.mean(np.abs(full.astype(float) - gray_full(src.frame(info.name, i)))) < 0.1


def test_a_weak_clap_read_from_jpeg_luma_is_timed_as_from_the_full_decoding(
        session_root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The first camera of this session sees a weak clap. Read by libjpeg's reduced
    decoding, in whole levels, its coarse V fit moved so far that the full-resolution
    fit, more than half a frame off it, was refused: the clap came 83 ms early. Read as
    luma and area-resized, the clap is the full decoding's, about a millisecond from the
    truth."""
    out, truth = make_session(session_root, seed=4, cameras=3, size="640x480",
                              duration=30.0, drift_ppm=5.0)
    with open_recording(out / truth["recording"]) as src:
        info = src.streams[0]
        end = info.first_ns + int(SEARCH_S * 1e9)
        now = video_clap_candidates(src, info.name, info.first_ns, end)
        monkeypatch.setattr(sync_pipeline, "small_gray", lambda source, info, i, depth:
                            to_gray_small(source.frame(info.name, i), depth=depth))
        monkeypatch.setattr(sync_pipeline, "full_gray", lambda source, info, i, depth:
                            gray_full(source.frame(info.name, i), depth))
        before = video_clap_candidates(src, info.name, info.first_ns, end)
    seen_ns = truth["claps"][0]["session_ns"] + truth["cameras"][0]["clock_offset_ns"]
    assert now and before
    assert (now[0].clap_ns, now[0].method) == (before[0].clap_ns, before[0].method)
    assert now[0].sigma_ns == pytest.approx(before[0].sigma_ns, rel=0.01)
    assert abs(now[0].clap_ns - seen_ns) < 1_500_000


@pytest.mark.parametrize("encoding", ["mono8", "mono16", "png"])
def test_frames_not_jpeg_are_read_as_before(session_root: Path, encoding: str) -> None:
    """Raw and PNG frames are decoded in full and made gray exactly as before, and the
    clap is still found."""
    out, truth = make_session(session_root, seed=0, encoding=encoding)
    with open_recording(out / truth["recording"]) as src:
        info = src.streams[0]
        depth = stream_depth(src, info.name)
        for i in (0, info.count // 2):
            small, scale = small_gray(src, info, i, depth)
            want, want_scale = to_gray_small(src.frame(info.name, i), depth=depth)
            assert scale == want_scale and np.array_equal(small, want)
            assert np.array_equal(full_gray(src, info, i, depth),
                                  gray_full(src.frame(info.name, i), depth))
        assert len(_search(src)) >= 2
