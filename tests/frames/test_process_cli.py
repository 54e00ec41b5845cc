"""Frame processing end to end on a small synthetic bag, scored against its truth."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.cli import main
from speechcal_core.frames.analysis import analyse_frames
from speechcal_core.review.loading import load_for_review
from speechcal_core.session.model import Trigger
from speechcal_core.sources import open_recording
from speechcal_core.sync.model import SyncModel
from speechcal_core.target import TargetSpec


@pytest.fixture(scope="module")
def synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("process") / "synth"
    # a fresh process: the generator forks render workers, unsafe once threads have run here
    subprocess.run([sys.executable, "-m", "speechcal_core.cli", "synth", str(out),
                    "--cameras", "2", "--duration", "30", "--seed", "21", "--triggers", "8"],
                   check=True, capture_output=True, timeout=300)
    return out, json.loads((out / "truth.json").read_text())


def _hold_of(truth: dict, start_s: float, end_s: float) -> list[int] | None:
    mid = (start_s + end_s) / 2
    for t in truth["triggers"]:
        if abs((t["start_s"] + t["end_s"]) / 2 - mid) < 0.3:
            return t["hold"]
    return None


@pytest.mark.slow
def test_frames_of_a_bag_lie_in_holds_and_calibrate_within_one_percent(synth) -> None:
    out, truth = synth
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"])
    triggers = [Trigger(t["word"], t["start_s"], t["end_s"]) for t in truth["triggers"]]
    with open_recording([out / truth["recording"]]) as source:
        analysis = analyse_frames(source, sync, triggers, TargetSpec(),
                                  models=("pinhole",))
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    for s in analysis.sets:
        hold = _hold_of(truth, s.trigger.start_s, s.trigger.end_s)
        for f in s.frames:
            assert hold[0] <= f.stamp_ns - offsets[f.stream] <= hold[1]
            assert not f.flags
    for cam in truth["cameras"]:
        entry = analysis.calibration[cam["name"]]
        found, want = np.asarray(entry["intrinsics"][:4]), np.asarray(cam["intrinsics"])
        assert (np.abs(found - want) / want).max() < 0.01
        assert entry["rms_px"] < 0.5


@pytest.mark.slow
def test_process_command_writes_the_session_with_progress_on_stderr(synth, tmp_path: Path,
                                                                    capsys) -> None:
    out, truth = synth
    session_path = tmp_path / "session.json"
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "--offset-ns", str(truth["sync"]["offset_ns"]), "-o", str(session_path)])
    assert code == 0
    captured = capsys.readouterr()
    assert captured.out == "" and "choosing frames" in captured.err
    assert re.search(r"\d+ frame sets \(\d+ flagged\); calibration check over \d+ sets not "
                     r"rejected: 2 of 2 cameras fit", captured.err)
    doc = json.loads(session_path.read_text())
    assert {"sets", "calibration", "frame_details", "coverage"} <= set(doc)
    assert doc["target"] == asdict(TargetSpec())  # what export describes to Kalibr
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    for s in doc["sets"]:
        hold = _hold_of(truth, s["trigger"]["start_s"], s["trigger"]["end_s"])
        if hold is None:
            continue  # a word the truth does not know: nothing to score
        for f in s["frames"]:
            assert hold[0] <= f["stamp_ns"] - offsets[f["stream"]] <= hold[1]
        assert s["frames"][0]["corners"] > 0
    # a session file is what --force replaces, keeping the old one as .bak
    assert main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "-o", str(session_path), "--force"]) == 0
    assert f"the file it replaced is kept as {session_path}.bak" in capsys.readouterr().err
    assert json.loads(session_path.with_name("session.json.bak").read_text()) == doc


@pytest.mark.slow
def test_a_stream_left_out_stays_out_of_the_session_its_review_and_its_export(
        synth, tmp_path: Path, capsys) -> None:
    out, truth = synth
    session_path = tmp_path / "one.json"
    assert main(["process", str(out / truth["recording"]), str(out / "audio.ogg"),
                 "--offset-ns", str(truth["sync"]["offset_ns"]),
                 "--skip-stream", "/cam1/image_raw", "-o", str(session_path), "--json"]) == 0
    doc = json.loads(session_path.read_text())
    assert doc["streams"] == ["/cam0/image_raw"]
    assert json.loads(capsys.readouterr().out)["streams"] == ["/cam0/image_raw"]
    assert {f["stream"] for s in doc["sets"] for f in s["frames"]} == {"/cam0/image_raw"}
    assert set(doc["calibration"]) == {"/cam0/image_raw"}
    inputs = load_for_review(session_path=session_path)
    try:
        assert [s.name for s in inputs.source.streams] == ["/cam0/image_raw"]
    finally:
        inputs.close()
    exported = tmp_path / "folders"
    assert main(["export", str(session_path), "--format", "folders", "--out", str(exported),
                 "--include-undecided"]) == 0
    assert len([p for p in exported.iterdir() if p.is_dir()]) == 1
    capsys.readouterr()
    assert main(["process", str(out / truth["recording"]), str(out / "audio.ogg"),
                 "--stream", "/cam9/image_raw", "-o", str(tmp_path / "none.json")]) == 1
    assert ("no stream '/cam9/image_raw' in this recording (streams: /cam0/image_raw, "
            "/cam1/image_raw)") in capsys.readouterr().err


def test_process_refuses_an_output_folder_that_does_not_exist_before_any_work(
        synth, tmp_path: Path, capsys) -> None:
    out, truth = synth
    target = tmp_path / "no" / "such" / "session.json"
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "-o", str(target)])
    err = capsys.readouterr().err
    assert code == 1
    assert f"the folder {target.parent} does not exist" in err
    assert "indexing" not in err and "%]" not in err  # no progress: nothing was started


@pytest.mark.parametrize("which", ["recording", "audio"])
def test_process_never_writes_the_session_over_its_own_inputs_even_with_force(
        synth, capsys, which: str) -> None:
    out, truth = synth
    recording, audio = out / truth["recording"], out / "audio.ogg"
    victim = recording if which == "recording" else audio
    before = victim.stat()
    code = main(["process", str(recording), "--audio", str(audio), "-o", str(victim),
                 "--force"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1
    assert f"{victim} is the {which} this reads" in err and "%]" not in err
    after = victim.stat()
    assert (after.st_size, after.st_mtime_ns) == (before.st_size, before.st_mtime_ns)
    assert not victim.with_name(victim.name + ".bak").exists()


def test_process_takes_the_audio_among_the_inputs_as_review_does(synth, capsys) -> None:
    out, truth = synth
    recording, audio = out / truth["recording"], out / "audio.ogg"
    # -o onto the audio shows it was taken as the audio, and stops before any work
    assert main(["process", str(recording), str(audio), "-o", str(audio), "--force"]) == 1
    assert f"{audio} is the audio this reads" in capsys.readouterr().err
    assert main(["process", str(audio), "-o", "s.json"]) == 2
    assert (f"{audio} is an audio file: give the recording too (speechcal process "
            f"RECORDING --audio {audio})") in capsys.readouterr().err
    assert main(["process", str(recording), "-o", "s.json"]) == 2
    assert "a recording needs its audio: add --audio AUDIO" in capsys.readouterr().err
    other = out / "other.wav"
    assert main(["process", str(recording), str(audio), "--audio", str(other),
                 "-o", "s.json"]) == 2
    assert (f"two audio files given, {audio} and --audio {other}: give only the "
            "microphone's") in capsys.readouterr().err


def test_an_aiff_or_m4a_among_the_inputs_is_taken_for_the_audio(synth, tmp_path: Path,
                                                                capsys) -> None:
    """``process recording.bag mic.aiff`` said "a recording needs its audio: add --audio"
    (and the window took no drop of the two): only five endings counted as audio."""
    out, truth = synth
    recording = out / truth["recording"]
    samples, rate = sf.read(out / "audio.ogg", dtype="float32")
    aiff = tmp_path / "mic.aiff"
    sf.write(aiff, samples, rate)
    # -o onto the audio shows it was taken as the audio, and stops before any work
    assert main(["process", str(recording), str(aiff), "-o", str(aiff), "--force"]) == 1
    assert f"{aiff} is the audio this reads" in capsys.readouterr().err
    m4a = tmp_path / "mic.m4a"
    m4a.write_bytes(b"\x00\x00\x00\x20ftypM4A \x00\x00\x00\x00M4A mp42isom" + bytes(4000))
    assert main(["process", str(recording), str(m4a), "-o", str(tmp_path / "s.json")]) == 1
    err = capsys.readouterr().err
    assert f"{m4a}: M4A audio is not read; convert it to WAV or FLAC first" in err
    assert not (tmp_path / "s.json").exists()


def test_process_output_that_is_a_folder_names_a_file_to_give_before_any_work(
        synth, tmp_path: Path, capsys) -> None:
    out, truth = synth
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "-o", str(tmp_path), "--force"])
    err = capsys.readouterr().err
    assert code == 1 and f"{tmp_path} is a folder" in err
    assert f"-o {tmp_path / 'session.json'}" in err and "%]" not in err


def test_process_with_an_offset_far_off_says_the_sets_have_no_frames(
        synth, tmp_path: Path, capsys) -> None:
    out, truth = synth

    # the audio's last 3 s on the recording's start: every word lies before its first frame
    early = truth["sync"]["offset_ns"] - round((sf.info(out / "audio.ogg").duration - 3) * 1e9)
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "--offset-ns", str(early), "-o", str(tmp_path / "session.json")])
    err = capsys.readouterr().err
    assert code == 0
    assert "have no frame in any camera at the trigger time: check the offset" in err
    assert "note: trigger words said outside the recording: " in err
    assert " before its first frame (" in err


@pytest.mark.slow
def test_process_takes_the_pronunciation_of_a_word_missing_from_the_dictionary(
        synth, tmp_path: Path, capsys) -> None:
    out, truth = synth
    args = ["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
            "--offset-ns", str(truth["sync"]["offset_ns"]), "--trigger", "kaptchur",
            "-o", str(tmp_path / "session.json")]
    assert main(args) == 2  # a word the detector cannot use: bad usage
    assert "--pronounce 'kaptchur=" in capsys.readouterr().err  # the advice names the option
    assert main([*args, "--pronounce", "kaptchur=K AE P CH ER"]) == 0
    doc = json.loads((tmp_path / "session.json").read_text())
    assert doc["trigger_words"] == ["kaptchur"]
    # the operator said "capture": its sets are at the spoken triggers
    assert len(doc["sets"]) >= len(truth["triggers"]) // 2
    assert all(_hold_of(truth, s["trigger"]["start_s"], s["trigger"]["end_s"])
               for s in doc["sets"])


@pytest.mark.parametrize("kind", ["notes", "truth"])
def test_force_replaces_only_a_session_file(synth, tmp_path: Path, capsys, kind: str) -> None:
    """-o naming the operator's notes or another JSON file is refused, --force or not:
    it would be replaced, and its .bak replaced again by the next run."""
    out, truth = synth
    victim = tmp_path / ("notes.txt" if kind == "notes" else "truth.json")
    victim.write_text("board moved at 01:12\n" if kind == "notes"
                      else (out / "truth.json").read_text())
    before = victim.read_text()
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "-o", str(victim), "--force"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "%]" not in err  # before any work
    assert f"{victim} exists and --force replaces only a session file" in err
    assert "choose another -o, or move it away first" in err and "--audio AUDIO" not in err
    assert victim.read_text() == before
    assert not victim.with_name(victim.name + ".bak").exists()


def _true_words(truth: dict, folder: Path) -> Path:
    """A transcript of the session's true trigger words (for tests of what ``--force``
    keeps, which need sets to decide on, not their detection)."""
    words = folder / "words.csv"
    words.write_text("word,start,end\n" + "".join(
        f"{t['word']},{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    return words


def test_a_second_force_leaves_the_bak_that_holds_the_review_work(
        synth, tmp_path: Path, capsys) -> None:
    """The first --force keeps the reviewed file as .bak; a second one used to replace
    that .bak with the first one's fresh, undecided file: the decisions were gone."""
    from speechcal_core.session.store import load_session, save_session

    out, truth = synth
    path = tmp_path / "session.json"
    run = ["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
           "--offset-ns", str(truth["sync"]["offset_ns"]),
           "--transcript", str(_true_words(truth, tmp_path)), "-o", str(path)]
    assert main(run) == 0
    reviewed = load_session(path)
    reviewed.sets[:3] = [s.with_decision("accepted") for s in reviewed.sets[:3]]
    save_session(reviewed, path)
    capsys.readouterr()

    assert main([*run, "--force"]) == 0
    assert f"the file it replaced is kept as {path}.bak" in capsys.readouterr().err
    assert main([*run, "--force"]) == 0
    err = capsys.readouterr().err
    assert f"{path}.bak is left as it was: it holds review work (3 decisions)" in err
    kept = load_session(path.with_name("session.json.bak"))
    assert [s.decision for s in kept.sets[:3]] == ["accepted"] * 3
    assert all(s.decision == "undecided" for s in load_session(path).sets)


