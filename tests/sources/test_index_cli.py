"""``speechcal index``: JSON document, table, --no-cache, --scan and exit codes."""

from __future__ import annotations

import json
import os

from source_data import PERIOD, T0
from test_files import write_video

from speechcal_core.cli import main
from speechcal_core.sources.rosbag1 import Ros1Bag


def test_index_json_lists_streams_with_design_keys(make_bag, capsys) -> None:
    path = make_bag("ros1")
    assert main(["index", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    streams = {s["name"]: s for s in doc["streams"]}
    cam0 = streams["/cam0/image_raw"]
    for key in ("name", "encoding", "width", "height", "count", "first_ns", "last_ns", "dropped"):
        assert key in cam0
    assert (cam0["encoding"], cam0["width"], cam0["height"], cam0["count"]) == ("bgr8", 16, 12, 20)
    assert cam0["first_ns"] == T0 and cam0["median_period_ns"] == PERIOD
    assert streams["/cam1/image_raw"]["encoding"] == "jpeg"


def test_index_table_and_no_cache(make_bag, capsys) -> None:
    path = make_bag("ros2-sqlite3")
    assert main(["index", str(path), "--no-cache"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].split()[:3] == ["stream", "encoding", "size"]
    assert "/cam0/image_raw" in out and "16x12" in out


def test_index_table_shows_a_stamp_before_1970_as_the_json_has_it(tmp_path, capsys) -> None:
    """A video given a negative --video-start-ns: -5 ns was shown as -1.999999995 s."""
    video = write_video(tmp_path / "cam0.mp4", n=5)
    assert main(["index", str(video), "--video-start-ns", "-5"]) == 0
    row = capsys.readouterr().out.splitlines()[1].split()
    assert row[-2:] == ["-0.000000005", f"0.{4 * 50_000_000 - 5:09d}"]


def test_index_bad_input_exits_1_with_one_line_reason(make_bag, capsys) -> None:
    path = make_bag("ros1")
    bag = Ros1Bag(path)
    index_pos = bag.index_pos
    bag.close()
    os.truncate(path, index_pos)
    assert main(["index", str(path), "--json"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip()
    assert len(err.splitlines()) == 1 and "rosbag reindex" in err
    assert main(["index", str(path), "--json", "--scan"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert [s["count"] for s in doc["streams"]] == [20, 20]
    assert any("recovered by scanning" in n for n in doc["notes"])
