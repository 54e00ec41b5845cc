"""Damaged and unusual recordings, each made for real: clear errors or marked-bad frames."""

from __future__ import annotations

import os
import re
import sqlite3
import struct
from pathlib import Path

import numpy as np
import pytest
from source_data import T0, Cam, regular

from speechcal_core.frames.preview import preview_gray
from speechcal_core.sources import BadFrameError, SourceError, open_recording
from speechcal_core.sources.rosbag1 import Ros1Bag
from speechcal_core.sync.clap_frames import full_gray, small_gray


def _index_pos(path: Path) -> int:
    bag = Ros1Bag(path)
    try:
        return bag.index_pos
    finally:
        bag.close()


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4"])
def test_unindexed_bag_names_reindex_command_and_scan_recovers(make_bag, fmt: str) -> None:
    path = make_bag(fmt, imu=True)
    os.truncate(path, _index_pos(path))  # the index section is gone, as after a crash
    with pytest.raises(SourceError) as err:
        open_recording([path])
    msg = str(err.value)
    assert f"rosbag reindex {path}" in msg and f"speechcal index {path} --scan" in msg
    with open_recording([path], scan=True) as src:
        assert [s.count for s in src.streams] == [20, 20]
        assert src.frame("/cam0/image_raw", 19).shape == (12, 16, 3)
    # as the message says: after the scan, the other commands open it from its index
    with open_recording([path]) as src:
        assert [s.count for s in src.streams] == [20, 20]


def test_bag_with_zero_index_pos_and_cut_in_a_chunk_recovers_complete_messages(make_bag) -> None:
    path = make_bag("ros1", [Cam("/cam0/image_raw", regular(40))])
    with path.open("r+b") as fh:  # an interrupted recording: header never updated
        data = fh.read(4096 + 13)
        pos = data.index(b"index_pos=") + len(b"index_pos=")
        fh.seek(pos)
        fh.write(struct.pack("<Q", 0))
    os.truncate(path, int(path.stat().st_size * 0.6))
    with pytest.raises(SourceError, match="not indexed"):
        open_recording([path])
    with open_recording([path], scan=True) as src:
        (info,) = src.streams
        assert 10 < info.count < 40
        assert list(src.stamps("/cam0/image_raw")) == regular(info.count)
        src.frame("/cam0/image_raw", info.count - 1)


def test_truncated_mcap_is_refused_then_recovered_by_scanning(make_bag) -> None:
    # 40 frames of 57 kB: three 1 MB chunks, the file cut inside the second
    folder = make_bag("ros2-mcap", [Cam("/cam0/image_raw", regular(40), width=160, height=120)])
    (mcap,) = folder.glob("*.mcap")
    os.truncate(mcap, int(mcap.stat().st_size * 0.7))
    with pytest.raises(SourceError) as err:
        open_recording([mcap])
    assert "truncated" in str(err.value) and mcap.name in str(err.value)
    assert "--scan" in str(err.value)
    with open_recording([mcap], scan=True) as src:
        (info,) = src.streams
        assert 17 < info.count < 40
        assert list(src.stamps("/cam0/image_raw")) == regular(info.count)
        src.frame("/cam0/image_raw", info.count - 1)
    # as the message says: after the scan, the other commands open it from its index
    with open_recording([mcap]) as src:
        assert src.streams[0].count == info.count
        src.frame("/cam0/image_raw", info.count - 1)


def test_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(SourceError, match=re.escape("nothere.bag: file not found")):
        open_recording([tmp_path / "nothere.bag"])


def test_bag_without_image_topics_lists_what_it_has(make_bag) -> None:
    path = make_bag("ros1", [], imu=True)
    with pytest.raises(SourceError, match=r"no sensor_msgs/Image.*\/imu \[sensor_msgs/Imu\]") \
            as exc:
        open_recording([path])
    assert str(exc.value).startswith(f"{path}: ")  # the path as given, not only its name