def test_a_force_over_reviewed_files_keeps_the_older_review_work_too(
        synth, tmp_path: Path, capsys) -> None:
    """The file replaced and its .bak both hold decisions: the .bak moves aside to
    .bak.1 (then .bak.2), never replaced by the newer one."""
    from speechcal_core.session.store import load_session, save_session

    out, truth = synth
    path = tmp_path / "session.json"
    run = ["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
           "--offset-ns", str(truth["sync"]["offset_ns"]),
           "--transcript", str(_true_words(truth, tmp_path)), "-o", str(path)]

    def review(n: int) -> None:
        reviewed = load_session(path)
        reviewed.sets[:n] = [s.with_decision("accepted") for s in reviewed.sets[:n]]
        save_session(reviewed, path, backup=False)

    assert main(run) == 0
    review(3)
    assert main([*run, "--force"]) == 0  # the 3 decisions go to .bak
    review(2)
    capsys.readouterr()
    assert main([*run, "--force"]) == 0
    err = capsys.readouterr().err
    assert f"the file it replaced is kept as {path}.bak" in err
    assert f"the earlier {path}.bak, which holds review work too (3 decisions), is kept " \
           f"as {path}.bak.1" in err

    def decided(name: str) -> int:
        return sum(s.decision == "accepted" for s in load_session(tmp_path / name).sets)

    assert (decided("session.json.bak"), decided("session.json.bak.1")) == (2, 3)
    review(1)
    assert main([*run, "--force"]) == 0
    assert (decided("session.json.bak"), decided("session.json.bak.1"),
            decided("session.json.bak.2")) == (1, 3, 2)


