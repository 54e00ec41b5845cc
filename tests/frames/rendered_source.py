"""A FrameSource over frames the synthetic renderer draws on demand (no files), for tests."""

from __future__ import annotations

import threading

import numpy as np

from speechcal_core.sources.base import RawFrame, StreamInfo
from speechcal_core.synth.camera_stamps import plan_frames
from speechcal_core.synth.render import renderer_for
from speechcal_core.synth.timeline import Timeline


class RenderedSource:
    """Every camera of a synthetic timeline, frames rendered when first read and kept."""

    def __init__(self, timeline: Timeline) -> None:
        self.timeline = timeline
        self._renderer = renderer_for(timeline)
        self._frames = {timeline.cameras[f.camera_index].name: f for f in plan_frames(timeline)}
        self._cache: dict[tuple[str, int], np.ndarray] = {}
        self._lock = threading.Lock()
        self.decoded = 0
        self.streams = []
        for i, cam in enumerate(timeline.cameras):
            st = self._frames[cam.name].header_ns
            self.streams.append(StreamInfo(
                cam.name, "sensor_msgs/msg/Image", "bgr8", cam.width, cam.height, st.size,
                int(st[0]), int(st[-1]), int(np.median(np.diff(st))), cam.fps, 0))
            self._index = i

    def stamps(self, stream: str) -> np.ndarray:
        return self._frames[stream].header_ns

    def true_ns(self, stream: str) -> np.ndarray:
        """Reference-clock mid-exposure time of each frame."""
        return self._frames[stream].true_ns

    def frame(self, stream: str, i: int) -> np.ndarray:
        key = (stream, i)
        with self._lock:
            if key in self._cache:
                return self._cache[key]
        cam = next(k for k, c in enumerate(self.timeline.cameras) if c.name == stream)
        img = self._renderer.render(cam, int(self._frames[stream].true_ns[i]))
        with self._lock:
            self._cache[key] = img
            self.decoded += 1
        return img

    def nearest(self, stream: str, t_ns: int) -> int:
        st = self.stamps(stream)
        return int(np.argmin(np.abs(st - t_ns)))

    def raw(self, stream: str, i: int) -> RawFrame:
        raise NotImplementedError("rendered frames have no serialized form")

    def close(self) -> None:
        self._cache.clear()

    def __enter__(self) -> RenderedSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class ArraySource:
    """A FrameSource over frames held in memory: ``{stream: (stamps, frames)}``."""

    def __init__(self, data: dict[str, tuple[np.ndarray, list[np.ndarray]]]) -> None:
        self._data = data
        self.streams = []
        for name, (st, frames) in data.items():
            h, w = frames[0].shape[:2]
            period = int(np.median(np.diff(st))) if st.size > 1 else 0
            self.streams.append(StreamInfo(name, "sensor_msgs/msg/Image", "mono8", w, h,
                                           st.size, int(st[0]), int(st[-1]), period,
                                           1e9 / period if period else 0.0, 0))

    def stamps(self, stream: str) -> np.ndarray:
        return self._data[stream][0]

    def frame(self, stream: str, i: int) -> np.ndarray:
        return self._data[stream][1][i]

    def nearest(self, stream: str, t_ns: int) -> int:
        return int(np.argmin(np.abs(self.stamps(stream) - t_ns)))

    def raw(self, stream: str, i: int) -> RawFrame:
        raise NotImplementedError("in-memory frames have no serialized form")

    def close(self) -> None:
        pass

    def __enter__(self) -> ArraySource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
