"""Write the synthetic multi-camera recording (ROS1 bag or ROS2 sqlite3/mcap bag) of a timeline.

Frames are rendered in chunks of receive time, by worker processes when there are several
cores, and streamed to the rosbags writer in receive-time order across cameras, so memory
stays bounded by a few chunks whatever the session length.
"""

from __future__ import annotations

import multiprocessing
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.errors import SpeechCalError
from speechcal_core.processes import exit_with_parent, spawn_can_start, usable_cores
from speechcal_core.synth.camera_stamps import CameraFrames, plan_frames
from speechcal_core.synth.image_messages import message_type, serialize_frame, typestore_for
from speechcal_core.synth.render import FrameRenderer
from speechcal_core.synth.timeline import Timeline

if TYPE_CHECKING:
    from rosbags.rosbag1 import Writer as Writer1
    from rosbags.rosbag2 import Writer as Writer2

CHUNK_BYTES = 48 << 20  # rendered payload per chunk (bounds memory per chunk in flight)
CHUNK_FRAMES = 120  # at most this many frames per chunk
MIN_FRAMES_FOR_POOL = 1500  # below this, worker start-up costs more than it saves


class RecordingWriteError(SpeechCalError):
    """The recording could not be written (existing output, failing writer)."""


@dataclass
class RecordingTruth:
    """What was written: bag path, format and, per camera topic, the header stamps."""

    path: Path
    format: str
    stamps: dict[str, np.ndarray]  # topic -> int64 header stamps written, sorted
    dropped: dict[str, int]  # topic -> frames dropped
    encoding: str = ""
    true_ns: dict[str, np.ndarray] = field(default_factory=dict)  # topic -> true mid-exposure


@dataclass(frozen=True)
class _Task:
    """Frames to render: parallel arrays in receive-time order."""

    camera: np.ndarray
    true_ns: np.ndarray
    header_ns: np.ndarray
    seq: np.ndarray


def recording_path(timeline: Timeline, out_dir: Path) -> Path:
    """Where :func:`write_recording` puts the bag for the timeline's format."""
    fmt = timeline.options.format
    return out_dir / ("recording.bag" if fmt == "ros1" else "recording")


def frame_id(topic: str) -> str:
    """Camera frame name of a topic: ``/cam0/image_raw`` -> ``cam0``."""
    parts = [p for p in topic.split("/") if p]
    return parts[0] if parts else "camera"


def write_recording(timeline: Timeline, out_dir: Path,
                    progress: Callable[[float], None] | None = None,
                    workers: int | None = None) -> RecordingTruth:
    """Render every camera's frames and write the bag into ``out_dir``.

    ros1 -> ``out_dir/recording.bag``; ros2-sqlite3 / ros2-mcap -> ``out_dir/recording/``.
    ``progress`` gets the finished fraction (0-1). ``workers`` defaults to the usable cores.
    """
    options = timeline.options
    out_dir = Path(out_dir).absolute()
    out_dir.mkdir(parents=True, exist_ok=True)
    path = recording_path(timeline, out_dir)
    if path.exists():
        raise RecordingWriteError(f"{path} exists already; remove it or write elsewhere")
    frames = plan_frames(timeline)
    order = _receive_order(frames)
    tasks = list(_chunks(timeline, frames, order))
    ros_version = 1 if options.format == "ros1" else 2
    if workers is None:
        workers = usable_cores()
    workers = max(1, min(workers, len(tasks)))
    total = len(order[0])
    msgtype = message_type(options.encoding)
    typestore = typestore_for(ros_version)
    with _open_writer(options.format, options.ros1_compression, path) as writer:
        conns = [writer.add_connection(cam.name, msgtype, typestore=typestore)
                 for cam in timeline.cameras]
        done = 0
        for task, payloads in _rendered(timeline, tasks, ros_version, workers, total):
            for cam, raw in zip(task.camera, payloads, strict=True):
                writer.write(conns[int(cam)], int(order[2][done]), raw)
                done += 1
            if progress is not None:
                progress(done / max(1, total))
    names = [cam.name for cam in timeline.cameras]
    return RecordingTruth(
        path=path,
        format=options.format,
        stamps={n: f.header_ns.copy() for n, f in zip(names, frames, strict=True)},
        dropped={n: f.dropped for n, f in zip(names, frames, strict=True)},
        encoding=options.encoding,
        true_ns={n: f.true_ns.copy() for n, f in zip(names, frames, strict=True)},
    )


