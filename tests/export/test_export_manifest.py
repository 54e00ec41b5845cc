"""manifest.json and manifest.csv agree with the session and with the files written."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from speechcal_core.export import export_session_file
from speechcal_core.session.store import load_session


@pytest.mark.parametrize("fmt", ["kalibr", "folders", "rosbag1", "rosbag2"])
def test_manifest_json_and_csv_describe_the_exported_sets(session_file, tmp_path, fmt) -> None:
    path = session_file()
    out = tmp_path / "out"
    export_session_file(path, fmt, out)
    doc = json.loads((out / "manifest.json").read_text())
    rows = list(csv.DictReader((out / "manifest.csv").open(newline="")))
    accepted = [s for s in load_session(path).sets if s.decision == "accepted"]
    assert doc["format"] == fmt and doc["session"] == str(path.absolute())
    assert [s["id"] for s in doc["sets"]] == [s.id for s in accepted]
    assert len(rows) == sum(len(s["frames"]) for s in doc["sets"]) == 6
    for entry, s in zip(doc["sets"], accepted, strict=True):
        assert (entry["word"], entry["start_s"], entry["end_s"], entry["t_ns"],
                entry["decision"], entry["skew_ns"]) == (
            s.trigger.word, round(s.trigger.start_s, 6), round(s.trigger.end_s, 6), s.t_ns,
            "accepted", s.skew_ns)
        for f, choice in zip(entry["frames"], s.frames, strict=True):
            assert (f["stream"], f["index"], f["stamp_ns"], f["sharpness"], f["corners"],
                    f["flags"]) == (choice.stream, choice.index, choice.stamp_ns,
                                    choice.sharpness, choice.corners, list(choice.flags))
            assert (out / f["file"]).exists()
            if fmt in ("kalibr", "folders"):
                assert f["file"] == f"{f['file'].split('/')[0]}/{s.t_ns}.png"
            row = next(r for r in rows if int(r["set_id"]) == s.id and r["stream"] == f["stream"])
            assert (int(row["stamp_ns"]), float(row["sharpness"]), int(row["corners"]),
                    row["file"], row["word"], int(row["t_ns"])) == (
                f["stamp_ns"], f["sharpness"], f["corners"], f["file"], s.trigger.word, s.t_ns)
            assert row["flags"] == ";".join(f["flags"])
            assert (row["start_s"], row["end_s"]) == (str(entry["start_s"]), str(entry["end_s"]))
            assert max(len(row["start_s"]), len(row["end_s"])) <= 12  # no float noise
    cameras = {c["stream"]: c["camera"] for c in doc["cameras"]}
    expected = {"kalibr": {"/cam0/image_raw": "cam0", "/cam1/image_raw": "cam1"},
                "folders": {"/cam0/image_raw": "cam0_image_raw",
                            "/cam1/image_raw": "cam1_image_raw"}}.get(
        fmt, {"/cam0/image_raw": "/cam0/image_raw", "/cam1/image_raw": "/cam1/image_raw"})
    assert cameras == expected


def test_kalibr_manifest_says_where_the_target_came_from(session_file, tmp_path: Path) -> None:
    out = tmp_path / "out"
    export_session_file(session_file(), "kalibr", out)
    target = json.loads((out / "manifest.json").read_text())["target"]
    assert target == {"kind": "aprilgrid", "rows": 6, "cols": 6, "size": 0.055,
                      "spacing": 0.3, "from": "default"}
