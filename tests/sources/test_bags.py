"""ROS1, ROS2 sqlite3 and MCAP bags through one FrameSource: stamps, frames, raw, merging."""

from __future__ import annotations

import re
import shutil
import threading
from pathlib import Path

import numpy as np
import pytest
from source_data import FORMATS, PERIOD, ROS1, ROS2, T0, Cam, pixels, regular

from speechcal_core.sources import FrameSource, StreamChoice, open_recording
from speechcal_core.sources.base import COMPRESSED_MSGTYPE, IMAGE_MSGTYPE
from speechcal_core.sources.errors import SourceError


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_bag_format_gives_stamps_frames_and_raw(make_bag, fmt: str) -> None:
    path = make_bag(fmt)
    with open_recording([path]) as src:
        assert isinstance(src, FrameSource)
        info = {s.name: s for s in src.streams}
        assert set(info) == {"/cam0/image_raw", "/cam1/image_raw"}
        cam0, cam1 = info["/cam0/image_raw"], info["/cam1/image_raw"]
        assert (cam0.msgtype, cam0.encoding) == (IMAGE_MSGTYPE, "bgr8")
        assert (cam0.width, cam0.height) == (16, 12)
        assert (cam1.msgtype, cam1.encoding) == (COMPRESSED_MSGTYPE, "jpeg")
        assert cam0.count == 20 and cam0.first_ns == T0 and cam0.last_ns == T0 + 19 * PERIOD
        assert cam0.median_period_ns == PERIOD and cam0.nominal_rate_hz == 20.0
        assert cam0.dropped == 0 and cam0.bad_frames == () and cam0.stamp_problems == ""
        stamps = src.stamps("/cam0/image_raw")
        assert stamps.dtype == np.int64 and list(stamps) == regular()
        np.testing.assert_array_equal(src.frame("/cam0/image_raw", 7), pixels(0, 7))
        jpeg = src.frame("/cam1/image_raw", 3)
        assert jpeg.shape == (12, 16, 3) and jpeg.dtype == np.uint8
        assert np.abs(jpeg[6, 8].astype(int) - pixels(1, 3)[6, 8]).max() < 12
        assert src.nearest("/cam1/image_raw", T0 + 7_000_000 + 2 * PERIOD + 1) == 2
        raw = src.raw("/cam0/image_raw", 4)
        assert raw.stamp_ns == T0 + 4 * PERIOD
        assert raw.log_time_ns == T0 + 4 * PERIOD + 3_000_000
        ros1 = fmt.startswith("ros1")
        assert raw.serialization == ("ros1" if ros1 else "cdr")
        ts = ROS1 if ros1 else ROS2
        des = ts.deserialize_ros1 if ros1 else ts.deserialize_cdr
        msg = des(raw.rawdata, "sensor_msgs/msg/Image")
        assert msg.encoding == "bgr8" and msg.header.frame_id == "cam0"
        assert raw.connection["msgdef"]
        if ros1:
            assert raw.connection["md5sum"] == "060021388200f6f0f447d0fcd9c64743"


@pytest.mark.parametrize("fmt", ["ros2-sqlite3", "ros2-mcap"])
def test_bare_ros2_storage_file_opens_without_its_folder(make_bag, fmt: str) -> None:
    folder = make_bag(fmt)
    (storage,) = [p for p in folder.iterdir() if p.suffix in (".db3", ".mcap")]
    with open_recording([storage]) as src:
        assert [s.count for s in src.streams] == [20, 20]


def test_a_recording_named_twice_is_read_once(make_bag) -> None:
    """A shell glob and a name together: the same bag twice, or a ROS2 folder with its own
    storage file, give each frame once."""
    bag = make_bag("ros1")
    folder = make_bag("ros2-sqlite3", name="r2")
    (storage,) = folder.glob("*.db3")
    for paths in ([bag, bag.parent / ".." / bag.parent.name / bag.name], [folder, storage],
                  [storage, folder]):
        with open_recording(paths) as src:
            assert [s.count for s in src.streams] == [20, 20], paths
            assert all(s.stamp_problems == "" for s in src.streams), paths


def test_a_copy_of_a_bag_given_beside_it_is_refused_naming_both(make_bag) -> None:
    """``*.bag`` caught a backup beside the recording: numpy's "truth value of an array
    is ambiguous" came out as the error; now both files are named."""
    bag = make_bag("ros1")
    copy = bag.with_name("recording.orig.bag")
    shutil.copyfile(bag, copy)
    with pytest.raises(SourceError, match=(
            rf"^{re.escape(str(copy))}: holds the same /cam0/image_raw frames as "
            rf"{re.escape(str(bag))} \(a copy of it\?\); give only one of them$")):
        open_recording([bag, copy])


