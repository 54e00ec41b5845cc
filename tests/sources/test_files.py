"""Video files and folders of stamped images through the same FrameSource."""

from __future__ import annotations

import re
from pathlib import Path

import cv2
import numpy as np
import pytest
from source_data import PERIOD, T0, pixels

from speechcal_core.sources import BadFrameError, SourceError, open_recording


def write_video(path: Path, n: int = 20, fourcc: str = "mp4v", fps: float = 20.0) -> Path:
    """n frames whose green channel encodes the frame number (10 * i)."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*fourcc), fps, (32, 24))
    assert writer.isOpened()
    for i in range(n):
        writer.write(np.full((24, 32, 3), (60, 10 * i, 200), np.uint8))
    writer.release()
    return path


@pytest.mark.parametrize(
    ("suffix", "fourcc"), [(".mp4", "mp4v"), (".avi", "MJPG"), (".mkv", "MJPG")]
)
def test_video_frames_are_stamped_from_container_times_plus_start(
    tmp_path: Path, suffix: str, fourcc: str
) -> None:
    path = write_video(tmp_path / f"cam0{suffix}", fourcc=fourcc)
    (tmp_path / f"cam0{suffix}.start_ns").write_text(f"{T0}\n")
    with open_recording([path]) as src:
        (info,) = src.streams
        assert info.name == "cam0" and info.msgtype == "video"
        assert (info.width, info.height, info.count) == (32, 24, 20)
        assert info.median_period_ns == PERIOD and info.stamp_problems == ""
        assert list(src.stamps("cam0")) == [T0 + k * PERIOD for k in range(20)]
        for i in (13, 2, 3, 19, 0):  # random order forces seeks
            img = src.frame("cam0", i)
            assert img.shape == (24, 32, 3) and img.dtype == np.uint8
            assert abs(int(img[12, 16, 1]) - 10 * i) <= 4
        raw = src.raw("cam0", 5)
        assert raw.serialization == "bgr8" and len(raw.rawdata) == 24 * 32 * 3
        assert raw.stamp_ns == T0 + 5 * PERIOD


def test_video_start_stamp_argument_and_missing_start_is_reported(tmp_path: Path) -> None:
    path = write_video(tmp_path / "side.avi", n=5, fourcc="MJPG")
    with open_recording([path], video_start_ns=1000) as src:
        assert src.stamps("side")[0] == 1000
    with open_recording([path]) as src:
        assert src.stamps("side")[0] == 0
        assert src.streams[0].stamp_problems == (
            "no start stamp (write it to side.avi.start_ns); stamps start at 0")  # no more


def test_a_start_stamp_with_a_digit_too_many_is_named_not_a_traceback(
        tmp_path: Path) -> None:
    """20 digits overflowed the frames' int64 stamps (OverflowError); one under int64's
    end wrapped them round to negative times, which were said to be unset."""
    from speechcal_core.errors import UsageError

    path = write_video(tmp_path / "side.avi", n=5, fourcc="MJPG")
    fix = ("no header stamp: give the first frame's time in nanoseconds since 1970, e.g. "
           "1700000000000000000 (19 digits)")
    for start in (17_000_000_000_000_000_000, 9_223_372_036_854_775_000):
        with pytest.raises(UsageError) as usage:
            open_recording([path], video_start_ns=start).close()
        assert str(usage.value) == f"--video-start-ns {start}: {fix}"
        (tmp_path / "side.avi.start_ns").write_text(f"{start}\n")
        with pytest.raises(SourceError) as exc:
            open_recording([path]).close()
        assert str(exc.value) == f"{tmp_path / 'side.avi.start_ns'}: {start} is {fix}"
        (tmp_path / "side.avi.start_ns").unlink()
    named = write_video(tmp_path / "17000000000000000000.avi", n=5, fourcc="MJPG")
    with open_recording([named]) as src:  # a file name too long for a stamp is a name
        assert src.stamps("17000000000000000000")[0] == 0


def test_two_videos_give_two_streams(tmp_path: Path) -> None:
    a = write_video(tmp_path / "cam0.avi", n=5, fourcc="MJPG")
    b = write_video(tmp_path / "cam1.avi", n=7, fourcc="MJPG")
    with open_recording([a, b]) as src:
        assert [(s.name, s.count) for s in src.streams] == [("cam0", 5), ("cam1", 7)]


def test_damaged_video_is_refused_with_its_name(tmp_path: Path) -> None:
    path = tmp_path / "broken.mp4"
    path.write_bytes(b"\0\0\0\x18ftypmp42" + bytes(range(256)) * 4)
    with pytest.raises(SourceError, match=re.escape(f"{path}: cannot open the video")):
        open_recording([path])
    # on the command line: that one reason alone, without FFmpeg's own lines
    import subprocess
    import sys

    result = subprocess.run([sys.executable, "-m", "speechcal_core.cli", "index", str(path)],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        f"speechcal index: error: {path}: cannot open the video (unknown or damaged file); "
        "copy it again where it is whole, or give the cameras' recording in another form "
        "(a bag, or a folder of <stamp_ns>.png images)"]


@pytest.mark.parametrize(("content", "says"), [
    (b"", "the file is empty (0 bytes)"),
    (b"OggS" + bytes(60), "the file is an Ogg audio file (give audio with --audio)"),
    (b"#ROSBAG V2.0\n" + bytes(60), "the file is a ROS1 bag (name it .bag)"),
])
def test_a_file_named_as_a_video_says_what_it_is_and_what_to_do(
        tmp_path: Path, content: bytes, says: str) -> None:
    """An empty .mp4 (a camera that never started) or audio named .mp4: the error said
    only "unknown or damaged file", with no way on."""
    path = tmp_path / "cam0.mp4"
    path.write_bytes(content)
    with pytest.raises(SourceError) as err:
        open_recording([path])
    assert str(err.value) == (f"{path}: cannot open the video ({says}); copy it again where "
                              "it is whole, or give the cameras' recording in another form "
                              "(a bag, or a folder of <stamp_ns>.png images)")


def make_kalibr_folder(root: Path, cams: int = 2, n: int = 6) -> Path:
    """``root/cam{k}/<stamp_ns>.png`` (cam1 as JPEG) plus an imu0.csv to ignore."""
    for k in range(cams):
        folder = root / f"cam{k}"
        folder.mkdir(parents=True)
        for i in range(n):
            suffix = ".png" if k == 0 else ".jpg"
            cv2.imwrite(str(folder / f"{T0 + i * PERIOD + k}{suffix}"), pixels(k, i))
    (root / "imu0.csv").write_text("timestamp,wx\n")
    return root


def test_kalibr_image_folders_are_streams(tmp_path: Path) -> None:
    root = make_kalibr_folder(tmp_path / "dataset")
    (root / "cam0" / "notes.txt").write_text("ignored")
    with open_recording([root]) as src:
        info = {s.name: s for s in src.streams}
        assert set(info) == {"cam0", "cam1"}
        assert (info["cam0"].encoding, info["cam1"].encoding) == ("png", "jpeg")
        assert info["cam0"].count == 6 and info["cam0"].width == 16
        assert src.stamps("cam1")[2] == T0 + 2 * PERIOD + 1
        np.testing.assert_array_equal(src.frame("cam0", 4), pixels(0, 4))
        raw = src.raw("cam0", 4)
        assert raw.serialization == "file" and raw.suffix == ".png"
        assert raw.rawdata.startswith(b"\x89PNG")
        assert src.nearest("cam0", T0 + 10 * PERIOD) == 5


def test_image_files_listed_in_any_order_are_not_out_of_order(tmp_path: Path) -> None:
    """A folder lists its files in no set order; stamps in the names are the order, so
    none is reported out of order (every camera of an export was)."""
    root = make_kalibr_folder(tmp_path / "dataset", cams=1, n=40)
    with open_recording([root]) as src:
        (info,) = src.streams
        assert info.count == 40 and info.stamp_problems == ""
        assert np.all(np.diff(src.stamps("cam0")) > 0)

def test_corrupt_image_file_is_marked_bad_and_the_rest_still_works(tmp_path: Path) -> None:
    root = make_kalibr_folder(tmp_path / "dataset", cams=2)
    jpg = sorted((root / "cam1").iterdir())[3]
    jpg.write_bytes(jpg.read_bytes()[:200])  # truncated JPEG
    with open_recording([root]) as src:
        with pytest.raises(BadFrameError, match=jpg.name):
            src.frame("cam1", 3)
        assert {s.name: s.bad_frames for s in src.streams}["cam1"] == (3,)
        assert src.frame("cam1", 4).shape == (12, 16, 3)


@pytest.mark.parametrize("damage", ["truncated", "not an image"])
def test_unreadable_first_images_are_bad_frames_and_the_size_is_the_first_readable(
        tmp_path: Path, damage: str) -> None:
    root = make_kalibr_folder(tmp_path / "dataset", cams=2)
    first_two = sorted((root / "cam0").iterdir())[:2]
    for png in first_two:
        png.write_bytes(png.read_bytes()[:40] if damage == "truncated" else b"not an image")
    with open_recording([root]) as src:
        info = {s.name: s for s in src.streams}
        assert (info["cam0"].width, info["cam0"].height) == (16, 12)
        assert info["cam0"].bad_frames == (0, 1) and info["cam1"].bad_frames == ()
        (note,) = src.notes
        assert all(p.name in note for p in first_two) and "bad frames" in note
        np.testing.assert_array_equal(src.frame("cam0", 2), pixels(0, 2))


def test_index_names_an_unreadable_first_image(tmp_path: Path, capsys) -> None:
    from speechcal_core.cli import main

    root = make_kalibr_folder(tmp_path / "dataset", cams=1)
    png = sorted((root / "cam0").iterdir())[0]
    png.write_bytes(png.read_bytes()[:40])
    assert main(["index", str(root)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^cam0\s+png\s+16x12\s+6\s+\S+\s+0\s+1\s", out, re.M), out
    assert f"note: {png.parent}: 1 image cannot be read: {png.name} (PNG is truncated" in out


def test_a_camera_folder_whose_every_image_is_unreadable_is_all_bad_frames(
        tmp_path: Path) -> None:
    root = make_kalibr_folder(tmp_path / "dataset", cams=2, n=5)
    for jpg in (root / "cam1").iterdir():
        jpg.write_bytes(b"")
    with open_recording([root]) as src:
        info = {s.name: s for s in src.streams}
        assert info["cam1"].bad_frames == (0, 1, 2, 3, 4) and info["cam0"].bad_frames == ()
        (note,) = src.notes
        assert note.startswith(f"{root / 'cam1'}: none of its 5 images can be read: ")
        assert note.count("(empty compressed payload)") == 3 and "and 2 more" in note


@pytest.mark.parametrize(("names", "apart"), [
    ([f"{i:06d}.png" for i in range(1, 21)], 1),  # ffmpeg's %06d.png
    ([f"{1_700_000_005_505 + 33 * i}.png" for i in range(20)], 33),  # milliseconds
])
def test_images_named_by_frame_number_or_in_milliseconds_are_refused(
        tmp_path: Path, names: list[str], apart: int) -> None:
    """They were read as stamps a nanosecond apart: a 1 GHz camera, no clap, no note."""
    folder = tmp_path / "frames" / "cam0"
    folder.mkdir(parents=True)
    for i, name in enumerate(names):
        cv2.imwrite(str(folder / name), pixels(0, i))
    with pytest.raises(SourceError) as err:
        open_recording([tmp_path / "frames"])
    assert str(err.value).startswith(
        f"{folder}: its images' names ({names[0]}, {names[1]}, …) lie {apart} ns apart: "
        "frame numbers (or milli- or microseconds), not header stamps in nanoseconds; name "
        "each image by its header stamp in nanoseconds (<stamp_ns>.png")


@pytest.mark.parametrize("first", [17_000_000_000_000_000_000, 9_223_372_036_654_775_807])
def test_images_named_beyond_any_header_stamp_are_refused(tmp_path: Path,
                                                          first: int) -> None:
    """A digit too many in the names raised OverflowError; names near int64's end were
    taken, leaving no room for the times computed from them."""
    folder = tmp_path / "frames" / "cam0"
    folder.mkdir(parents=True)
    for i in range(3):
        cv2.imwrite(str(folder / f"{first + i * PERIOD}.png"), pixels(0, i))
    last = f"{first + 2 * PERIOD}.png"
    with pytest.raises(SourceError) as exc:
        open_recording([tmp_path / "frames"]).close()
    assert str(exc.value) == (
        f"{folder}: its image {last} is named beyond any header stamp; name each image by "
        "its header stamp in nanoseconds since 1970 (<stamp_ns>.png, e.g. "
        "1700000000000000000.png)")


def test_folder_without_stamped_images_is_refused(tmp_path: Path) -> None:
    (tmp_path / "cam0").mkdir()
    (tmp_path / "cam0" / "image.png").write_bytes(b"x")
    with pytest.raises(SourceError, match=re.escape("no <stamp_ns>.png")) as err:
        open_recording([tmp_path])
    assert "give that file" not in str(err.value)
    (tmp_path / "recording.bag").write_bytes(b"x")  # the session's folder, not its bag
    with pytest.raises(SourceError, match=re.escape("; it holds recording.bag: give that "
                                                    "file")):
        open_recording([tmp_path])


def test_a_folder_holding_a_ros2_bag_folder_points_to_it(tmp_path: Path) -> None:
    """A ROS2 session's folder given instead of its bag folder (synth writes
    OUT/recording/ with metadata.yaml)."""
    bag = tmp_path / "recording"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    (tmp_path / "audio.ogg").write_bytes(b"x")
    with pytest.raises(SourceError, match=re.escape("; it holds recording: give that ROS2 "
                                                    "bag folder")):
        open_recording([tmp_path])
