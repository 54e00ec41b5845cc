"""Read header stamps and image fields straight from serialized ROS1 / CDR messages."""

from __future__ import annotations

import struct
from dataclasses import dataclass

from speechcal_core.sources.errors import BadFrameError

_U32 = {True: struct.Struct("<I"), False: struct.Struct(">I")}
_STAMP_ROS1 = struct.Struct("<II")
_STAMP_CDR = {True: struct.Struct("<iI"), False: struct.Struct(">iI")}

#: bytes of a serialized message that hold its header stamp (ROS1: seq + stamp; CDR: 4 + stamp)
STAMP_PREFIX = 12


@dataclass(frozen=True)
class ImageMsg:
    """Fields of a sensor_msgs/Image or CompressedImage; ``data`` is a view into the message."""

    stamp_ns: int
    frame_id: str
    height: int
    width: int
    encoding: str  # raw encoding, or CompressedImage.format
    is_bigendian: bool
    step: int
    data: memoryview
    compressed: bool
    data_len: int = -1  # declared payload length (also known with header_only)
    data_offset: int = -1  # where the payload starts in the message


def stamp_ros1(raw: bytes | memoryview) -> int:
    """Header stamp of a ROS1 message whose first field is a std_msgs/Header."""
    sec, nsec = _STAMP_ROS1.unpack_from(raw, 4)
    return sec * 1_000_000_000 + nsec


def stamp_cdr(raw: bytes | memoryview) -> int:
    """Header stamp of a CDR message whose first field is a std_msgs/Header."""
    sec, nsec = _STAMP_CDR[raw[1] == 1].unpack_from(raw, 4)
    return sec * 1_000_000_000 + nsec


def stamp_of(raw: bytes | memoryview, cdr: bool) -> int:
    """Header stamp in either serialization."""
    return stamp_cdr(raw) if cdr else stamp_ros1(raw)


class _Cursor:
    """Sequential reader over a serialized message (ROS1 or CDR alignment rules)."""

    def __init__(self, raw: memoryview, cdr: bool) -> None:
        self.raw = raw
        self.cdr = cdr
        self.little = (raw[1] == 1) if cdr else True
        self.pos = 4 if cdr else 0
        self.u32 = _U32[self.little]

    def align(self, n: int) -> None:
        if self.cdr:
            rel = self.pos - 4
            self.pos += (-rel) % n

    def uint32(self) -> int:
        self.align(4)
        (value,) = self.u32.unpack_from(self.raw, self.pos)
        self.pos += 4
        return value

    def uint8(self) -> int:
        value = self.raw[self.pos]
        self.pos += 1
        return value

    def string(self) -> str:
        n = self.uint32()
        end = self.pos + n
        if end > len(self.raw):
            raise ValueError("string runs past the end of the message")
        text = bytes(self.raw[self.pos : end])
        self.pos = end
        if self.cdr and text.endswith(b"\0"):
            text = text[:-1]
        return text.decode("utf-8", "replace")

    def blob(self) -> memoryview:
        n = self.uint32()
        end = self.pos + n
        if end > len(self.raw):
            raise ValueError(f"payload says {n} bytes but only {len(self.raw) - self.pos} follow")
        view = self.raw[self.pos : end]
        self.pos = end
        return view


def parse_image(
    raw: bytes | memoryview, cdr: bool, compressed: bool, *, header_only: bool = False
) -> ImageMsg:
    """Parse an Image or CompressedImage message; ``BadFrameError`` when it is malformed.

    With ``header_only`` a prefix of the message is enough and ``data`` is left empty.
    """
    view = memoryview(raw)
    try:
        stamp = stamp_of(view, cdr)
        cur = _Cursor(view, cdr)
        cur.pos += 8 if cdr else 12  # CDR: sec, nanosec; ROS1: seq, secs, nsecs
        frame_id = cur.string()
        if compressed:
            fmt = cur.string()
            data = cur.blob()
            return ImageMsg(stamp, frame_id, 0, 0, fmt, False, 0, data, True)
        height = cur.uint32()
        width = cur.uint32()
        encoding = cur.string()
        is_bigendian = bool(cur.uint8())
        step = cur.uint32()
        if header_only:
            data_len = cur.uint32()
            data, data_offset = memoryview(b""), cur.pos
        else:
            data = cur.blob()
            data_len, data_offset = len(data), cur.pos - len(data)
    except (struct.error, IndexError, ValueError) as exc:
        raise BadFrameError(f"malformed message ({exc})") from None
    return ImageMsg(
        stamp, frame_id, height, width, encoding, is_bigendian, step, data, False,
        data_len, data_offset,
    )  # fmt: skip
