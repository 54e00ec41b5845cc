"""``speechcal review RECORDING --audio AUDIO --session PATH``: the new session goes to
PATH, e.g. when the recording lies on read-only media."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from speechcal_core.cli import main
from speechcal_core.review.loading import default_session_path


def test_a_recording_is_reviewed_with_its_session_kept_where_asked(
        tiny_synth: tuple[Path, dict], tmp_path: Path) -> None:
    folder, truth = tiny_synth
    recording, audio = folder / truth["recording"], folder / truth["audio"]
    target = tmp_path / "mine.json"
    code = main(["review", str(recording), "--audio", str(audio), "--session", str(target),
                 "--screenshot", str(tmp_path / "x.png")])
    assert code == 0
    assert json.loads(target.read_text())["sets"]
    assert not default_session_path([str(recording)]).exists()


def test_a_recording_with_its_session_reopens_without_the_audio(
        processed_tiny, tiny_synth: tuple[Path, dict], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """The session knows its audio: ``review RECORDING --session S`` opens S as it is (it
    asked for --audio before); without a session there the audio is still needed."""
    _folder, truth = tiny_synth
    # the session a review of the recording and its audio made at reviews/lab.json
    shutil.copytree(processed_tiny("reviews/lab.json"), tmp_path, dirs_exist_ok=True)
    recording, audio = tmp_path / "rec" / truth["recording"], tmp_path / "rec" / truth["audio"]
    target = tmp_path / "reviews" / "lab.json"
    shot = str(tmp_path / "x.png")
    assert main(["review", str(recording), "--session", str(target), "--screenshot", shot]) == 0
    assert json.loads(target.read_text())["audio"].endswith(audio.name)
    assert main(["review", str(recording), "--session", str(tmp_path / "none.json"),
                 "--screenshot", shot]) == 2
    assert "a recording needs its audio: add --audio AUDIO" in capsys.readouterr().err


def test_session_option_with_a_session_file_is_a_usage_error(
        truth_session_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["review", str(truth_session_file), "--session", "x.json"]) == 2
    assert "go with a recording" in capsys.readouterr().err


@pytest.mark.parametrize("inputs", [["s1/session.json", "s1/audio.ogg"],
                                    ["s1/recording.bag", "s1/session.json"]])
def test_a_session_file_among_other_inputs_is_told_to_open_alone(
        inputs: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    """It was taken for a recording: "a JSON file (a session file opens with speechcal
    review), not a recording", said to a speechcal review."""
    assert main(["review", *inputs]) == 2
    assert ("s1/session.json is a session file: open it alone (speechcal review "
            "s1/session.json), it knows its recording and audio; a recording's session file "
            "goes with --session") in capsys.readouterr().err


def test_session_option_without_a_recording_is_a_usage_error(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["review", "--session", "x.json"]) == 2
    assert "--session goes with a recording" in capsys.readouterr().err
    assert main(["review", "--target", "board.yaml"]) == 2
    assert "--target goes with a recording: RECORDING --audio AUDIO --target T.yaml" \
        in capsys.readouterr().err


def test_the_audio_may_come_among_the_inputs_as_a_drop_gives_it(
        tiny_synth: tuple[Path, dict], tmp_path: Path) -> None:
    """``review recording.bag mic.ogg`` opens the pair (the window takes a drop of the two
    alike); the audio alone says to give the recording too."""
    folder, truth = tiny_synth
    recording, audio = folder / truth["recording"], folder / truth["audio"]
    target = tmp_path / "pair.json"
    assert main(["review", str(recording), str(audio), "--session", str(target),
                 "--screenshot", str(tmp_path / "x.png")]) == 0
    assert json.loads(target.read_text())["sets"]


def test_audio_alone_asks_for_the_recording(capsys: pytest.CaptureFixture[str],
                                            tmp_path: Path) -> None:
    assert main(["review", "s1/audio.ogg"]) == 2
    assert ("s1/audio.ogg is an audio file: give the recording too (speechcal review "
            "RECORDING --audio s1/audio.ogg)") in capsys.readouterr().err
    folder = tmp_path / "take.ogg"
    folder.mkdir()
    assert main(["review", str(folder)]) == 2
    assert f"{folder} is a folder, not an audio file" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["review.json.bak", "review.json.bak.1", "REVIEW.JSON"])
def test_a_previous_version_or_a_capitalised_session_file_opens_as_a_session(
        truth_session_file: Path, tmp_path: Path, name: str,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A damaged session's error says "the previous version is in review.json.bak";
    ``review review.json.bak`` (or a name from a FAT card in capitals) then said "a
    recording needs its audio: add --audio AUDIO", taking the session for a recording."""
    path = tmp_path / name
    shutil.copy(truth_session_file, path)
    assert main(["review", str(path), "--screenshot", str(tmp_path / "x.png")]) == 0
    err = capsys.readouterr().err
    assert "needs its audio" not in err
    if name != "REVIEW.JSON":  # the frames re-scored on opening were saved: restored
        assert f"{name} is a kept previous version: review work saved restores it as " \
            "review.json" in err
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            [name, "review.json", "x.png"])  # not review.json.bak.bak
