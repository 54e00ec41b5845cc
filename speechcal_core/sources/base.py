"""The ``FrameSource`` interface shared by every recording kind."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from types import TracebackType

    import numpy as np
    from typing_extensions import Self

IMAGE_MSGTYPE = "sensor_msgs/msg/Image"
COMPRESSED_MSGTYPE = "sensor_msgs/msg/CompressedImage"


def stream_order(name: str) -> tuple:
    """Sort key of stream names with their numbers in numeric order: ``/cam2/image_raw``
    before ``/cam10/image_raw``, as an operator counts cameras."""
    parts = re.split(r"(\d+)", name)
    return (tuple(int(p) if k % 2 else p.lower() for k, p in enumerate(parts)), name)


@dataclass(frozen=True)
class StreamInfo:
    """One camera stream: what it holds and how regular its header stamps are."""

    name: str  # topic, or folder / file name for image folders and videos
    msgtype: str  # sensor_msgs/msg/Image, sensor_msgs/msg/CompressedImage, "video", "file"
    encoding: str  # Image encoding (mono8, bayer_rggb8...), "jpeg"/"png", or the video codec
    width: int
    height: int
    count: int
    first_ns: int
    last_ns: int
    median_period_ns: int
    nominal_rate_hz: float
    dropped: int  # frames missing, estimated from gaps longer than 1.5 median periods
    bad_frames: tuple[int, ...] = ()  # indices (in stamp order) known to be undecodable
    stamp_problems: str = ""  # e.g. "3 stamps out of order (sorted); 1 duplicate stamp"


@dataclass(frozen=True)
class RawFrame:
    """An undecoded message with what is needed to write it again unchanged.

    ``serialization`` is ``"ros1"`` or ``"cdr"`` for bag messages (``rawdata`` is the
    serialized message), ``"file"`` for image-folder frames (``rawdata`` is the file's bytes,
    ``suffix`` its extension) and ``"bgr8"``/``"mono8"``/``"mono16"`` for decoded video
    frames (``rawdata`` is the pixel buffer, row-major, no padding).
    """

    stream: str
    msgtype: str
    rawdata: bytes
    serialization: str
    stamp_ns: int
    log_time_ns: int
    width: int = 0
    height: int = 0
    suffix: str = ""
    #: connection details: ROS1 ``msgdef``, ``md5sum``, ``callerid``, ``latching``;
    #: ROS2 ``msgdef``, ``offered_qos_profiles``; ``source_msgtype`` as stored in the file
    connection: dict[str, str] = field(default_factory=dict)


@runtime_checkable
class FrameSource(Protocol):
    """Camera streams of one recording, keyed by header stamp; reads are thread-safe."""

    @property
    def streams(self) -> list[StreamInfo]:
        """The recording's image streams (read-only: every source computes or keeps its own)."""
        ...

    def stamps(self, stream: str) -> np.ndarray:
        """Header stamps (int64 ns), sorted ascending; index i is frame i."""
        ...

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded frame: mono (H, W) uint8/uint16 or colour (H, W, 3) BGR uint8.

        Raises ``BadFrameError`` (a ``SourceError``) for a corrupt or wrong-size payload.
        """
        ...

    def nearest(self, stream: str, t_ns: int) -> int:
        """Index of the frame whose header stamp is nearest to ``t_ns``."""
        ...

    def raw(self, stream: str, i: int) -> RawFrame:
        """The undecoded payload of frame i, for lossless export."""
        ...

    def close(self) -> None:
        """Release files."""
        ...

    def __enter__(self) -> FrameSource: ...

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None: ...


def header_span_ns(source: FrameSource) -> tuple[int, int] | None:
    """First and last header stamp over ``source``'s streams (None: it has no frames)."""
    streams = [s for s in source.streams if s.count]
    if not streams:
        return None
    return min(s.first_ns for s in streams), max(s.last_ns for s in streams)


class ClosingContext:
    """``with source:`` support shared by every frame source: leaving the block closes it."""

    def close(self) -> None:
        """Release files (nothing by default)."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
