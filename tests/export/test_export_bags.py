"""rosbag1 and rosbag2 exports read back with rosbags: same topics, stamps and payloads."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from export_sessions import PATTERN, write_session
from ros2_humble_layout import as_humble_records_it
from rosbags.highlevel import AnyReader

from speechcal_core.export import ExportError, export_session_file
from speechcal_core.export.bags import ROS2_DATABASE, SQLITE_PATH_MAX
from speechcal_core.session.store import load_session
from speechcal_core.sources import open_recording
from speechcal_core.sources.msgparse import parse_image
from speechcal_core.target import TargetSpec

BAG = {"rosbag1": "calibration.bag", "rosbag2": "calibration"}


def _expected(session_path: Path) -> dict[tuple[str, int], tuple[int, bytes, str]]:
    """(topic, stamp) -> (log time, serialized message, serialization) of accepted frames."""
    session = load_session(session_path)
    out = {}
    with open_recording(session.recording) as source:
        for s in session.sets:
            if s.decision != "accepted":
                continue
            for f in s.frames:
                if f.index >= 0:
                    raw = source.raw(f.stream, f.index)
                    out[f.stream, f.stamp_ns] = (raw.log_time_ns, raw.rawdata, raw.serialization)
    return out


def _read(bag: Path) -> dict[tuple[str, int], tuple[int, bytes, object, str]]:
    got = {}
    with AnyReader([bag]) as reader:
        for conn, log_time, rawdata in reader.messages():
            msg = reader.deserialize(rawdata, conn.msgtype)
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            assert (conn.topic, stamp) not in got
            got[conn.topic, stamp] = (log_time, bytes(rawdata), msg, conn.msgtype)
    return got


@pytest.mark.parametrize(("source_fmt", "encoding", "export_fmt"), [
    ("ros1", "jpeg", "rosbag1"),
    ("ros2-sqlite3", "png", "rosbag2"),
    ("ros2-mcap", "mono16", "rosbag2"),
])
def test_bag_of_the_same_ros_version_holds_the_source_messages_byte_for_byte(
    session_file, tmp_path: Path, source_fmt: str, encoding: str, export_fmt: str
) -> None:
    path = session_file(source_fmt, encoding)
    out = tmp_path / "bag"
    result = export_session_file(path, export_fmt, out)
    expected = _expected(path)
    got = _read(out / BAG[export_fmt])
    assert set(got) == set(expected) and result.frames == len(expected) == 6
    for key, (log_time, rawdata, _ser) in expected.items():
        assert got[key][0] == log_time
        assert got[key][1] == rawdata


@pytest.mark.parametrize("export_fmt", ["rosbag1", "rosbag2"])
def test_a_bag_export_describes_its_board_for_kalibr_beside_the_bag(
        session_file, tmp_path: Path, export_fmt: str) -> None:
    """``kalibr_calibrate_cameras --bag`` also needs ``--target``: a bag export held the
    frames only, and the operator had to find or write the board's yaml."""
    board = TargetSpec("checkerboard", 7, 5, 0.04)
    out = tmp_path / "bag"
    result = export_session_file(session_file(), export_fmt, out, target=board)
    assert result.target == "given"
    assert TargetSpec.from_kalibr_yaml(out / "target.yaml") == board
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["target"] == {"kind": "checkerboard", "rows": 7, "cols": 5,
                                  "size": 0.04, "spacing": board.spacing, "from": "given"}


def test_a_ros2_bag_has_metadata_that_humble_and_iron_can_read(session_file,
                                                                tmp_path: Path) -> None:
    # their metadata reader takes offered_qos_profiles as a string; version 9's is a list
    from ruamel.yaml import YAML  # what rosbags reads metadata with

    export_session_file(session_file("ros2-sqlite3", "png"), "rosbag2", tmp_path / "bag")
    info = YAML(typ="safe").load(tmp_path / "bag" / BAG["rosbag2"] / "metadata.yaml")
    info = info["rosbag2_bagfile_information"]
    assert info["version"] == 8 and info["storage_identifier"] == "sqlite3"
    topics = [t["topic_metadata"] for t in info["topics_with_message_count"]]
    assert topics and all(isinstance(t["offered_qos_profiles"], str) for t in topics)


def _folder_path_of(parent: Path, n_bytes: int) -> Path:
    """A path under ``parent`` exactly ``n_bytes`` long, of names under the 255-byte limit."""
    path = parent
    while (left := n_bytes - len(os.fsencode(path)) - 1) > 0:
        path = path / ("d" * min(left, 150) if left != 151 else "d" * 140)
    assert len(os.fsencode(path)) == n_bytes
    return path


