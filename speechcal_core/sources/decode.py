"""Turn image payloads (raw encodings, JPEG/PNG) into numpy images: mono or BGR uint8."""

from __future__ import annotations

import cv2
import numpy as np

from speechcal_core.sources.base import COMPRESSED_MSGTYPE, RawFrame
from speechcal_core.sources.errors import BadFrameError, SourceError
from speechcal_core.sources.msgparse import parse_image

# encoding -> (channels, bytes per channel)
_LAYOUT: dict[str, tuple[int, int]] = {
    "mono8": (1, 1), "8UC1": (1, 1), "mono16": (1, 2), "16UC1": (1, 2),
    "bgr8": (3, 1), "rgb8": (3, 1), "8UC3": (3, 1),
    "bgra8": (4, 1), "rgba8": (4, 1), "8UC4": (4, 1),
    "bgr16": (3, 2), "rgb16": (3, 2), "16UC3": (3, 2),
    "bgra16": (4, 2), "rgba16": (4, 2), "16UC4": (4, 2),
    "bayer_rggb8": (1, 1), "bayer_bggr8": (1, 1), "bayer_gbrg8": (1, 1), "bayer_grbg8": (1, 1),
    "bayer_rggb16": (1, 2), "bayer_bggr16": (1, 2), "bayer_gbrg16": (1, 2),
    "bayer_grbg16": (1, 2),
    "yuv422": (2, 1), "uyvy": (2, 1), "yuyv": (2, 1), "yuv422_yuy2": (2, 1),
}  # fmt: skip

# ROS names the pattern of the top-left 2x2; OpenCV names it from the second row/column.
_BAYER = {
    "rggb": cv2.COLOR_BayerRGGB2BGR,
    "bggr": cv2.COLOR_BayerBGGR2BGR,
    "gbrg": cv2.COLOR_BayerGBRG2BGR,
    "grbg": cv2.COLOR_BayerGRBG2BGR,
}

SUPPORTED_ENCODINGS = frozenset(_LAYOUT)


def is_supported(encoding: str) -> bool:
    """Whether ``decode_raw`` knows this sensor_msgs/Image encoding."""
    return encoding in _LAYOUT


def bytes_per_pixel(encoding: str) -> int:
    """Bytes of one pixel in a packed row."""
    channels, size = _LAYOUT[encoding]
    return channels * size


#: sensor bit depths 16-bit images commonly hold (right-aligned)
SENSOR_DEPTHS = (8, 10, 12, 14, 16)


def sensor_depth(largest: int) -> int:
    """The smallest of SENSOR_DEPTHS that holds the value ``largest``."""
    used = max(0, int(largest)).bit_length()
    return next((d for d in SENSOR_DEPTHS if d >= used), SENSOR_DEPTHS[-1])


def to_uint8(img: np.ndarray, depth: int | None = None) -> np.ndarray:
    """An 8-bit view of a frame: 16-bit data is shifted down by the sensor depth it holds,
    so a 12-bit sensor's 0-4095 fills 0-255 as 16-bit data's 0-65535 does. ``depth``: the
    stream's (``sources.depth.stream_depth``, one scale for all its frames); without it,
    what this frame's largest value needs. Other images are returned as they are."""
    if img.dtype != np.uint16:
        return img
    if depth is None:
        depth = sensor_depth(int(img.max()) if img.size else 0)
    return (img >> (max(8, depth) - 8)).astype(np.uint8)



def decode_raw(
    data: bytes | memoryview,
    encoding: str,
    width: int,
    height: int,
    step: int,
    is_bigendian: bool = False,
) -> np.ndarray:
    """Decode a sensor_msgs/Image payload, honouring ``step`` padding and byte order.

    Returns mono (H, W) uint8/uint16 or colour (H, W, 3) BGR uint8. Raises ``SourceError``
    for an unknown encoding and ``BadFrameError`` when the payload size does not match.
    """
    if encoding not in _LAYOUT:
        known = ", ".join(sorted(_LAYOUT))
        raise SourceError(f"unknown image encoding {encoding!r} (supported: {known})")
    channels, size = _LAYOUT[encoding]
    row = width * channels * size
    if width <= 0 or height <= 0:
        raise BadFrameError(f"empty image {width}x{height}")
    if step < row:
        raise BadFrameError(f"step {step} is shorter than a {encoding} row of {row} bytes")
    if len(data) < step * (height - 1) + row:
        raise BadFrameError(
            f"payload has {len(data)} bytes, a {width}x{height} {encoding} image with step "
            f"{step} needs {step * height}"
        )
    buf = np.frombuffer(data, dtype=np.uint8, count=min(len(data), step * height))
    if buf.size < step * height:  # last row without its padding
        buf = np.concatenate([buf, np.zeros(step * height - buf.size, np.uint8)])
    rows = buf.reshape(height, step)[:, :row]
    if size == 2:
        dtype = np.dtype(">u2" if is_bigendian else "<u2")
        img = np.ascontiguousarray(rows).view(dtype).astype(np.uint16, copy=False)
    else:
        img = rows
    img = img.reshape(height, width, channels) if channels > 1 else img.reshape(height, width)
    return _convert(img, encoding)