def _receive_order(frames: list[CameraFrames]) -> tuple[np.ndarray, ...]:
    """All frames as (camera, index in camera, log_ns) sorted by receive time, then camera."""
    cams = np.concatenate([np.full(f.log_ns.size, f.camera_index) for f in frames])
    idx = np.concatenate([np.arange(f.log_ns.size) for f in frames])
    logs = np.concatenate([f.log_ns for f in frames])
    order = np.lexsort((cams, logs))
    return cams[order], idx[order], logs[order]


def _chunks(timeline: Timeline, frames: list[CameraFrames],
            order: tuple[np.ndarray, ...]) -> Iterator[_Task]:
    cams, idx, _ = order
    frame_bytes = max(c.width * c.height * 3 for c in timeline.cameras)
    size = int(max(4, min(CHUNK_FRAMES, CHUNK_BYTES // frame_bytes)))
    true_all = [f.true_ns for f in frames]
    header_all = [f.header_ns for f in frames]
    for start in range(0, cams.size, size):
        c, i = cams[start : start + size], idx[start : start + size]
        yield _Task(
            camera=c,
            true_ns=np.array([true_all[a][b] for a, b in zip(c, i, strict=True)], np.int64),
            header_ns=np.array([header_all[a][b] for a, b in zip(c, i, strict=True)], np.int64),
            seq=i.astype(np.int64),
        )


def _rendered(timeline: Timeline, tasks: list[_Task], ros_version: int, workers: int,
              total: int) -> Iterator[tuple[_Task, list[bytes]]]:
    """(task, serialized messages) in task order, rendered here or by worker processes."""
    if workers <= 1 or total < MIN_FRAMES_FOR_POOL or not spawn_can_start():
        renderer = FrameRenderer(timeline)
        for task in tasks:
            yield task, _render_task(renderer, timeline, task, ros_version)
        return
    # spawn, not fork: a forked child inherits OpenCV's thread pool mid-use and can
    # deadlock in its first cv2 call (seen under pytest after earlier cv2 work)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                             initializer=_init_worker, initargs=(timeline,)) as pool:
        pending: deque[tuple[_Task, Future]] = deque()
        it = iter(tasks)
        for task in it:
            pending.append((task, pool.submit(_worker_task, task, ros_version)))
            if len(pending) >= 2 * workers:
                break
        while pending:
            task, fut = pending.popleft()
            payloads = fut.result()
            nxt = next(it, None)
            if nxt is not None:
                pending.append((nxt, pool.submit(_worker_task, nxt, ros_version)))
            yield task, payloads


def _render_task(renderer: FrameRenderer, timeline: Timeline, task: _Task,
                 ros_version: int) -> list[bytes]:
    encoding = timeline.options.encoding
    out = []
    for cam, t, hdr, seq in zip(task.camera, task.true_ns, task.header_ns, task.seq,
                                strict=True):
        topic = timeline.cameras[int(cam)].name
        bgr = renderer.render(int(cam), int(t))
        out.append(serialize_frame(bgr, encoding, int(hdr), frame_id(topic), int(seq),
                                   ros_version))
    return out


_WORKER: dict[str, object] = {}


def _init_worker(timeline: Timeline) -> None:
    import cv2

    exit_with_parent()
    cv2.setNumThreads(1)
    _WORKER["timeline"] = timeline
    _WORKER["renderer"] = FrameRenderer(timeline)


def _worker_task(task: _Task, ros_version: int) -> list[bytes]:
    renderer = _WORKER["renderer"]
    assert isinstance(renderer, FrameRenderer)
    return _render_task(renderer, renderer.timeline, task, ros_version)


def _open_writer(fmt: str, compression: str, path: Path) -> Writer1 | Writer2:
    """A rosbags writer (context manager) for ``fmt``."""
    if fmt == "ros1":
        from rosbags.rosbag1 import Writer as Writer1

        writer1 = Writer1(path)
        if compression == "bz2":
            writer1.set_compression(Writer1.CompressionFormat.BZ2)
        elif compression == "lz4":
            writer1.set_compression(Writer1.CompressionFormat.LZ4)
        return writer1
    from rosbags.rosbag2 import StoragePlugin
    from rosbags.rosbag2 import Writer as Writer2

    plugin = StoragePlugin.MCAP if fmt == "ros2-mcap" else StoragePlugin.SQLITE3
    return Writer2(path, version=9, storage_plugin=plugin)
