"""Turn rendered BGR frames into serialized ``sensor_msgs`` image messages (ROS1 or ROS2).

Raw encodings become ``sensor_msgs/msg/Image`` (``mono8``, ``bgr8``, ``rgb8``, ``mono16``
little endian, ``bayer_rggb8``; ``step`` = bytes per row, no padding). ``jpeg`` and ``png``
become ``sensor_msgs/msg/CompressedImage`` with the image_transport format string
``"bgr8; jpeg compressed bgr8"`` / ``"bgr8; png compressed bgr8"``.
"""

from __future__ import annotations

from functools import cache

import cv2
import numpy as np
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED_IMAGE = "sensor_msgs/msg/CompressedImage"
JPEG_QUALITY = 90
PNG_COMPRESSION = 1  # fast; PNG is lossless at any level
COMPRESSED_FORMATS = {
    "jpeg": "bgr8; jpeg compressed bgr8",
    "png": "bgr8; png compressed bgr8",
}


@cache
def typestore_for(ros_version: int) -> Typestore:
    """The rosbags typestore we write with: ROS1 Noetic or ROS2 Humble."""
    return get_typestore(Stores.ROS1_NOETIC if ros_version == 1 else Stores.ROS2_HUMBLE)


def message_type(encoding: str) -> str:
    """The message type that carries frames of ``encoding``."""
    return COMPRESSED_IMAGE if encoding in COMPRESSED_FORMATS else IMAGE


def encode_pixels(bgr: np.ndarray, encoding: str) -> tuple[np.ndarray, int]:
    """Pixel payload (flat uint8) and row step in bytes of a BGR frame in ``encoding``.

    For compressed encodings the payload is the JPEG/PNG file and the step is 0.
    """
    if encoding == "bgr8":
        return bgr.reshape(-1), bgr.shape[1] * 3
    if encoding == "rgb8":
        return cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB).reshape(-1), bgr.shape[1] * 3
    if encoding == "mono8":
        return cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY).reshape(-1), bgr.shape[1]
    if encoding == "mono16":
        grey = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY).astype("<u2") * np.uint16(257)
        return grey.view(np.uint8).reshape(-1), bgr.shape[1] * 2
    if encoding == "bayer_rggb8":
        return bayer_rggb(bgr).reshape(-1), bgr.shape[1]
    if encoding == "jpeg":
        ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    elif encoding == "png":
        ok, buf = cv2.imencode(".png", bgr, [cv2.IMWRITE_PNG_COMPRESSION, PNG_COMPRESSION])
    else:
        raise ValueError(f"unknown image encoding {encoding!r}")
    if not ok:
        raise RuntimeError(f"OpenCV could not encode a frame as {encoding}")
    return buf.reshape(-1), 0


def bayer_rggb(bgr: np.ndarray) -> np.ndarray:
    """Mosaic a BGR frame into an RGGB Bayer pattern (R at even row, even column)."""
    out = np.empty(bgr.shape[:2], np.uint8)
    out[0::2, 0::2] = bgr[0::2, 0::2, 2]
    out[0::2, 1::2] = bgr[0::2, 1::2, 1]
    out[1::2, 0::2] = bgr[1::2, 0::2, 1]
    out[1::2, 1::2] = bgr[1::2, 1::2, 0]
    return out


def serialize_frame(bgr: np.ndarray, encoding: str, stamp_ns: int, frame_id: str,
                    seq: int, ros_version: int) -> bytes:
    """One serialized image message (ROS1 wire format or CDR) of ``bgr``."""
    ts = typestore_for(ros_version)
    types = ts.types
    stamp = types["builtin_interfaces/msg/Time"](sec=int(stamp_ns // 1_000_000_000),
                                                 nanosec=int(stamp_ns % 1_000_000_000))
    header_type = types["std_msgs/msg/Header"]
    if ros_version == 1:
        header = header_type(seq=seq, stamp=stamp, frame_id=frame_id)
    else:
        header = header_type(stamp=stamp, frame_id=frame_id)
    data, step = encode_pixels(bgr, encoding)
    if encoding in COMPRESSED_FORMATS:
        msg = types[COMPRESSED_IMAGE](header=header, format=COMPRESSED_FORMATS[encoding],
                                      data=data)
        msgtype = COMPRESSED_IMAGE
    else:
        height, width = bgr.shape[:2]
        msg = types[IMAGE](header=header, height=height, width=width,
                           encoding=encoding, is_bigendian=0, step=step, data=data)
        msgtype = IMAGE
    if ros_version == 1:
        return bytes(ts.serialize_ros1(msg, msgtype))
    return bytes(ts.serialize_cdr(msg, msgtype))
