"""Synthetic recordings read back with plain rosbags and agree with their truth."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from speechcal_core.synth import recording_writer
from speechcal_core.synth.camera_stamps import KEEP_NEAR_CLAP_NS, TRANSPORT_DELAY_NS, plan_frames
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.recording_writer import RecordingTruth, write_recording
from speechcal_core.synth.render import render_frame
from speechcal_core.synth.timeline import Timeline, plan_session

NS = 1_000_000_000


def _tiny(**kw) -> Timeline:
    base = dict(cameras=2, duration=5.0, seed=8, width=160, height=120)
    return plan_session(SynthOptions(**{**base, **kw}))


def _read_back(path: Path) -> dict[str, list[tuple[int, int, object]]]:
    """topic -> [(log time, header stamp, message)] in the reader's order."""
    out: dict[str, list[tuple[int, int, object]]] = {}
    with AnyReader([path]) as reader:
        for conn, log, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            stamp = msg.header.stamp.sec * NS + msg.header.stamp.nanosec
            out.setdefault(conn.topic, []).append((log, stamp, msg))
    return out


def _check_against_truth(tl: Timeline, truth: RecordingTruth) -> dict:
    back = _read_back(truth.path)
    assert set(back) == {c.name for c in tl.cameras}
    for cam in tl.cameras:
        msgs = back[cam.name]
        stamps = np.array([s for _, s, _ in msgs], np.int64)
        logs = np.array([t for t, _, _ in msgs], np.int64)
        assert np.array_equal(stamps, truth.stamps[cam.name])
        assert np.all(np.diff(stamps) > 0)
        delay = logs - stamps
        assert delay.min() >= TRANSPORT_DELAY_NS[0] and delay.max() < TRANSPORT_DELAY_NS[1]
        expected = round((tl.end_ns - tl.start_ns) / NS * cam.fps)
        assert abs(len(stamps) + truth.dropped[cam.name] - expected) <= 1
        # header stamp = true mid-exposure + clock offset + jitter
        err = stamps - truth.true_ns[cam.name] - cam.clock_offset_ns
        assert np.abs(err).max() < 6 * cam.jitter_ns
        assert msgs[0][2].header.frame_id == cam.name.split("/")[1]
    return back


@pytest.mark.parametrize("fmt", ["ros1", "ros2-sqlite3", "ros2-mcap"])
def test_each_format_reads_back_and_agrees_with_truth(tmp_path: Path, fmt: str) -> None:
    tl = _tiny(format=fmt)
    truth = write_recording(tl, tmp_path)
    assert truth.path == tmp_path / ("recording.bag" if fmt == "ros1" else "recording")
    assert truth.format == fmt and truth.path.is_absolute()
    back = _check_against_truth(tl, truth)
    _log, stamp, msg = back[tl.cameras[0].name][10]
    assert msg.format == "bgr8; jpeg compressed bgr8"
    img = cv2.imdecode(np.asarray(msg.data), cv2.IMREAD_COLOR)
    k = int(np.searchsorted(truth.stamps[tl.cameras[0].name], stamp))
    ref = render_frame(tl, 0, int(truth.true_ns[tl.cameras[0].name][k]))
    assert np.abs(img.astype(int) - ref).mean() < 3.0


@pytest.mark.parametrize("compression", ["bz2", "lz4"])
def test_ros1_chunk_compression_reads_back(tmp_path: Path, compression: str) -> None:
    tl = _tiny(format="ros1", ros1_compression=compression, duration=5.0)
    truth = write_recording(tl, tmp_path)
    assert compression.encode() in truth.path.read_bytes()[:1 << 20]  # chunk header field
    _check_against_truth(tl, truth)


def _decode_raw(msg) -> np.ndarray:
    """Rows honouring ``step``, as a consumer must."""
    data = np.asarray(msg.data, np.uint8)
    rows = data.reshape(msg.height, msg.step)
    if msg.encoding in ("bgr8", "rgb8"):
        return rows[:, : msg.width * 3].reshape(msg.height, msg.width, 3)
    if msg.encoding == "mono16":
        assert msg.is_bigendian == 0
        return rows[:, : msg.width * 2].copy().view("<u2").reshape(msg.height, msg.width)
    return rows[:, : msg.width]


