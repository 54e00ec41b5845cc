"""``speechcal review RECORDING --audio AUDIO --trigger W``: the operator's own trigger word
(and sensitivity, pronunciations, audio channel) for the session the review makes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from speechcal_core.cli import main


def test_the_review_finds_the_trigger_word_it_is_given(
        snapshot_synth: tuple[Path, dict], tmp_path: Path) -> None:
    folder, truth = snapshot_synth
    recording, audio = folder / truth["recording"], folder / truth["audio"]
    target = tmp_path / "snapshot.json"
    assert main(["review", str(recording), "--audio", str(audio), "--session", str(target),
                 "--trigger", "Snapshot!", "--channel", "0",
                 "--screenshot", str(tmp_path / "x.png")]) == 0
    session = json.loads(target.read_text())
    assert session["trigger_words"] == ["snapshot"]
    assert session["audio_channel"] == 0
    said = [(t["start_s"] + t["end_s"]) / 2 for t in truth["triggers"]]
    found = [(s["trigger"]["start_s"] + s["trigger"]["end_s"]) / 2 for s in session["sets"]]
    assert {s["trigger"]["word"] for s in session["sets"]} == {"snapshot"}
    assert len(found) >= len(said) - 1
    assert all(min(abs(f - t) for t in said) < 0.1 for f in found)


def test_trigger_options_with_a_session_file_are_a_usage_error(
        truth_session_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for option in (["--trigger", "snapshot"], ["--target", "target.yaml"]):
        assert main(["review", str(truth_session_file), *option]) == 2
        assert "go with a recording the review processes" in capsys.readouterr().err


def test_the_review_looks_for_the_board_it_is_given(
        checkerboard_synth: tuple[Path, dict], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A checkerboard recording opened with its target.yaml: the new session has its
    corners, with no second processing run."""
    folder, truth = checkerboard_synth
    session_path = tmp_path / "review.json"
    assert main(["review", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--target", str(folder / "target.yaml"),
                 "--session", str(session_path), "--screenshot", str(tmp_path / "x.png")]) == 0
    session = json.loads(session_path.read_text())
    assert session["target"]["kind"] == "checkerboard" and not session["target_assumed"]
    # the board is found in every set (the AprilGrid assumed without --target: in none)
    assert session["coverage"]["/cam0/image_raw"]["views"] == len(session["sets"]) >= 3
    # the session is opened again as it is; stderr has the whole note, which the window's
    # status line cuts short
    capsys.readouterr()
    assert main(["review", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--trigger", "snapshot",
                 "--session", str(session_path), "--screenshot", str(tmp_path / "x.png")]) == 0
    err = capsys.readouterr().err
    assert "speechcal review: 1 camera, " in err
    assert "not detected again with trigger word snapshot (it has capture): Edit ▸ " in err
    assert "adds its sets and keeps the review work" in err


def test_a_bad_target_file_is_reported_before_anything_opens(
        tiny_synth: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder, truth = tiny_synth
    board = tmp_path / "board.yaml"
    board.write_text("target_type: hexagon\n")
    code = main(["review", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--target", str(board)])
    err = capsys.readouterr().err
    assert code != 0 and str(board) in err and "hexagon" in err


def test_a_bad_sensitivity_is_a_usage_error_before_anything_opens(
        tiny_synth: tuple[Path, dict], capsys: pytest.CaptureFixture[str]) -> None:
    folder, truth = tiny_synth
    code = main(["review", str(folder / truth["recording"]), "--audio",
                 str(folder / truth["audio"]), "--sensitivity", "2"])
    assert code == 2
    assert "--sensitivity 2: give a value from 0 to 1" in capsys.readouterr().err


def test_a_session_without_sets_says_why_beside_the_empty_list(
        open_window, truth_session_file: Path) -> None:
    from speechcal_core.session.store import load_session, save_session

    session = load_session(truth_session_file)
    session.sets = []
    session.extra["detection_notes"] = ["audio.ogg: no trigger word (capture) found"]
    save_session(session, truth_session_file)
    window = open_window(truth_session_file)
    assert window.no_sets_label.isVisible()
    assert "no trigger word (capture) found. Said another word?" in window.no_sets_label.text()
    window.model.add_set()  # the operator adds one at the playhead: the hint goes
    assert not window.no_sets_label.isVisible()