def _convert(img: np.ndarray, encoding: str) -> np.ndarray:
    if encoding.startswith("bayer_"):
        pattern = encoding[6:10]
        return to_uint8(cv2.cvtColor(np.ascontiguousarray(img), _BAYER[pattern]))
    if encoding in ("yuv422", "uyvy"):
        return cv2.cvtColor(np.ascontiguousarray(img), cv2.COLOR_YUV2BGR_UYVY)
    if encoding in ("yuyv", "yuv422_yuy2"):
        return cv2.cvtColor(np.ascontiguousarray(img), cv2.COLOR_YUV2BGR_YUYV)
    if img.ndim == 2:
        return np.ascontiguousarray(img)
    if encoding.startswith("rgb"):
        img = img[..., 2::-1]
    elif img.shape[2] == 4:
        img = img[..., :3]
    return np.ascontiguousarray(to_uint8(img))


def _looks_complete(data: bytes | memoryview) -> str:
    head = bytes(data[:8])
    if head.startswith(b"\xff\xd8"):
        tail = bytes(data[-16:]).rstrip(b"\0")
        return "" if tail.endswith(b"\xff\xd9") else "JPEG is truncated (no end marker)"
    if head.startswith(b"\x89PNG\r\n\x1a\n"):
        return "" if b"IEND" in bytes(data[-16:]) else "PNG is truncated (no IEND chunk)"
    return ""


def decode_compressed(data: bytes | memoryview) -> np.ndarray:
    """Decode a JPEG/PNG payload to mono (H, W) uint8/uint16 or (H, W, 3) BGR uint8."""
    if len(data) == 0:
        raise BadFrameError("empty compressed payload")
    problem = _looks_complete(data)
    if problem:
        raise BadFrameError(problem)
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    if img is None:
        raise BadFrameError("JPEG/PNG payload cannot be decoded (corrupt data)")
    if img.ndim == 3:
        if img.shape[2] == 4:
            img = cv2.cvtColor(img, cv2.COLOR_BGRA2BGR)
        elif img.shape[2] == 1:
            img = img[..., 0]
        if img.ndim == 3:
            img = to_uint8(img)
    return img


#: the reductions libjpeg can apply while decoding, as OpenCV's gray reading flags
REDUCED_GRAY = {1: cv2.IMREAD_GRAYSCALE, 2: cv2.IMREAD_REDUCED_GRAYSCALE_2,
                4: cv2.IMREAD_REDUCED_GRAYSCALE_4, 8: cv2.IMREAD_REDUCED_GRAYSCALE_8}


def decode_jpeg_gray(data: bytes | memoryview, factor: int = 1) -> np.ndarray | None:
    """A JPEG payload decoded straight to 8-bit gray (its luma) at ``1/factor`` of its size
    (1, 2, 4 or 8; each side rounded up): libjpeg leaves out the colour and scales while
    decoding (a 1280x720 frame at 1/8 in about half the time of :func:`decode_compressed`,
    and no gray conversion or resize after). None when the payload is not a complete JPEG
    (:func:`decode_compressed` says why)."""
    if len(data) == 0 or bytes(data[:2]) != b"\xff\xd8" or _looks_complete(data):
        return None
    return cv2.imdecode(np.frombuffer(data, np.uint8), REDUCED_GRAY[factor])


def compressed_payload(raw: RawFrame | object) -> memoryview | bytes | None:
    """The JPEG/PNG bytes inside a raw frame (:meth:`FrameSource.raw`), or None when it is
    not compressed. Raises ``BadFrameError`` for a malformed message."""
    msgtype = getattr(raw, "msgtype", "")
    serialization = getattr(raw, "serialization", "")
    data = getattr(raw, "rawdata", b"")
    if serialization == "file" and getattr(raw, "suffix", "").lower() in (".jpg", ".jpeg",
                                                                         ".png"):
        return data
    if msgtype == COMPRESSED_MSGTYPE and serialization in ("ros1", "cdr"):
        return parse_image(data, serialization == "cdr", True).data
    return None


def compressed_kind(fmt: str, data: bytes | memoryview) -> str:
    """``"jpeg"`` or ``"png"`` (from the magic bytes, else from the format string)."""
    head = bytes(data[:4])
    if head.startswith(b"\xff\xd8"):
        return "jpeg"
    if head.startswith(b"\x89PNG"):
        return "png"
    low = fmt.lower()
    return "png" if "png" in low else "jpeg" if ("jpeg" in low or "jpg" in low) else low


def raw_size_problem(data_len: int, encoding: str, width: int, height: int, step: int) -> str:
    """Why a raw payload of ``data_len`` bytes cannot hold the image, or "" when it can."""
    if encoding not in _LAYOUT:
        return ""
    row = width * bytes_per_pixel(encoding)
    if step < row:
        return f"step {step} is shorter than a {encoding} row of {row} bytes"
    if height > 0 and data_len < step * (height - 1) + row:
        return f"payload has {data_len} bytes, {width}x{height} {encoding} needs {step * height}"
    return ""
