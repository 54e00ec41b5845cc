"""The processing facade with a transcript and a known offset (no clap, no recogniser)."""

from __future__ import annotations

from pathlib import Path

import pytest

from speechcal_core.pipeline import process_recording

#: the tiny session's fisheye camera: at 256x192 it reads its board (one tag, the rest
#: grown from it) only in the last set
TINY_FISHEYE = "/cam2/image_raw"


def test_transcript_and_known_offset_give_one_set_per_trigger_inside_its_hold(
    tiny_synth: tuple[Path, dict], tmp_path: Path
) -> None:
    folder, truth = tiny_synth
    csv = tmp_path / "words.csv"
    rows = ["word,start,end", "okay,0.20,0.45"]
    rows += [f"Capture!,{t['start_s']:.4f},{t['end_s']:.4f}" for t in truth["triggers"]]
    csv.write_text("\n".join(rows) + "\n")
    stages: list[str] = []
    session = process_recording(
        [str(folder / truth["recording"])], str(folder / truth["audio"]),
        transcript=str(csv), offset_ns=truth["sync"]["offset_ns"],
        progress=lambda text, _f: stages.append(text),
    )
    assert session.sync.source == "manual" and session.sync_evidence == {}
    assert [s.trigger.word for s in session.sets] == ["capture"] * len(truth["triggers"])
    for frame_set, trig in zip(session.sets, truth["triggers"], strict=True):
        start, end = trig["hold"]
        for frame in frame_set.frames:
            assert frame.index >= 0
            assert start - 40e6 <= frame.stamp_ns <= end + 40e6
    assert "finding the clap" not in stages and stages[-1] == "done"
    # no note: the 256x192 fisheye camera, its board at the detector's limit, reads it in
    # the last set (and in no other)
    assert session.extra.get("detection_notes", []) == []
    assert [next(f.corners for f in s.frames if f.stream == TINY_FISHEYE) > 0
            for s in session.sets] == [False] * (len(session.sets) - 1) + [True]
    # no target given: the session says its 6x6 AprilGrid is an assumption
    assert session.extra["target"]["kind"] == "aprilgrid"
    assert session.extra["target_assumed"] is True


def test_a_transcript_running_past_the_audio_is_noted(tiny_synth: tuple[Path, dict],
                                                      tmp_path: Path, capsys) -> None:
    """Another recording's transcript: its words lie past this audio's end, and process
    says so instead of writing sets without frames in silence."""
    from speechcal_core.cli import main

    folder, truth = tiny_synth
    csv = tmp_path / "words.csv"
    csv.write_text("word,start,end\ncapture,2.0,2.4\ncapture,500.0,500.5\n")
    assert main(["process", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--transcript", str(csv), "--offset-ns",
                 str(truth["sync"]["offset_ns"]), "-o", str(tmp_path / "s.json")]) == 0
    err = capsys.readouterr().err
    assert f"note: {csv}: 1 trigger word lies past the audio's end" in err
    assert "is it this audio's transcript?" in err


def test_two_recordings_given_as_one_are_noted(tiny_synth: tuple[Path, dict],
                                               snapshot_synth: tuple[Path, dict],
                                               tmp_path: Path, capsys) -> None:
    """Two sessions' bags whose camera stamps overlap: process says so, as index does,
    instead of merging them without a word."""
    from speechcal_core.cli import main

    folder, truth = tiny_synth
    other, other_truth = snapshot_synth
    assert main(["process", str(folder / truth["recording"]),
                 str(other / other_truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--offset-ns", str(truth["sync"]["offset_ns"]),
                 "-o", str(tmp_path / "s.json")]) == 0
    err = capsys.readouterr().err
    assert "note: /cam0/image_raw: " in err
    assert "of one file fall among another's (another recording given too?" in err


def test_two_recordings_given_as_one_are_named_when_no_clap_is_seen(
        tiny_synth: tuple[Path, dict], snapshot_synth: tuple[Path, dict]) -> None:
    """Interleaved frames of two takes can hide the clap: the error said only "no clap
    seen" and where to look for it; it now names the two recordings first. (Here the
    search is cut short so that no clap is seen.)"""
    from speechcal_core.audio import load_audio
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.errors import SyncError
    from speechcal_core.sync.pipeline import sync_recording

    folder, truth = tiny_synth
    other, other_truth = snapshot_synth
    audio = load_audio(str(folder / truth["audio"]))
    with open_recording([str(folder / truth["recording"]),
                         str(other / other_truth["recording"])]) as source, \
            pytest.raises(SyncError) as error:
        sync_recording(source, audio, search_s=0.1)
    message = str(error.value)
    assert message.startswith("no clap seen in the first 0.1 s of any camera")
    assert "of one file fall among another's (another recording given too?" in message
    assert "give one recording's files, or make the clap visible" in message


def test_a_recording_with_unset_stamps_is_not_called_two_recordings(
        tiny_synth: tuple[Path, dict], tmp_path: Path) -> None:
    """A driver that never set header stamps: the error told the user to "give one
    recording's files", the advice for two takes given as one."""
    from rosbags.rosbag1 import Reader, Writer
    from rosbags.typesys import Stores, get_typestore

    from speechcal_core.audio import load_audio
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.errors import SyncError
    from speechcal_core.sync.pipeline import sync_recording

    folder, truth = tiny_synth
    unset = tmp_path / "unset.bag"
    typestore = get_typestore(Stores.ROS1_NOETIC)
    with Reader(folder / truth["recording"]) as reader, Writer(unset) as writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=typestore)
                 for c in reader.connections}
        for conn, log_time, raw in reader.messages():
            zeroed = bytearray(raw)
            zeroed[4:12] = bytes(8)  # header.stamp after the seq number
            writer.write(conns[conn.id], log_time, bytes(zeroed))
    with open_recording([str(unset)]) as source, pytest.raises(SyncError) as error:
        sync_recording(source, load_audio(str(folder / truth["audio"])))
    message = str(error.value)
    assert "zero or negative stamps (header stamps not set?); make the clap" in message
    assert "give one recording's files" not in message


