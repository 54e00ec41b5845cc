"""Trigger words at a still board: nearly all with the right offset, and a note when many
fall in a move (another session's audio, or an offset seconds off)."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from truth_sessions import truth_sync, truth_triggers

from speechcal_core.cli import main
from speechcal_core.frames.analysis import analyse_frames
from speechcal_core.frames.word_stillness import (
    MIN_WORDS,
    ODDS,
    WordStillness,
    moving_words_note,
    word_stillness,
)
from speechcal_core.sources import open_recording
from speechcal_core.target import TargetSpec


def _stillness(folder: Path, truth: dict, shift_ns: int) -> WordStillness:
    """The best-still search over the true triggers with the true offset moved."""
    sync = truth_sync(truth)
    sync = sync.with_offset(sync.offset_ns + shift_ns)
    with open_recording([str(folder / truth["recording"])]) as source:
        analysis = analyse_frames(source, sync, truth_triggers(truth), TargetSpec())
    return word_stillness(analysis.sets, analysis.extra["frame_details"])


def test_with_the_true_offset_nearly_every_word_falls_at_a_still_board(noisy_synth) -> None:
    stillness = _stillness(*noisy_synth, shift_ns=0)
    assert stillness.judged == len(noisy_synth[1]["triggers"]) >= MIN_WORDS
    assert stillness.still >= 0.8 * stillness.judged and not stillness.doubtful
    assert moving_words_note(stillness, "audio.ogg") == ""


@pytest.mark.parametrize("shift_s", [-1.2, 1.0])
def test_an_offset_a_second_off_puts_many_words_in_a_move(noisy_synth, shift_s) -> None:
    stillness = _stillness(*noisy_synth, shift_ns=int(shift_s * 1e9))
    assert stillness.doubtful
    note = moving_words_note(stillness, "take2/audio.ogg")
    assert note.startswith(f"only {stillness.still} of {stillness.judged} trigger words")
    assert "is take2/audio.ogg this recording's audio?" in note


def test_a_count_is_doubtful_when_chance_explains_it_far_better() -> None:
    assert WordStillness(still=9, judged=18).doubtful  # half: another session's audio
    assert not WordStillness(still=11, judged=17).doubtful  # a short session of early words
    assert not WordStillness(still=7, judged=MIN_WORDS).doubtful
    assert WordStillness(still=2, judged=MIN_WORDS).doubtful
    assert not WordStillness(still=2, judged=MIN_WORDS - 1).doubtful  # too few to judge
    assert WordStillness(still=9, judged=18).odds_of_chance > ODDS > \
        WordStillness(still=11, judged=17).odds_of_chance


def test_details_searched_at_another_time_are_not_judged(noisy_synth) -> None:
    """After an offset edit, a set's details are its old time's until re-scored."""
    folder, truth = noisy_synth
    with open_recording([str(folder / truth["recording"])]) as source:
        analysis = analyse_frames(source, truth_sync(truth), truth_triggers(truth),
                                  TargetSpec())
    details = analysis.extra["frame_details"]
    moved = [replace(s, t_ns=s.t_ns + 33_000_000) for s in analysis.sets[:4]]
    stillness = word_stillness([*moved, *analysis.sets[4:]], details)
    assert stillness.judged == len(analysis.sets) - 4


def test_process_notes_the_words_in_moves_and_names_the_audio(
        noisy_synth, tmp_path: Path, capsys) -> None:
    folder, truth = noisy_synth
    words = tmp_path / "words.csv"  # the true words: no recogniser needed here
    words.write_text("".join(f"{t['word']},{t['start_s']},{t['end_s']}\n"
                             for t in truth["triggers"]))
    audio = folder / truth["audio"]
    off = truth["sync"]["offset_ns"] + 10**9
    code = main(["process", str(folder / truth["recording"]), "--audio", str(audio),
                 "--transcript", str(words), "--offset-ns", str(off),
                 "-o", str(tmp_path / "session.json"), "--json"])
    captured = capsys.readouterr()
    assert code == 0
    assert f"of {len(truth['triggers'])} trigger words fall while the board is held still" \
        in captured.err
    (note,) = [n for n in json.loads(captured.out)["notes"] if "held still" in n]
    assert note.startswith("only ")
    assert f"is {audio} this recording's audio and {words} its transcript?" in note