@pytest.mark.parametrize("fmt", ["ros1", "ros2-sqlite3", "ros2-mcap"])
def test_an_image_topic_without_any_message_is_named(make_bag, fmt: str) -> None:
    """A camera whose driver died before its first frame leaves its topic in the bag
    with no message (ROS2 records every topic it discovers): it was left out without a
    word, and a recording of such topics alone was said to have no image topics."""
    cams = [Cam("/cam0/image_raw", regular(), index=0), Cam("/cam1/image_raw", [], index=1)]
    with open_recording([make_bag(fmt, cams)]) as src:
        assert [s.name for s in src.streams] == ["/cam0/image_raw"]
        assert ("/cam1/image_raw: an image topic without any message (its camera sent no "
                "frame while recording): left out") in src.notes
    path = make_bag(fmt, [Cam("/cam1/image_raw", [], index=1)])
    with pytest.raises(SourceError) as exc:
        open_recording([path])
    assert str(exc.value).startswith(str(path))  # the bag, or the file in its folder
    assert str(exc.value).endswith(
        ": its image topics hold no message (/cam1/image_raw): the cameras sent no frame "
        "while recording; check them and record again")


@pytest.mark.parametrize("fmt", ["ros1-bz2", "ros2-sqlite3"])
def test_corrupt_jpeg_is_marked_bad_and_the_stream_still_works(make_bag, fmt: str) -> None:
    good = Cam("/cam0/image_raw", regular(10), encoding="jpeg")
    path = make_bag(fmt, [good])
    ok_jpeg = None
    with open_recording([path]) as src:
        ok_jpeg = bytes(src.raw("/cam0/image_raw", 0).rawdata)
    assert ok_jpeg
    # the same JPEG with its second half replaced by garbage, and one cut short
    cut = Cam("/cam0/image_raw", regular(10), encoding="jpeg")
    frames = {4: b"\xff\xd8\xff\xe0" + bytes(range(256)) * 3 + b"\xff\xd9", 7: b"\xff\xd8\xff\xdb"}
    cut.payloads.update(frames)
    path = make_bag(fmt, [cut], name=f"bad_{fmt}")
    with open_recording([path]) as src:
        for i in (4, 7):
            with pytest.raises(BadFrameError, match=f"frame {i}"):
                src.frame("/cam0/image_raw", i)
        assert src.streams[0].bad_frames == (4, 7)
        assert src.frame("/cam0/image_raw", 5).shape == (12, 16, 3)


@pytest.mark.parametrize("fmt", ["ros1", "ros2-mcap"])
def test_an_empty_compressed_frame_is_a_bad_frame_in_the_reduced_preview_too(
        make_bag, fmt: str) -> None:
    """A driver's CompressedImage with no data: the frame search's reduced decoding ended
    `speechcal process` in an OpenCV assertion traceback."""
    cam = Cam("/cam0/image_raw", regular(10), encoding="jpeg", width=64, height=48)
    cam.payloads[4] = b""
    with open_recording([make_bag(fmt, [cam])]) as src:
        with pytest.raises(BadFrameError, match="frame 4 is empty"):
            preview_gray(src, "/cam0/image_raw", 4, 2)
        assert preview_gray(src, "/cam0/image_raw", 5, 2).shape == (24, 32)