def test_json_says_what_was_written_and_stdout_holds_nothing_else(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys) -> None:
    import json

    from speechcal_core.cli import main

    folder, truth = tiny_synth
    out = tmp_path / "s.json"
    offset = truth["sync"]["offset_ns"]
    assert main(["process", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--transcript",
                 str(_true_words(truth, tmp_path / "words.csv")), "--offset-ns", str(offset),
                 "-o", str(out), "--json"]) == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    assert doc.pop("notes") == []
    assert doc == {"session": str(out.absolute()), "sets": len(truth["triggers"]),
                   "sync": {"offset_ns": offset, "drift": 0.0, "source": "manual"},
                   "replaced": False, "streams": None,
                   "audio": str((folder / truth["audio"]).absolute()), "audio_topic": None}
    assert f"wrote {out}" in captured.err


def test_process_refuses_to_replace_a_session_without_force(
    tiny_synth: tuple[Path, dict], truth_session_file: Path, tmp_path: Path, capsys
) -> None:
    from speechcal_core.cli import main

    folder, truth = tiny_synth
    session = tmp_path / "session.json"
    reviewed = truth_session_file.read_text()  # a session with the operator's decisions
    session.write_text(reviewed)
    args = ["process", str(folder / truth["recording"]), "--audio",
            str(folder / truth["audio"]), "--offset-ns", str(truth["sync"]["offset_ns"]),
            "-o", str(session)]
    assert main(args) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "already exists" in err[0] and "--force" in err[0]
    assert session.read_text() == reviewed
    assert main([*args, "--force"]) == 0
    assert session.read_text() != reviewed and '"sets"' in session.read_text()
    assert (tmp_path / "session.json.bak").read_text() == reviewed
    assert f"the file it replaced is kept as {session}.bak" in capsys.readouterr().err


def _true_words(truth: dict, path: Path) -> Path:
    path.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    return path


def test_trigger_words_past_the_recordings_end_are_named_as_such(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys) -> None:
    """A recording cut short (here: the audio placed 8 s later against it): the words said
    after its last frame are named, not only "check the offset"."""
    from speechcal_core.cli import main

    folder, truth = tiny_synth
    late = truth["sync"]["offset_ns"] + 8_000_000_000
    assert main(["process", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--transcript",
                 str(_true_words(truth, tmp_path / "words.csv")), "--offset-ns", str(late),
                 "-o", str(tmp_path / "s.json")]) == 0
    err = capsys.readouterr().err
    assert "note: trigger words said outside the recording: " in err
    assert " after its last frame (" in err and "is the recording cut short" in err
    assert "before its first frame" not in err


def test_an_offset_that_puts_the_audio_outside_the_recording_is_refused(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys) -> None:
    from speechcal_core.cli import main

    folder, truth = tiny_synth
    out = tmp_path / "s.json"
    assert main(["process", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--transcript",
                 str(_true_words(truth, tmp_path / "words.csv")), "--offset-ns", "12",
                 "-o", str(out)]) == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]  # after the progress lines
    assert last.startswith("speechcal process: error: --offset-ns 12 puts the audio (0 to ")
    assert "outside the recording's header stamps (" in last and not out.exists()


def _stereo(audio: Path, out: Path, mic_channel: int) -> Path:
    """``audio`` on channel ``mic_channel`` of a two-channel file, silence on the other
    (a recorder whose second input was unplugged)."""
    import numpy as np
    import soundfile as sf

    samples, rate = sf.read(str(audio), dtype="float32")
    both = np.zeros((samples.size, 2), np.float32)
    both[:, mic_channel] = samples
    sf.write(str(out), both, rate)
    return out