def test_one_camera_recorded_raw_and_compressed_gets_a_note(make_bag) -> None:
    """Both topics are taken as cameras (a calibration of the pair fails), so it is said;
    hardware-triggered cameras share stamps under names of their own and get none."""
    bag = make_bag("ros1", [Cam("/cam0/image_raw", regular(10), index=0),
                            Cam("/cam0/image_raw/compressed", regular(10), "jpeg", index=0),
                            Cam("/cam1/image_raw", regular(10), index=1)])
    with open_recording([bag]) as src:
        assert [s.name for s in src.streams] == [
            "/cam0/image_raw", "/cam0/image_raw/compressed", "/cam1/image_raw"]
        assert src.notes == [
            "/cam0/image_raw/compressed has the same header stamps as /cam0/image_raw, frame "
            "for frame: one camera recorded twice (raw and compressed?) is taken as two "
            "cameras in one place; a calibration of both fails or is meaningless: leave "
            "one out (speechcal process or review ... --skip-stream "
            "/cam0/image_raw/compressed, or the review window's Edit ▸ Leave a camera out…)"]


def test_streams_left_out_are_as_if_not_recorded_and_take_their_note_along(make_bag) -> None:
    bag = make_bag("ros1", [Cam("/cam0/image_raw", regular(10), index=0),
                            Cam("/cam0/image_raw/compressed", regular(10), "jpeg", index=0),
                            Cam("/cam1/image_raw", regular(10), index=1)])
    skip = StreamChoice(skip=("/cam0/image_raw/compressed",))
    with open_recording([bag], streams=skip) as src:
        assert [s.name for s in src.streams] == ["/cam0/image_raw", "/cam1/image_raw"]
        assert src.notes == []
        assert src.frame("/cam1/image_raw", 3).shape == (12, 16, 3)
        with pytest.raises(SourceError, match="'/cam0/image_raw/compressed' is left out"):
            src.stamps("/cam0/image_raw/compressed")
    # a topic typed without its leading "/" (or with a trailing one) is found too
    with open_recording([bag], streams=StreamChoice(only=("cam1/image_raw/",))) as src:
        assert [s.name for s in src.streams] == ["/cam1/image_raw"]
    with pytest.raises(SourceError, match=re.escape(
            "no stream '/cam9' in this recording (streams: /cam0/image_raw, "
            "/cam0/image_raw/compressed, /cam1/image_raw); `speechcal index RECORDING` "
            "lists them")):
        open_recording([bag], streams=StreamChoice(skip=("/cam9",)))
    with pytest.raises(SourceError, match="no stream left"):
        open_recording([bag], streams=StreamChoice(only=("/cam1/image_raw",),
                                                    skip=("/cam1/image_raw",)))


def test_split_bags_and_two_pcs_merge_by_topic(make_bag) -> None:
    first = make_bag("ros1", [Cam("/cam0/image_raw", regular(10), index=0)], name="a")
    second = make_bag(
        "ros1-lz4", [Cam("/cam0/image_raw", regular(10, start=T0 + 10 * PERIOD), index=0)], name="b"
    )
    other_pc = make_bag("ros2-sqlite3", [Cam("/cam1/image_raw", regular(20), index=1)], name="c")
    with open_recording([second, first, other_pc]) as src:
        info = {s.name: s for s in src.streams}
        assert info["/cam0/image_raw"].count == 20
        assert info["/cam0/image_raw"].stamp_problems == ""
        assert list(src.stamps("/cam0/image_raw")) == regular(20)
        # frame 15 is frame 5 of the second file
        np.testing.assert_array_equal(src.frame("/cam0/image_raw", 15), pixels(0, 5))
        np.testing.assert_array_equal(src.frame("/cam1/image_raw", 15), pixels(1, 15))
        assert src.raw("/cam1/image_raw", 0).serialization == "cdr"


