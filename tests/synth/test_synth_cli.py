"""``speechcal synth`` end to end: files read back with plain rosbags and soundfile."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from rosbags.highlevel import AnyReader

from speechcal_core.cli import main

SMALL = ["--cameras", "2", "--duration", "9", "--size", "192x144", "--seed", "11"]


def _synth(tmp_path: Path, *extra: str) -> tuple[Path, dict]:
    out = tmp_path / "session"
    assert main(["synth", str(out), *SMALL, *extra]) == 0
    return out, json.loads((out / "truth.json").read_text())


def _header_stamps(recording: Path) -> dict[str, list[int]]:
    stamps: dict[str, list[int]] = {}
    with AnyReader([recording]) as reader:
        for conn, _t, raw in reader.messages():
            msg = reader.deserialize(raw, conn.msgtype)
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            stamps.setdefault(conn.topic, []).append(stamp)
    return stamps


@pytest.mark.parametrize("fmt", ["ros1", "ros2-sqlite3", "ros2-mcap"])
def test_recording_reads_back_with_plain_rosbags_and_agrees_with_truth(
    tmp_path: Path, fmt: str
) -> None:
    out, truth = _synth(tmp_path, "--format", fmt)
    assert truth["format"] == fmt
    stamps = _header_stamps(out / truth["recording"])
    assert sorted(stamps) == sorted(c["name"] for c in truth["cameras"])
    for cam in truth["cameras"]:
        got = np.array(sorted(stamps[cam["name"]]))
        assert len(got) == cam["count"]
        expected = (truth["end_ns"] - truth["start_ns"]) / 1e9 * cam["fps"]
        assert cam["count"] + cam["dropped"] == pytest.approx(expected, abs=2)
        assert truth["start_ns"] - 20e6 < got[0] and got[-1] < truth["end_ns"] + 20e6


def test_the_boards_target_yaml_is_written_for_process(tmp_path: Path) -> None:
    """``process --target OUT/target.yaml`` checks the frames against the board shown."""
    from speechcal_core.target import TargetSpec

    out, truth = _synth(tmp_path, "--target", "checkerboard")
    target = TargetSpec.from_kalibr_yaml(out / "target.yaml")
    assert target == TargetSpec(**truth["target"])
    assert target.kind == "checkerboard"


def test_audio_reads_back_and_claps_and_triggers_agree_with_the_sync_model(
    tmp_path: Path,
) -> None:
    out, truth = _synth(tmp_path, "--claps", "2", "--drift-ppm", "30", "--duration", "14")
    info = sf.info(str(out / truth["audio"]))
    assert (info.samplerate, info.channels) == (48000, 1)
    offset, drift = truth["sync"]["offset_ns"], truth["sync"]["drift"]
    assert drift == pytest.approx(30e-6)

    def to_session(t_s: float) -> float:
        return offset + t_s * (1 + drift) * 1e9

    assert len(truth["claps"]) == 2
    for clap in truth["claps"]:
        assert to_session(clap["audio_s"]) == pytest.approx(clap["session_ns"], abs=1e5)
        assert 0 < clap["audio_s"] < info.duration
    assert truth["triggers"]
    samples, rate = sf.read(str(out / truth["audio"]), dtype="float32")
    for trig in truth["triggers"]:
        mid = (trig["start_s"] + trig["end_s"]) / 2
        assert to_session(mid) == pytest.approx(trig["session_ns"], abs=1e3)
        hold = trig["hold"]
        assert hold[0] - 0.35e9 <= trig["session_ns"] <= hold[1]
        word = samples[int(trig["start_s"] * rate): int(trig["end_s"] * rate)]
        assert np.sqrt(np.mean(word**2)) > 3 * np.median(np.abs(samples))


def test_same_seed_writes_the_same_truth(tmp_path: Path) -> None:
    _, a = _synth(tmp_path / "a")
    _, b = _synth(tmp_path / "b")
    assert a == b


def _run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "speechcal_core.cli", *args],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["--cameras", "0"], 2, "--cameras must be between 1 and 12"),
        (["--format", "avi"], 2, "unknown --format 'avi'"),
        (["--encoding", "yuv9"], 2, "unknown --encoding 'yuv9'"),
        (["--trigger-word", "banana"], 2, "banana"),
        (["--seed", "-1"], 2, "--seed must be 0 or more, got -1"),  # was a numpy traceback
    ],
)
def test_bad_options_give_one_line_usage_errors(
    tmp_path: Path, args: list[str], code: int, message: str
) -> None:
    result = _run_cli("synth", str(tmp_path / "out"), *args)
    assert result.returncode == code
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0]
    assert not (tmp_path / "out").exists()


def test_existing_output_is_kept_without_force(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    result = _run_cli("synth", str(out), *SMALL)
    assert result.returncode == 1
    assert "holds files that are not a synthetic session (notes.txt)" in result.stderr
    assert "choose another folder" in result.stderr
    assert (out / "notes.txt").read_text() == "mine"


def test_force_replaces_an_earlier_synthetic_session_and_nothing_else(tmp_path) -> None:
    """--force emptied any folder it was given (the current one with ``synth .``); it
    replaces only an earlier synthetic session, never files synth did not write."""
    out, _truth = _synth(tmp_path)
    assert main(["index", str(out / "recording.bag")]) == 0  # an index beside it: regenerable
    assert any(p.name.endswith(".speechcal-index.npz") for p in out.iterdir())
    assert main(["synth", str(out), *SMALL, "--force"]) == 0
    assert main(["synth", str(out), *SMALL]) == 1  # without --force: kept
    (out / "recording.speechcal.json").write_text("{}")  # review work saved beside it
    result = _run_cli("synth", str(out), *SMALL, "--force")
    assert result.returncode == 1
    assert "also holds files synth did not write (recording.speechcal.json" in result.stderr
    assert (out / "recording.speechcal.json").read_text() == "{}"
    mine = tmp_path / "notes.txt"
    mine.write_text("mine")
    result = _run_cli("synth", str(mine), *SMALL, "--force")
    assert result.returncode == 1 and "this is a file" in result.stderr
    assert mine.read_text() == "mine"


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_unwritable_output_is_a_one_line_error(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    result = _run_cli("synth", str(locked / "out"), *SMALL)
    assert result.returncode == 1
    assert "cannot write there" in result.stderr.strip().splitlines()[-1]


def test_output_under_a_file_is_a_one_line_error(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = _run_cli("synth", str(blocker / "out"), *SMALL)
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot write there" in lines[0]


def test_a_session_too_short_for_a_trigger_says_so(tmp_path: Path) -> None:
    result = _run_cli("synth", str(tmp_path / "out"), "--cameras", "1", "--duration", "5",
                      "--size", "96x72")
    assert result.returncode == 0
    assert "0 triggers" in result.stderr
    assert "note: --duration 5 s leaves no time for a trigger" in result.stderr


def test_a_session_asked_for_no_trigger_notes_nothing(tmp_path: Path) -> None:
    """--triggers 0 (a recording to test the clap on) said the duration left no time."""
    result = _run_cli("synth", str(tmp_path / "out"), "--cameras", "1", "--duration", "8",
                      "--size", "96x72", "--triggers", "0")
    assert result.returncode == 0
    assert "0 triggers" in result.stderr and "note:" not in result.stderr