def test_the_microphones_channel_is_used_and_kept_in_the_session(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys) -> None:
    """A two-channel recorder: --channel picks the microphone's for the clap and the
    words, and the session keeps it for the window's waveform, sound and search."""
    from speechcal_core.cli import main
    from speechcal_core.review.loading import load_for_review
    from speechcal_core.session.store import load_session

    folder, truth = tiny_synth
    stereo = _stereo(folder / truth["audio"], tmp_path / "stereo.wav", mic_channel=1)
    words = _true_words(truth, tmp_path / "words.csv")
    out = tmp_path / "s.json"
    assert main(["process", str(folder / truth["recording"]), "--audio", str(stereo),
                 "--channel", "1", "--transcript", str(words), "-o", str(out)]) == 0
    session = load_session(out)
    assert session.audio_channel == 1
    assert abs(session.sync.offset_ns - truth["sync"]["offset_ns"]) < 40_000_000  # clap found
    inputs = load_for_review(session_path=str(out))
    try:
        _t, _mn, mx = inputs.pyramid.envelope(0.0, inputs.pyramid.duration_s, 400)
        assert float(mx.max()) > 0.05  # the microphone's channel, not the silent one
    finally:
        inputs.close()
    assert main(["detect", str(stereo), "--channel", "0", "--json"]) == 0  # silent channel
    assert "no speech found" in capsys.readouterr().err
    assert main(["detect", str(stereo), "--channel", "2"]) == 1
    assert "has 2 channel(s), channel 2 asked" in capsys.readouterr().err


def test_audio_that_ends_long_before_the_recording_is_noted(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys) -> None:
    """A cut-short audio file: the words said after its end cannot be found, and process
    says so instead of quietly writing fewer sets."""
    import soundfile as sf

    from speechcal_core.cli import main

    folder, truth = tiny_synth
    samples, rate = sf.read(str(folder / truth["audio"]), dtype="float32")
    short = tmp_path / "short.wav"
    sf.write(str(short), samples[:6 * rate], rate)
    assert main(["process", str(folder / truth["recording"]), "--audio", str(short),
                 "--offset-ns", str(truth["sync"]["offset_ns"]),
                 "-o", str(tmp_path / "s.json")]) == 0
    err = capsys.readouterr().err
    assert f"note: {short}: the audio ends after 6.0 s, " in err
    assert "before the recording's last frame: trigger words said after that are not " \
        "found; is the audio file complete?" in err
    assert main(["process", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--offset-ns", str(truth["sync"]["offset_ns"]),
                 "-o", str(tmp_path / "whole.json")]) == 0
    assert "is the audio file complete?" not in capsys.readouterr().err


def test_no_clap_seen_names_the_command_that_takes_its_options(
        tiny_synth: tuple[Path, dict]) -> None:
    """``speechcal process`` failing with "search longer (--search-s), or set it by hand
    (--video-clap-ns)": process takes neither option (sync does), so following the advice
    ended in "unrecognized arguments". The advice now names the command that takes them
    and how process then takes the clap (--offset-ns)."""
    from speechcal_core.audio import load_audio
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.errors import SyncError
    from speechcal_core.sync.pipeline import sync_recording

    folder, truth = tiny_synth
    audio = load_audio(str(folder / truth["audio"]))
    with open_recording(str(folder / truth["recording"])) as source, \
            pytest.raises(SyncError) as error:
        sync_recording(source, audio, search_s=0.1)
    message = str(error.value)
    assert "(--search-s)" not in message and "(--video-clap-ns)" not in message
    assert message.endswith(
        "make the clap visible to the cameras, search longer (speechcal sync --search-s S), "
        "or set it by hand (speechcal sync --video-clap-ns NS prints the offset; process "
        "takes it as --offset-ns N)")


@pytest.mark.parametrize("assumed, reason", [
    (True, "no --target was given, so Kalibr's default board was looked for. Process again"),
    (False, "is --target the board filmed? Process again"),
])
def test_a_board_found_nowhere_is_noted_in_sentences(assumed: bool, reason: str) -> None:
    from speechcal_core.pipeline import target_not_found_note
    from speechcal_core.session.model import FrameChoice, FrameSet, Trigger
    from speechcal_core.target import TargetSpec

    frames = (FrameChoice("/cam0/image_raw", 3, 100, corners=0),
              FrameChoice("/cam1/image_raw", 3, 101, corners=0))
    sets = [FrameSet(1, 100, Trigger("capture", 1.0, 1.5), frames)]
    note = target_not_found_note(sets, TargetSpec(), assumed)
    assert note.startswith("the 6x6 AprilGrid of 0.055 m tags was not found in any frame of "
                           "any camera (2 frames of 1 frame sets): ")
    assert reason in note