def test_ros2_folder_with_several_storage_files_is_one_recording(make_bag) -> None:
    first = make_bag("ros2-sqlite3", [Cam("/cam0/image_raw", regular(10))], name="split")
    second = make_bag(
        "ros2-sqlite3", [Cam("/cam0/image_raw", regular(10, start=T0 + 10 * PERIOD))], name="b"
    )
    (db3,) = second.glob("*.db3")
    db3.rename(first / "split_1.db3")
    with open_recording([first]) as src:
        assert list(src.stamps("/cam0/image_raw")) == regular(20)
        assert src.notes == []
    # one part alone opens, but says that it is part of a larger recording
    with open_recording([first / "split_1.db3"]) as src:
        assert list(src.stamps("/cam0/image_raw")) == regular(20)[10:]
        (note,) = src.notes
        assert note == (f"{first}: part 2 of the 2 files of this split ROS2 bag given, so "
                        f"only part of the recording is read; give the folder {first} for "
                        "all of it")
    with open_recording(sorted(first.glob("*.db3"))) as src:
        assert src.notes == []


@pytest.mark.parametrize("fmt", ["ros2-sqlite3", "ros2-mcap"])
def test_a_ros2_folder_missing_a_part_its_metadata_lists_says_so(make_bag, fmt: str) -> None:
    """A split bag copied without one of its parts read as a shorter recording, without
    a word."""
    folder = make_bag(fmt, [Cam("/cam0/image_raw", regular(10))], name="split")
    (part,) = [p.name for p in folder.iterdir() if p.suffix in (".db3", ".mcap")]
    meta = folder / "metadata.yaml"
    text = meta.read_text()
    assert text.count(f"- {part}") == 1  # as rosbags writes it, block style
    meta.write_text(text.replace(f"- {part}", f"- {part}\n  - split_1{Path(part).suffix}"))
    with open_recording([folder]) as src:
        assert list(src.stamps("/cam0/image_raw")) == regular(10)
        assert src.notes == [
            f"{folder}: its metadata.yaml lists split_1{Path(part).suffix}, not in the "
            "folder: that part of the recording is missing (a split bag copied in part?); "
            "copy the bag folder again whole"]


@pytest.mark.parametrize("fmt", ["ros1", "ros1-lz4", "ros1-bz2"])
def test_many_small_chunks_are_indexed_in_file_order(make_bag, fmt: str) -> None:
    cams = [Cam(f"/cam{k}/image_raw", regular(30), index=k) for k in range(2)]
    cams.append(Cam("/cam2/image_raw", regular(30), index=2, encoding="png"))
    path = make_bag(fmt, cams, imu=True, chunk_bytes=1500)  # about one message per chunk
    with open_recording([path]) as src:
        assert [s.count for s in src.streams] == [30, 30, 30]
        assert all(s.stamp_problems == "" for s in src.streams)
        for k in range(3):
            assert list(src.stamps(f"/cam{k}/image_raw")) == regular(30)
        for i in (0, 17, 29):
            np.testing.assert_array_equal(src.frame("/cam1/image_raw", i), pixels(1, i))
            np.testing.assert_array_equal(src.frame("/cam2/image_raw", i), pixels(2, i))


def test_zstd_mcap_chunks_are_indexed_from_their_heads(make_bag, monkeypatch) -> None:
    import speechcal_core.sources.mcap as mcap_module

    full: list[int] = []
    real = mcap_module.decompress
    monkeypatch.setattr(mcap_module, "decompress", lambda *a: full.append(1) or real(*a))
    cams = [Cam(f"/cam{k}/image_raw", regular(40), width=160, height=120, index=k) for k in (0, 1)]
    with open_recording([make_bag("ros2-mcap-zstd", cams)]) as src:
        assert not full  # message heads came from partial decompression
        assert [s.count for s in src.streams] == [40, 40]
        assert list(src.stamps("/cam1/image_raw")) == regular(40)
        np.testing.assert_array_equal(src.frame("/cam1/image_raw", 39), pixels(1, 39, 160, 120))


def test_dropped_frames_are_counted_from_gaps(make_bag) -> None:
    stamps = [s for k, s in enumerate(regular(30)) if k not in (5, 6, 20)]
    with open_recording([make_bag("ros1", [Cam("/cam0/image_raw", stamps)])]) as src:
        (info,) = src.streams
        assert info.count == 27 and info.dropped == 3 and info.median_period_ns == PERIOD


@pytest.mark.parametrize("fmt", ["ros1", "ros2-mcap"])
def test_a_frame_with_an_unset_header_stamp_is_left_out(make_bag, fmt: str) -> None:
    """A camera driver's first frame stamped 0 put the stream's start in 1970: the clap
    search (its first 20 s) found nothing, and the gap counted as dropped frames."""
    stamps = [0, *regular(19, start=T0 + PERIOD)]
    with open_recording([make_bag(fmt, [Cam("/cam0/image_raw", stamps)])]) as src:
        (info,) = src.streams
        assert info.count == 19 and info.first_ns == T0 + PERIOD and info.dropped == 0
        assert "1 frame with a zero or negative header stamp left out" in info.stamp_problems
        assert list(src.stamps("/cam0/image_raw")) == stamps[1:]
        np.testing.assert_array_equal(src.frame("/cam0/image_raw", 0), pixels(0, 1))


