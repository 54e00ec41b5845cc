"""rosbag1 and rosbag2 exports: the chosen frames' messages on their original topics.

``OUT/calibration.bag`` (ROS1, uncompressed) or ``OUT/calibration/`` (a ROS2 bag folder,
sqlite3 storage, metadata version 8, whose QoS profiles are a string: Humble and Iron fail
on version 9's list, later releases read both). Messages keep their header, encoding and
payload (see :mod:`bag_messages`) and their recorded log time; they are written in
log-time order, each frame once even when two sets chose it.
"""

from __future__ import annotations

import os
import sqlite3
from typing import TYPE_CHECKING

from speechcal_core.export.bag_messages import BagMessage, bag_message
from speechcal_core.export.errors import ExportError
from speechcal_core.export.plan import Outcome, Progress
from speechcal_core.fsutil import staging_name_bytes
from speechcal_core.sources.errors import BadFrameError
from speechcal_core.sources.rosbag2 import SQLITE_PATH_MAX

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Plan
    from speechcal_core.sources.base import FrameSource

ROS1_BAG = "calibration.bag"
ROS2_BAG = "calibration"
ROS2_DATABASE = f"{ROS2_BAG}/{ROS2_BAG}.db3"  # what rosbags' sqlite3 storage names it


def rosbag2_path_problem(out: Path) -> str:
    """Why a rosbag2 export cannot be written at ``out`` ("" when it can): its database
    would lie at a path too long for SQLite, while written (in the hidden folder beside
    ``out``) or where it ends up, and neither rosbags nor ``ros2 bag`` could open it."""
    db = out.absolute() / ROS2_DATABASE
    final = len(os.fsencode(db))
    staged = final - len(os.fsencode(out.name)) + staging_name_bytes(out)
    longest = max(final, staged)
    if longest <= SQLITE_PATH_MAX:
        return ""
    room = SQLITE_PATH_MAX - (longest - len(os.fsencode(out.absolute())))
    return (f"{db}: a ROS 2 bag's database there would have a path of {longest} bytes "
            f"(while written), and SQLite, its storage, opens no file whose path is longer "
            f"than {SQLITE_PATH_MAX} bytes (ros2 bag could not read it either); choose an "
            f"output folder whose path is at most {room} bytes long, or --format rosbag1")


def _messages(
    source: FrameSource, plan: Plan, ros_version: int, where: str, progress: Progress
) -> tuple[list[BagMessage], Outcome]:
    out = Outcome.empty()
    messages: dict[tuple[str, int], BagMessage] = {}
    total = max(len(plan.frames), 1)
    for k, pf in enumerate(plan.frames):
        progress(f"reading {pf.choice.stream} frame {pf.index}", 0.8 * k / total)
        key = (pf.frame_set.id, pf.choice.stream)
        if (pf.choice.stream, pf.index) in messages:
            out.files[key] = where
            continue
        try:
            raw = source.raw(pf.choice.stream, pf.index)
        except BadFrameError as exc:
            out.skipped[key] = str(exc)
            continue
        messages[(pf.choice.stream, pf.index)] = bag_message(raw, ros_version)
        out.files[key] = where
    ordered = sorted(messages.values(), key=lambda m: (m.log_time_ns, m.topic, m.stamp_ns))
    return ordered, out


def write_rosbag1(source: FrameSource, plan: Plan, root: Path, progress: Progress) -> Outcome:
    """``root/calibration.bag`` with the chosen frames."""
    from rosbags.rosbag1 import Writer

    messages, out = _messages(source, plan, 1, ROS1_BAG, progress)
    progress(f"writing {ROS1_BAG}", 0.8)
    try:
        with Writer(root / ROS1_BAG) as writer:
            conns = {}
            for m in messages:
                if m.topic not in conns:
                    conns[m.topic] = writer.add_connection(
                        m.topic, m.msgtype, msgdef=m.msgdef, md5sum=m.digest,
                        callerid=m.callerid, latching=m.latching)
                writer.write(conns[m.topic], m.log_time_ns, m.data)
    except OSError as exc:
        raise ExportError(f"{root / ROS1_BAG}: cannot write the bag ({exc.strerror})") from None
    out.written.append(ROS1_BAG)
    return out


def write_rosbag2(source: FrameSource, plan: Plan, root: Path, progress: Progress) -> Outcome:
    """``root/calibration/`` (metadata.yaml + calibration.db3) with the chosen frames."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    messages, out = _messages(source, plan, 2, ROS2_BAG, progress)
    progress(f"writing {ROS2_BAG}/", 0.8)
    bag = root / ROS2_BAG
    try:
        with Writer(bag, version=8, storage_plugin=StoragePlugin.SQLITE3) as writer:
            conns = {}
            for m in messages:
                if m.topic not in conns:
                    conns[m.topic] = writer.add_connection(
                        m.topic, m.msgtype, msgdef=m.msgdef, rihs01=m.digest)
                writer.write(conns[m.topic], m.log_time_ns, m.data)
    except OSError as exc:
        raise ExportError(f"{bag}: cannot write the bag ({exc.strerror})") from None
    except sqlite3.Error as exc:  # the storage plugin's database: a full disk, say
        raise ExportError(f"{bag}: cannot write the bag ({exc})") from None
    out.written.extend(sorted(f"{ROS2_BAG}/{p.name}" for p in bag.iterdir()))
    return out