@pytest.mark.parametrize("encoding", ["mono8", "bgr8", "rgb8", "mono16", "bayer_rggb8", "png"])
def test_each_encoding_carries_the_rendered_pixels(tmp_path: Path, encoding: str) -> None:
    fmt = "ros2-mcap" if encoding in ("rgb8", "png") else "ros1"
    tl = _tiny(format=fmt, encoding=encoding)
    truth = write_recording(tl, tmp_path)
    back = _check_against_truth(tl, truth)
    name = tl.cameras[1].name
    _, stamp, msg = back[name][7]
    k = int(np.searchsorted(truth.stamps[name], stamp))
    bgr = render_frame(tl, 1, int(truth.true_ns[name][k]))
    grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    if encoding == "png":
        assert msg.format == "bgr8; png compressed bgr8"
        assert np.array_equal(cv2.imdecode(np.asarray(msg.data), cv2.IMREAD_COLOR), bgr)
        return
    assert msg.encoding == encoding and msg.is_bigendian == 0
    assert (msg.width, msg.height) == (tl.cameras[1].width, tl.cameras[1].height)
    pixels = _decode_raw(msg)
    expected = {
        "mono8": grey,
        "bgr8": bgr,
        "rgb8": bgr[..., ::-1],
        "mono16": grey.astype(np.uint16) * 257,
        "bayer_rggb8": None,
    }[encoding]
    if encoding == "bayer_rggb8":
        assert msg.step == msg.width
        assert np.array_equal(pixels[0::2, 0::2], bgr[0::2, 0::2, 2])  # R
        assert np.array_equal(pixels[0::2, 1::2], bgr[0::2, 1::2, 1])  # G
        assert np.array_equal(pixels[1::2, 1::2], bgr[1::2, 1::2, 0])  # B
    else:
        assert np.array_equal(pixels, expected)


def test_worker_processes_write_the_same_bytes_as_one_process(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    tl = _tiny(format="ros2-mcap", duration=6.0)
    # OpenCV's thread pool busy in this process before the workers start (a forked worker
    # used to deadlock on it)
    cv2.GaussianBlur(np.zeros((1080, 1920, 3), np.uint8), (0, 0), 3.0)
    monkeypatch.setattr(recording_writer, "MIN_FRAMES_FOR_POOL", 0)
    monkeypatch.setattr(recording_writer, "CHUNK_FRAMES", 40)
    fractions: list[float] = []
    pooled = write_recording(tl, tmp_path / "pooled", progress=fractions.append, workers=2)
    single = write_recording(tl, tmp_path / "single", workers=1)
    assert fractions[-1] == pytest.approx(1.0) and fractions == sorted(fractions)
    with AnyReader([pooled.path]) as a, AnyReader([single.path]) as b:
        pairs = zip(a.messages(), b.messages(), strict=True)
        assert all(x[1:] == y[1:] and x[0].topic == y[0].topic for x, y in pairs)


def test_existing_recording_is_not_overwritten(tmp_path: Path) -> None:
    tl = _tiny()
    (tmp_path / "recording.bag").write_bytes(b"keep")
    with pytest.raises(recording_writer.RecordingWriteError, match="exists"):
        write_recording(tl, tmp_path)
    assert (tmp_path / "recording.bag").read_bytes() == b"keep"


def test_frames_drop_but_never_near_a_clap() -> None:
    tl = _tiny(duration=20.0, claps=2)
    lossy = replace(tl, cameras=tuple(replace(c, drop_rate=0.4) for c in tl.cameras))
    for cam, frames in zip(lossy.cameras, plan_frames(lossy), strict=True):
        assert frames.dropped > 0.25 * (len(frames.true_ns) + frames.dropped)
        period = NS / cam.fps
        for clap in lossy.claps_ns:
            near = frames.true_ns[np.abs(frames.true_ns - clap) <= KEEP_NEAR_CLAP_NS]
            assert np.all(np.diff(near) < 1.5 * period)
            assert len(near) >= 2 * KEEP_NEAR_CLAP_NS / period - 1
        jitter = frames.header_ns - frames.true_ns - cam.clock_offset_ns
        assert abs(np.std(jitter) / cam.jitter_ns - 1) < 0.3
        assert frames.true_ns[0] >= lossy.start_ns and frames.true_ns[-1] <= lossy.end_ns
    assert [f.header_ns.tolist() for f in plan_frames(lossy)] == \
        [f.header_ns.tolist() for f in plan_frames(lossy)]