def test_a_rosbag2_export_where_sqlite_cannot_open_its_database_is_refused(
        session_file, tmp_path: Path) -> None:
    # SQLite opens no path over 512 bytes with "-journal": the export used to fail after
    # reading every frame with "cannot write the bag (unable to open database file)"
    path = session_file("ros1", "mono8")
    longest = SQLITE_PATH_MAX - len(f"/.bag.partial-12345678/{ROS2_DATABASE}") + len("/bag")
    fits = _folder_path_of(tmp_path / "a", longest - len("/bag")) / "bag"
    export_session_file(path, "rosbag2", fits)
    assert len(_read(fits / BAG["rosbag2"])) == 6  # rosbags opens it there
    too_long = _folder_path_of(tmp_path / "b", longest + 1 - len("/bag")) / "bag"
    with pytest.raises(ExportError) as err:
        export_session_file(path, "rosbag2", too_long)
    message = str(err.value)
    assert message.startswith(f"{too_long / ROS2_DATABASE}: ")
    assert f"at most {longest} bytes" in message and "--format rosbag1" in message
    assert not too_long.parent.exists() or not any(too_long.parent.iterdir())
    export_session_file(path, "rosbag1", too_long)  # a ROS1 bag is one plain file
    assert len(_read(too_long / BAG["rosbag1"])) == 6


@pytest.mark.parametrize("export_fmt", ["rosbag1", "rosbag2"])
def test_a_bag_recorded_by_ros2_humble_exports_to_either_ros_version(
        small_recording, tmp_path: Path, export_fmt: str) -> None:
    # Humble stores no message definitions: the export writes the standard ones
    recorded, truth = small_recording("ros2-sqlite3", "png")
    folder = tmp_path / "session"
    shutil.copytree(recorded, folder)
    as_humble_records_it(folder / truth["recording"])
    path = write_session(folder, truth, tmp_path / "review" / "session.json", PATTERN)
    expected = _expected(path)
    result = export_session_file(path, export_fmt, tmp_path / "bag")
    got = _read(tmp_path / "bag" / BAG[export_fmt])
    assert set(got) == set(expected) and result.frames == len(expected) > 0
    for key, (log_time, rawdata, _ser) in expected.items():
        src = parse_image(rawdata, True, True)  # png: a CompressedImage
        _log, _raw, msg, msgtype = got[key]
        assert _log == log_time and msgtype == "sensor_msgs/msg/CompressedImage"
        assert msg.format == src.encoding and bytes(msg.data) == bytes(src.data)


@pytest.mark.parametrize(("source_fmt", "encoding", "export_fmt"), [
    ("ros1", "jpeg", "rosbag2"),
    ("ros2-sqlite3", "bayer_rggb8", "rosbag1"),
])
def test_bag_of_the_other_ros_version_keeps_header_encoding_and_payload(
    session_file, tmp_path: Path, source_fmt: str, encoding: str, export_fmt: str
) -> None:
    path = session_file(source_fmt, encoding)
    out = tmp_path / "bag"
    export_session_file(path, export_fmt, out)
    expected = _expected(path)
    got = _read(out / BAG[export_fmt])
    assert set(got) == set(expected)
    for key, (log_time, rawdata, serialization) in expected.items():
        src = parse_image(rawdata, serialization == "cdr", encoding == "jpeg")
        _log, _raw, msg, msgtype = got[key]
        assert _log == log_time
        assert msg.header.frame_id == src.frame_id
        assert bytes(msg.data) == bytes(src.data)  # payload copied, not re-encoded
        if encoding == "jpeg":
            assert msgtype == "sensor_msgs/msg/CompressedImage" and msg.format == src.encoding
        else:
            assert msgtype == "sensor_msgs/msg/Image"
            assert (msg.encoding, msg.width, msg.height, msg.step) == (
                src.encoding, src.width, src.height, src.step)


def test_bag_export_of_an_image_folder_carries_the_png_files_unchanged(
    session_file, tmp_path: Path
) -> None:
    from export_sessions import accepted_sets_over

    from speechcal_core.export import export_frame_sets

    kalibr = tmp_path / "kalibr"
    export_session_file(session_file(), "kalibr", kalibr)
    with open_recording([kalibr]) as folder_source:
        session = accepted_sets_over(folder_source, ["cam0", "cam1"])
        export_frame_sets(session, folder_source, "rosbag1", tmp_path / "bag")
    got = _read(tmp_path / "bag" / "calibration.bag")
    assert {k[0] for k in got} == {"/cam0", "/cam1"}
    for (topic, stamp), (_log, _raw, msg, msgtype) in got.items():
        assert msgtype == "sensor_msgs/msg/CompressedImage" and msg.format == "png"
        assert bytes(msg.data) == (kalibr / topic[1:] / f"{stamp}.png").read_bytes()