@pytest.mark.parametrize("fmt", ["ros1", "ros2-mcap"])
def test_damaged_jpeg_frames_in_the_clap_search_are_marked_bad_as_when_decoded(
        make_bag, fmt: str) -> None:
    """The clap search decodes JPEG frames straight to their luma; a damaged, cut or
    empty one is read as a full decoding reads it: a BadFrameError naming the frame, and
    the frame marked bad in its stream (not a grey picture from a half-decoded JPEG)."""
    cam = Cam("/cam0/image_raw", regular(10), encoding="jpeg", width=64, height=48)
    cam.payloads.update({4: b"\xff\xd8\xff\xe0" + bytes(range(256)) * 3 + b"\xff\xd9",
                         6: b"\xff\xd8\xff\xdb", 7: b""})
    with open_recording([make_bag(fmt, [cam], name=f"clap_{fmt}")]) as src:
        info = src.streams[0]
        for i in (4, 6, 7):
            with pytest.raises(BadFrameError, match=f"frame {i}"):
                small_gray(src, info, i, None)
            with pytest.raises(BadFrameError, match=f"frame {i}"):
                full_gray(src, info, i, None)
        assert src.streams[0].bad_frames == (4, 6, 7)
        assert small_gray(src, info, 5, None)[0].shape == (48, 64)
        assert full_gray(src, info, 5, None).shape == (48, 64)


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros2-sqlite3", "ros2-mcap", "ros2-mcap-zstd"])
def test_wrong_size_raw_payload_is_found_while_indexing(make_bag, fmt: str) -> None:
    cam = Cam("/cam0/image_raw", regular(10))
    cam.payloads[6] = bytes(100)  # 100 bytes where 16x12 bgr8 needs 576
    with open_recording([make_bag(fmt, [cam])]) as src:
        assert src.streams[0].bad_frames == (6,)
        with pytest.raises(BadFrameError, match="payload has 100 bytes"):
            src.frame("/cam0/image_raw", 6)
        assert src.frame("/cam0/image_raw", 7).shape == (12, 16, 3)


def test_unordered_and_duplicate_stamps_are_sorted_and_reported(make_bag) -> None:
    stamps = regular(10)
    stamps[3], stamps[4] = stamps[4], stamps[3]
    stamps[8] = stamps[7]
    with open_recording([make_bag("ros2-sqlite3", [Cam("/cam0/image_raw", stamps)])]) as src:
        got = src.stamps("/cam0/image_raw")
        assert list(got) == sorted(stamps)
        problems = src.streams[0].stamp_problems
        assert "1 stamp out of order (sorted)" in problems and "1 duplicate stamp" in problems
        # frame 3 in stamp order is the message stored 4th (it carries pixel value 4)
        assert src.frame("/cam0/image_raw", 3)[5, 5, 1] == 4


def test_unknown_encoding_is_named_in_the_error(make_bag) -> None:
    cam = Cam("/cam0/image_raw", regular(3), encoding="weird24")
    with open_recording([make_bag("ros1", [cam])]) as src:
        assert src.streams[0].encoding == "weird24"
        with pytest.raises(SourceError, match="unknown image encoding 'weird24'"):
            src.frame("/cam0/image_raw", 0)


def test_damaged_lz4_chunk_names_the_file(make_bag) -> None:
    path = make_bag("ros1-lz4", [Cam("/cam0/image_raw", regular(5))])
    with open_recording([path], use_cache=False):
        pass
    data = bytearray(path.read_bytes())
    start = 4096 + 13 + 200
    data[start : start + 300] = bytes(300)
    path.write_bytes(bytes(data))
    with pytest.raises(SourceError, match=f"{path.name}.*(damaged|truncated)"):
        open_recording([path])


def test_damaged_sqlite_file_names_the_file(make_bag) -> None:
    folder = make_bag("ros2-sqlite3")
    (db3,) = folder.glob("*.db3")
    data = bytearray(db3.read_bytes())
    data[100:4096] = b"\x5a" * (4096 - 100)  # first page (schema) overwritten
    db3.write_bytes(bytes(data))
    with pytest.raises(SourceError, match=db3.name):
        open_recording([folder])