def test_index_is_cached_beside_the_recording_and_reused(make_bag, monkeypatch) -> None:
    path = make_bag("ros1")
    with open_recording([path]) as src:
        first = src.streams
    assert (path.parent / f".{path.name}.speechcal-index.npz").is_file()

    from speechcal_core.sources.rosbag1 import Ros1Bag

    def fail(self: Ros1Bag) -> None:
        raise AssertionError("index rebuilt although cached")

    monkeypatch.setattr(Ros1Bag, "scan", fail)
    with open_recording([path]) as src:
        assert src.streams == first
        np.testing.assert_array_equal(src.frame("/cam0/image_raw", 2), pixels(0, 2))
    with pytest.raises(AssertionError, match="rebuilt"):
        open_recording([path], use_cache=False)


def test_changed_recording_invalidates_the_cache(make_bag, tmp_path: Path) -> None:
    path = make_bag("ros1", [Cam("/cam0/image_raw", regular(5))], name="x")
    with open_recording([path]) as src:
        assert src.streams[0].count == 5
    path.unlink()
    make_bag("ros1", [Cam("/cam0/image_raw", regular(8))], name="x")
    with open_recording([path]) as src:
        assert src.streams[0].count == 8


def test_cache_falls_back_to_user_cache_dir(make_bag, tmp_path: Path, monkeypatch) -> None:
    path = make_bag("ros1")
    # the cache name beside the bag is taken by a folder, so writing there fails
    (path.parent / f".{path.name}.speechcal-index.npz").mkdir()
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    with open_recording([path]) as src:
        assert src.streams[0].count == 20
    cached = list((tmp_path / "xdg" / "speechcal" / "index").glob(f"{path.name}.*.npz"))
    assert len(cached) == 1


@pytest.mark.parametrize("fmt", ["ros1-lz4", "ros2-sqlite3", "ros2-mcap-zstd"])
def test_concurrent_frame_reads_are_consistent(make_bag, fmt: str) -> None:
    path = make_bag(fmt, [Cam(f"/cam{k}/image_raw", regular(), index=k) for k in range(3)])
    errors: list[BaseException] = []
    with open_recording([path]) as src:

        def work(seed: int) -> None:
            rng = np.random.default_rng(seed)
            try:
                for _ in range(60):
                    cam, i = int(rng.integers(3)), int(rng.integers(20))
                    img = src.frame(f"/cam{cam}/image_raw", i)
                    np.testing.assert_array_equal(img, pixels(cam, i))
            except BaseException as exc:
                errors.append(exc)

        threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    assert not errors, errors[0]


def test_padded_rows_are_honoured_in_a_bag(make_bag) -> None:
    cam = Cam("/cam0/image_raw", regular(3), step_pad=5)
    with open_recording([make_bag("ros2-mcap", [cam])]) as src:
        np.testing.assert_array_equal(src.frame("/cam0/image_raw", 1), pixels(0, 1))


def test_cameras_are_listed_as_an_operator_counts_them(make_bag) -> None:
    """cam2 before cam10, in one bag and across two PCs' bags: the grid, the calibration
    check and the Kalibr export's cam0, cam1... follow this order."""
    names = ["/cam10/image_raw", "/cam2/image_raw", "/cam1/image_raw"]
    bag = make_bag("ros1", [Cam(n, regular(3), index=k) for k, n in enumerate(names)])
    other_pc = make_bag("ros2-sqlite3", [Cam("/cam9/image_raw", regular(3), index=3)],
                        name="pc2")
    expected = ["/cam1/image_raw", "/cam2/image_raw", "/cam9/image_raw", "/cam10/image_raw"]
    with open_recording([bag, other_pc]) as src:
        assert [s.name for s in src.streams] == expected
    with open_recording([bag]) as src:
        assert [s.name for s in src.streams] == [n for n in expected if n != "/cam9/image_raw"]


def test_stream_order_counts_numbers_and_keeps_distinct_names_apart() -> None:
    from speechcal_core.sources.base import stream_order

    names = ["cam10", "Cam2", "cam2", "cam1_left", "cam1", "fisheye0"]
    assert sorted(names, key=stream_order) == [
        "cam1", "cam1_left", "Cam2", "cam2", "cam10", "fisheye0"]
