"""Writers for small bags with known content and stamps (rosbags writers, real files)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

T0 = 1_700_000_000_000_000_000
PERIOD = 50_000_000  # 20 Hz
ROS1 = get_typestore(Stores.ROS1_NOETIC)
ROS2 = get_typestore(Stores.ROS2_HUMBLE)
FORMATS = ("ros1", "ros1-bz2", "ros1-lz4", "ros2-sqlite3", "ros2-mcap", "ros2-mcap-zstd")


def pixels(cam: int, i: int, width: int = 16, height: int = 12) -> np.ndarray:
    """Known BGR content of camera ``cam`` frame ``i``: a flat colour plus a marker pixel."""
    img = np.empty((height, width, 3), np.uint8)
    img[:] = (cam * 40 % 256, i % 256, 200)
    img[0, 0] = (255, 0, 0)
    return img


@dataclass
class Cam:
    """One camera topic to write."""

    topic: str
    stamps: Sequence[int]
    encoding: str = "bgr8"  # or "jpeg"/"png" for CompressedImage
    width: int = 16
    height: int = 12
    index: int = 0
    #: frame index -> replacement payload bytes (raw data or compressed bytes)
    payloads: dict[int, bytes] = field(default_factory=dict)
    step_pad: int = 0


def serialize_image(ros1: bool, stamp: int, cam: Cam, i: int) -> bytes:
    """A serialized Image / CompressedImage for frame i of ``cam``."""
    ts = ROS1 if ros1 else ROS2
    header_t = ts.types["std_msgs/msg/Header"]
    time_t = ts.types["builtin_interfaces/msg/Time"]
    kw = {"seq": i} if ros1 else {}
    header = header_t(
        **kw, stamp=time_t(sec=stamp // 10**9, nanosec=stamp % 10**9), frame_id=cam.topic[1:5]
    )
    img = pixels(cam.index, i, cam.width, cam.height)
    ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    if cam.encoding in ("jpeg", "png"):
        data = cam.payloads.get(i)
        if data is None:
            suffix = ".jpg" if cam.encoding == "jpeg" else ".png"
            data = cv2.imencode(suffix, img)[1].tobytes()
        msg = ts.types["sensor_msgs/msg/CompressedImage"](
            header, cam.encoding, np.frombuffer(data, np.uint8)
        )
        return bytes(ser(msg, "sensor_msgs/msg/CompressedImage"))
    step = cam.width * 3 + cam.step_pad
    rows = np.zeros((cam.height, step), np.uint8)
    rows[:, : cam.width * 3] = img.reshape(cam.height, -1)
    data = cam.payloads.get(i, rows.tobytes())
    msg = ts.types["sensor_msgs/msg/Image"](
        header, cam.height, cam.width, cam.encoding, 0, step, np.frombuffer(data, np.uint8)
    )
    return bytes(ser(msg, "sensor_msgs/msg/Image"))


def write_bag(
    path: Path, fmt: str, cams: Sequence[Cam], *, imu: bool = False, chunk_bytes: int = 0
) -> Path:
    """Write cams (and optionally an IMU topic) in ``fmt``; returns the recording path.

    ``chunk_bytes`` sets the ROS1 chunk size (small values give a chunk per message).
    """
    ros1 = fmt.startswith("ros1")
    ts = ROS1 if ros1 else ROS2
    if ros1:
        path = path.with_suffix(".bag")
        writer: Writer1 | Writer2 = Writer1(path)
        if fmt != "ros1":
            writer.set_compression(Writer1.CompressionFormat[fmt.split("-")[1].upper()])
        if chunk_bytes:
            writer.chunk_threshold = chunk_bytes
    else:
        plugin = StoragePlugin.MCAP if fmt.startswith("ros2-mcap") else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
        if fmt == "ros2-mcap-zstd":
            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer:
        events: list[tuple[int, int, object, bytes]] = []
        for cam in cams:
            msgtype = (
                "sensor_msgs/msg/CompressedImage"
                if cam.encoding in ("jpeg", "png")
                else "sensor_msgs/msg/Image"
            )
            conn = writer.add_connection(cam.topic, msgtype, typestore=ts)
            for i, stamp in enumerate(cam.stamps):
                log = T0 + i * PERIOD + 3_000_000 + cam.index
                events.append((log, len(events), conn, serialize_image(ros1, stamp, cam, i)))
        if imu:
            imu_t = ts.types["sensor_msgs/msg/Imu"]
            conn = writer.add_connection("/imu", "sensor_msgs/msg/Imu", typestore=ts)
            zero = np.zeros(9)
            header = ts.types["std_msgs/msg/Header"]
            vec = ts.types["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.8)
            quat = ts.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
            time_t = ts.types["builtin_interfaces/msg/Time"]
            for k in range(40):
                t = T0 + k * PERIOD // 2
                kw = {"seq": k} if ros1 else {}
                h = header(**kw, stamp=time_t(sec=t // 10**9, nanosec=t % 10**9), frame_id="imu")
                msg = imu_t(h, quat, zero, vec, zero, vec, zero)
                ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
                events.append((t, len(events), conn, bytes(ser(msg, "sensor_msgs/msg/Imu"))))
        for log, _, conn, data in sorted(events, key=lambda e: (e[0], e[1])):
            writer.write(conn, log, data)  # type: ignore[arg-type]
    return path


def regular(n: int = 20, start: int = T0, period: int = PERIOD) -> list[int]:
    """n evenly spaced stamps."""
    return [start + k * period for k in range(n)]