def test_file_that_is_not_a_bag_is_refused_naming_the_path_as_given(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "data").mkdir()
    monkeypatch.chdir(tmp_path)
    path = Path("data") / "notes.bag"
    path.write_text("hello")
    with pytest.raises(SourceError, match=re.escape(f"{path}: not a ROS1 bag")):
        open_recording([path])
    db = Path("data") / "empty.db3"
    sqlite3.connect(db).close()
    with pytest.raises(SourceError, match=re.escape(f"{db}: not a rosbag2 file")):
        open_recording([db])
    mcap = Path("data") / "other.mcap"
    mcap.write_text("hello")
    with pytest.raises(SourceError, match=re.escape(f"{mcap}: not an MCAP file")):
        open_recording([mcap])


@pytest.mark.parametrize(("name", "content", "says"), [
    ("cut.bag", b"", "{path}: not a ROS1 bag (the file is empty (0 bytes)); give the "
                     "recording's .bag file"),
    ("shot.bag", b"\x89PNG\r\n\x1a\n" + bytes(32), "{path}: not a ROS1 bag (the file is a "
                                                    "PNG image)"),
    ("session.json", b'{"schema": 1}', "{path}: this is a JSON file (a session file opens "
                                       "with speechcal review), not a recording"),
    ("mic.ogg", b"OggS" + bytes(60), "{path}: this is an Ogg audio file (give audio with "
                                     "--audio), not a recording"),
])
def test_a_file_given_as_a_recording_is_named_for_what_it_is(
        tmp_path: Path, name: str, content: bytes, says: str) -> None:
    """An empty bag (a recorder stopped early), a PNG named .bag, an audio or a session
    file in the recording's place: the error says what the file is, not only "magic
    missing" or "unknown recording kind"."""
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(SourceError, match=re.escape(says.format(path=path))):
        open_recording([path])


def test_jpeg_stream_dimensions_come_from_the_first_decodable_frame(make_bag) -> None:
    cam = Cam("/cam0/image_raw", regular(4), encoding="png")
    cam.payloads[0] = b"\x89PNG\r\n\x1a\n" + bytes(20)
    with open_recording([make_bag("ros2-mcap", [cam])]) as src:
        info = src.streams[0]
        assert (info.encoding, info.width, info.height) == ("png", 16, 12)
        assert src.stamps("/cam0/image_raw")[0] == T0
        assert np.asarray(src.frame("/cam0/image_raw", 1)).shape == (12, 16, 3)


def test_damaged_record_in_a_chunk_is_reported_and_the_rest_is_read(make_bag) -> None:
    path = make_bag("ros1", [Cam("/cam0/image_raw", regular(20))])
    bag = Ros1Bag(path)
    scan = bag.scan()
    bag.close()
    data_pos = int(scan.topics[0].offsets[12])
    with path.open("r+b") as fh:  # the data length of message 12 becomes absurd
        fh.seek(data_pos - 4)
        fh.write(struct.pack("<I", 0xFFFFFFF0))
    with open_recording([path]) as src:
        assert src.streams[0].count == 12
        assert any("damaged; 8 of its 20 messages are unreadable" in n for n in src.notes)
        src.frame("/cam0/image_raw", 11)


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4"])
def test_a_damaged_chunk_of_an_indexed_bag_is_skipped_by_scanning(make_bag, fmt: str) -> None:
    """Damage over one chunk's header: the error's advice (--scan) then keeps the other
    chunks, which the bag's index still finds, and says what was skipped."""
    path = make_bag(fmt, [Cam("/cam0/image_raw", regular(20))], chunk_bytes=1)
    bag = Ros1Bag(path)
    bag.scan()
    chunks = sorted(pos for pos, _ids, _total in bag.chunk_infos)
    bag.close()
    assert len(chunks) == 20  # a chunk per message
    with path.open("r+b") as fh:
        fh.seek(chunks[7])
        fh.write(b"\xab" * 64)
    with pytest.raises(SourceError) as err:
        open_recording([path], use_cache=False)
    assert f"chunk at byte {chunks[7]} is damaged" in str(err.value)
    assert f"speechcal index {path} --scan" in str(err.value)
    with open_recording([path], scan=True) as src:
        assert src.streams[0].count == 19
        assert list(src.stamps("/cam0/image_raw")) == regular(20)[:7] + regular(20)[8:]
        assert any(f"chunk at byte {chunks[7]} is damaged; its message is skipped" in n
                   for n in src.notes)
        src.frame("/cam0/image_raw", 7)  # the message after the damaged chunk
    with open_recording([path]) as src:  # the other commands then use the recovered index
        assert src.streams[0].count == 19