def _depth_bag(path: Path, first_ns: int, count: int = 40) -> Path:
    """A ROS1 bag of 32-bit float depth images (``32FC1``), 10 Hz from ``first_ns``."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS1_NOETIC)
    header_t, time_t = ts.types["std_msgs/msg/Header"], ts.types["builtin_interfaces/msg/Time"]
    pixels = np.frombuffer(np.ones((48, 64), np.float32).tobytes(), np.uint8)
    with Writer(path) as writer:
        conn = writer.add_connection("/depth/image_raw", "sensor_msgs/msg/Image", typestore=ts)
        for k in range(count):
            t = first_ns + k * 100_000_000
            header = header_t(seq=k, stamp=time_t(sec=t // 10**9, nanosec=t % 10**9),
                              frame_id="depth")
            msg = ts.types["sensor_msgs/msg/Image"](header, 48, 64, "32FC1", 0, 256, pixels)
            writer.write(conn, t, bytes(ts.serialize_ros1(msg, "sensor_msgs/msg/Image")))
    return path


def test_a_depth_stream_is_named_with_how_to_leave_it_out_before_any_work(
        synth, tmp_path: Path, capsys) -> None:
    """A 32-bit depth topic recorded with the cameras was taken for a camera: process
    read the clap and the words, then failed on its frames without saying what to do."""
    out, truth = synth
    with open_recording([out / truth["recording"]]) as source:
        first = source.streams[0].first_ns
    depth = _depth_bag(tmp_path / "depth.bag", first)
    code = main(["process", str(out / truth["recording"]), str(depth), "--audio",
                 str(out / "audio.ogg"), "-o", str(tmp_path / "session.json")])
    captured = capsys.readouterr()
    assert code == 1 and captured.out == ""
    assert "clap" not in captured.err and "trigger words" not in captured.err
    (line,) = [ln for ln in captured.err.splitlines() if "error:" in ln]
    assert "depth.bag: /depth/image_raw frame 0" in line
    assert "unknown image encoding '32FC1'" in line
    assert "leave the stream out with --skip-stream /depth/image_raw" in line
    assert not (tmp_path / "session.json").exists()


CHECKERBOARD_YAML = ("target_type: 'checkerboard'\ntargetCols: 8\ntargetRows: 6\n"
                     "rowSpacingMeters: 0.045\ncolSpacingMeters: 0.045\n")
APRILGRID_YAML = ("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\ntagSize: 0.055\n"
                  "tagSpacing: 0.3\n")


@pytest.mark.slow
@pytest.mark.parametrize(("fixture", "yaml", "board", "word"), [
    ("snapshot_synth", CHECKERBOARD_YAML, "8x6 checkerboard of 0.045 m squares", "snapshot"),
    ("checkerboard_synth", APRILGRID_YAML, "6x6 AprilGrid of 0.055 m tags", "capture"),
], ids=["checkerboard-yaml-on-aprilgrid", "aprilgrid-yaml-on-checkerboard"])
def test_a_wrong_target_is_named_as_found_in_no_frame(
        fixture: str, yaml: str, board: str, word: str, request: pytest.FixtureRequest,
        tmp_path: Path, capsys) -> None:
    """A checkerboard yaml for an AprilGrid recording (or the other way round) found the
    board nowhere; the session said only that no camera fit. Its notes now say the board
    was in no frame and that --target may be the wrong one."""
    out, truth = request.getfixturevalue(fixture)
    target = tmp_path / "target.yaml"
    target.write_text(yaml)
    session = tmp_path / "session.json"
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "--trigger", word, "--offset-ns", str(truth["sync"]["offset_ns"]),
                 "--target", str(target), "-o", str(session), "--json"])
    captured = capsys.readouterr()
    assert code == 0
    notes = json.loads(captured.out)["notes"]
    said = [n for n in notes if n.startswith(f"the {board} was not found in any frame")]
    assert len(said) == 1, notes
    assert "is --target the board filmed?" in said[0] and "--target TARGET.yaml" in said[0]
    assert f"note: {said[0]}" in captured.err
    sets = json.loads(session.read_text())["sets"]
    assert sets and not any(f["corners"] for s in sets for f in s["frames"])


def test_the_board_filmed_gives_no_such_note(checkerboard_synth, tmp_path: Path,
                                            capsys) -> None:
    out, truth = checkerboard_synth
    target = tmp_path / "target.yaml"
    target.write_text(CHECKERBOARD_YAML)
    code = main(["process", str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                 "--offset-ns", str(truth["sync"]["offset_ns"]), "--target", str(target),
                 "-o", str(tmp_path / "session.json"), "--json"])
    assert code == 0
    assert not any("was not found in any frame" in n
                   for n in json.loads(capsys.readouterr().out)["notes"])
