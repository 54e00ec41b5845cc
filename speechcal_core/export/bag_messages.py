"""Serialized image messages for a bag export, from the recording's undecoded frames.

Bag frames keep their message: written as stored when the serialization matches the bag
(ROS1 into rosbag1, CDR into rosbag2), otherwise converted field by field by rosbags
(``ros1_to_cdr`` / ``cdr_to_ros1``: the header's ``seq`` is dropped or set to 0, every
other field, including a JPEG/PNG or raw pixel payload, is copied byte for byte).
Image files become ``sensor_msgs/msg/CompressedImage`` carrying the file's bytes; video
frames become raw ``sensor_msgs/msg/Image`` (``bgr8``) on topic ``/<name>``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import TYPE_CHECKING

import numpy as np
from rosbags.typesys import Stores, get_typestore

from speechcal_core.export.errors import ExportError
from speechcal_core.export.plan import safe_name

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

    from speechcal_core.sources.base import RawFrame

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED_IMAGE = "sensor_msgs/msg/CompressedImage"
_BYTES_PER_PIXEL = {"bgr8": 3, "mono8": 1, "mono16": 2}
_FILE_FORMATS = {".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg"}


@cache
def typestore(ros_version: int) -> Typestore:
    """ROS1 Noetic or ROS2 Humble message definitions (Image and CompressedImage are the
    same in every later ROS2 release)."""
    return get_typestore(Stores.ROS1_NOETIC if ros_version == 1 else Stores.ROS2_HUMBLE)


@dataclass(frozen=True)
class BagMessage:
    """One message to write, with what its connection needs."""

    topic: str
    msgtype: str  # rosbags form, sensor_msgs/msg/Image
    data: bytes
    log_time_ns: int
    stamp_ns: int
    msgdef: str
    digest: str  # md5sum (ROS1) or RIHS01 hash (ROS2)
    callerid: str | None = None
    latching: int | None = None


def topic_for(stream: str, msgtype: str) -> str:
    """Bag streams keep their topic; image folders and videos get ``/<safe name>``."""
    if msgtype in (IMAGE, COMPRESSED_IMAGE):
        return stream
    return "/" + safe_name(stream)


def _definition(msgtype: str, ros_version: int, conn: dict[str, str]) -> tuple[str, str]:
    ts = typestore(ros_version)
    if ros_version == 1:
        if conn.get("msgdef") and conn.get("md5sum"):
            return conn["msgdef"], conn["md5sum"]
        msgdef, md5sum = ts.generate_msgdef(msgtype)
        return msgdef, md5sum
    rihs01 = ts.hash_rihs01(msgtype)
    if conn.get("msgdef") and "source_msgtype" in conn and "md5sum" not in conn:
        return conn["msgdef"], rihs01  # a ROS2 source's own definition
    msgdef, _ = ts.generate_msgdef(msgtype, ros_version=2)
    return msgdef, rihs01


def _built(raw: RawFrame, ros_version: int) -> tuple[str, bytes]:
    """Message type and serialized message for a frame that was never a message."""
    ts = typestore(ros_version)
    types = ts.types
    sec, nsec = divmod(raw.stamp_ns, 1_000_000_000)
    stamp = types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nsec)
    frame_id = safe_name(raw.stream)
    header = (types["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame_id)
              if ros_version == 1 else types["std_msgs/msg/Header"](stamp=stamp,
                                                                   frame_id=frame_id))
    payload = np.frombuffer(raw.rawdata, np.uint8)
    if raw.serialization == "file":
        fmt = _FILE_FORMATS.get(raw.suffix.lower())
        if fmt is None:
            raise ExportError(f"{raw.stream}: cannot put a {raw.suffix!r} file in a bag")
        msg = types[COMPRESSED_IMAGE](header=header, format=fmt, data=payload)
        msgtype = COMPRESSED_IMAGE
    elif raw.serialization in _BYTES_PER_PIXEL:
        step = raw.width * _BYTES_PER_PIXEL[raw.serialization]
        msg = types[IMAGE](header=header, height=raw.height, width=raw.width,
                           encoding=raw.serialization, is_bigendian=0, step=step, data=payload)
        msgtype = IMAGE
    else:
        raise ExportError(f"{raw.stream}: frames of kind {raw.serialization!r} cannot go in a bag")
    data = ts.serialize_ros1(msg, msgtype) if ros_version == 1 else ts.serialize_cdr(msg, msgtype)
    return msgtype, bytes(data)


def bag_message(raw: RawFrame, ros_version: int) -> BagMessage:
    """The message for ``raw`` in a ROS1 (``ros_version=1``) or ROS2 bag."""
    conn = raw.connection
    if raw.serialization in ("ros1", "cdr"):
        msgtype = raw.msgtype
        same = (raw.serialization == "ros1") == (ros_version == 1)
        if same:
            data = raw.rawdata
        else:
            ts2 = typestore(2)  # its Header has no seq: the converters drop or add it
            try:
                data = bytes(ts2.cdr_to_ros1(raw.rawdata, msgtype) if ros_version == 1
                             else ts2.ros1_to_cdr(raw.rawdata, msgtype))
            except Exception as exc:  # rosbags' SerdeError and struct errors
                raise ExportError(
                    f"{raw.stream}: frame stamped {raw.stamp_ns} cannot be converted "
                    f"for a ROS{ros_version} bag ({exc})"
                ) from None
        msgdef, digest = _definition(msgtype, ros_version, conn if same else {})
    else:
        msgtype, data = _built(raw, ros_version)
        msgdef, digest = _definition(msgtype, ros_version, {})
    callerid = conn.get("callerid") or None if ros_version == 1 else None
    latching = None
    if ros_version == 1 and conn.get("latching", "").isdigit():
        latching = int(conn["latching"])
    return BagMessage(topic_for(raw.stream, raw.msgtype), msgtype, data, raw.log_time_ns,
                      raw.stamp_ns, msgdef, digest, callerid, latching)