def test_commands_in_messages_quote_paths_with_spaces(make_bag, tmp_path: Path) -> None:
    """The advice is pasted into a shell: a path with spaces must stay one argument."""
    path = make_bag("ros1", imu=True)
    spaced = tmp_path / "my data" / "cut bag ü.bag"
    spaced.parent.mkdir()
    spaced.write_bytes(path.read_bytes()[:_index_pos(path)])
    with pytest.raises(SourceError) as err:
        open_recording([spaced])
    assert f"`rosbag reindex '{spaced}'`" in str(err.value)
    assert f"`speechcal index '{spaced}' --scan`" in str(err.value)


def test_a_cut_short_sqlite_bag_is_named_as_such_with_what_can_be_done(make_bag) -> None:
    folder = make_bag("ros2-sqlite3", [Cam("/cam0/image_raw", regular(200))])
    (db3,) = folder.glob("*.db3")
    os.truncate(db3, db3.stat().st_size // 2)
    with pytest.raises(SourceError) as err:
        open_recording([folder], use_cache=False)
    message = str(err.value)
    assert db3.name in message and "cut short" in message
    assert "copy it again" in message and "ros2 bag record -s mcap" in message


@pytest.mark.parametrize("keep", [3000, 9000])
def test_a_bag_cut_before_its_first_image_says_so(make_bag, keep: int) -> None:
    """Cut inside its header (3000 bytes) or its first chunk: --scan said "no image
    topics; record the camera image topics", as if the cameras had not been recorded."""
    path = make_bag("ros1", [Cam("/cam0/image_raw", regular(5))])
    os.truncate(path, keep)
    with pytest.raises(SourceError) as err:
        open_recording([path], scan=True, use_cache=False)
    message = str(err.value)
    assert "no image message could be read" in message and "truncated" in message
    assert "copy the recording again where it is whole" in message


def test_a_sqlite_bag_too_deep_for_sqlite_says_to_move_it(make_bag, tmp_path: Path) -> None:
    # SQLite opens no path over 504 bytes: this said "not a readable rosbag2 sqlite3 file
    # (unable to open database file)" and advised copying a cut-short bag again
    folder = make_bag("ros2-sqlite3", [Cam("/cam0/image_raw", regular(20))])
    deep = tmp_path / ("d" * 200) / ("e" * 200) / ("f" * 100)
    deep.mkdir(parents=True)
    moved = folder.rename(deep / folder.name)
    (db3,) = moved.glob("*.db3")
    with pytest.raises(SourceError) as err:
        open_recording([moved], use_cache=False)
    message = str(err.value)
    assert message.startswith(f"{db3}: its path is {len(os.fsencode(db3))} bytes long")
    assert "shorter path" in message and "cut short" not in message


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros2-sqlite3", "ros2-mcap"])
def test_a_closed_bag_without_any_message_says_so_not_interrupted(make_bag, fmt: str) -> None:
    """``rosbag record`` stopped cleanly while no camera published: a whole bag without
    connections, whose index section is empty (it starts at the file's end). It is not an
    interrupted recording (reindexing or --scan would not help): the error says no image
    topic was recorded, with or without --scan."""
    path = make_bag(fmt, [])
    for scan in (False, True):
        with pytest.raises(SourceError) as err:
            open_recording([path], scan=scan)
        msg = str(err.value)
        assert "no sensor_msgs/Image or CompressedImage topics" in msg
        assert "record the camera image topics" in msg
        assert "reindex" not in msg and "truncated" not in msg
