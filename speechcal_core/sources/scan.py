"""What indexing one recording file yields, and the protocol every bag-like file follows."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from pathlib import Path

IMAGE_TYPES = {
    "sensor_msgs/Image": "sensor_msgs/msg/Image",
    "sensor_msgs/msg/Image": "sensor_msgs/msg/Image",
    "sensor_msgs/CompressedImage": "sensor_msgs/msg/CompressedImage",
    "sensor_msgs/msg/CompressedImage": "sensor_msgs/msg/CompressedImage",
}


def image_msgtype(msgtype: str) -> str | None:
    """The ROS2-style name of an image message type, or None for other types."""
    return IMAGE_TYPES.get(msgtype)


@dataclass
class TopicScan:
    """One image topic of one file: per-message stamps and where each message lives."""

    topic: str
    msgtype: str  # sensor_msgs/msg/Image or sensor_msgs/msg/CompressedImage
    serialization: str  # "ros1" or "cdr"
    connection: dict[str, str]
    encoding: str = ""
    width: int = 0
    height: int = 0
    stamps: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    log_times: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    offsets: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    chunks: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))  # -1: direct
    sizes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))


@dataclass
class FileScan:
    """Index of one file: image topics, the compressed chunks they point into, and notes."""

    topics: list[TopicScan]
    #: (data_start, data_len, uncompressed_size) of each compressed chunk
    chunk_rows: list[tuple[int, int, int]] = field(default_factory=list)
    chunk_compression: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    other_topics: list[str] = field(default_factory=list)  # "topic [type]" of non-image topics
    empty_topics: list[str] = field(default_factory=list)  # image topics without a message

    @property
    def chunk_table(self) -> np.ndarray:
        """``chunk_rows`` as an (n, 3) int64 array."""
        return np.array(self.chunk_rows, np.int64).reshape(-1, 3)


class TopicCollector:
    """Accumulates per-message entries of one topic while walking a file."""

    def __init__(self, scan: TopicScan) -> None:
        self.scan = scan
        self.rows: list[tuple[int, int, int, int, int]] = []

    def add(self, stamp: int, log_time: int, offset: int, chunk: int, size: int) -> None:
        """Record one message."""
        self.rows.append((stamp, log_time, offset, chunk, size))

    def finish(self) -> TopicScan:
        """Fill the scan's arrays."""
        arr = np.array(self.rows, dtype=np.int64).reshape(-1, 5)
        s = self.scan
        s.stamps, s.log_times, s.offsets, s.chunks, s.sizes = (
            np.ascontiguousarray(arr[:, k]) for k in range(5)
        )
        return s


class MessageFile(Protocol):
    """One bag-like file: index it once, then read any message by its location."""

    path: Path

    def scan(self) -> FileScan:
        """Walk the file and index its image topics (may raise ``SourceError``)."""
        ...

    def attach(self, scan: FileScan) -> None:
        """Use an index (fresh or from the cache) for later reads."""
        ...

    def read(self, offset: int, chunk: int, size: int) -> bytes:
        """The serialized message at a location from the index; thread-safe."""
        ...

    def head(self, offset: int, chunk: int, n: int) -> bytes:
        """The first n bytes of a message (reading no more than needed); thread-safe."""
        ...

    def close(self) -> None:
        """Release the file."""
        ...
