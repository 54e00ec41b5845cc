"""Query by example: one marked instance finds the other instances of the same word."""

from __future__ import annotations

from pathlib import Path

import pytest
from speech_scenes import make_scene

from speechcal_core.audio import load_audio
from speechcal_core.speech import SpeechError, detect_triggers
from speechcal_core.speech.query_by_example import Example, find_similar


def test_one_marked_instance_finds_the_others_of_the_same_speaker(tmp_path: Path) -> None:
    items = [("mark", "awb/mark_1"), ("okay", "awb/okay_1"), ("mark", "awb/mark_2"),
             ("market", "awb/market_1"), ("nice", "awb/nice_1"), ("mark", "awb/mark_3"),
             ("good", "awb/good_1")]
    scene = make_scene(tmp_path / "marks.wav", items, seed=4)
    audio = load_audio(scene.path, rate=16000)
    (first, *_rest) = scene.spans("mark")
    hits = find_similar(audio, Example(*first, word="mark"))
    truth = [(a + b) / 2 for a, b in scene.spans("mark")]
    assert len(hits) == 3
    assert all(min(abs(h.t - t) for t in truth) < 0.08 for h in hits)


def test_examples_work_through_the_facade_for_any_word(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "x.wav", [("capture", "rms/capture_1"), ("ok", "rms/okay_1"),
                                            ("capture", "rms/capture_1")], seed=5)
    (a, b), _ = scene.spans("capture")
    result = detect_triggers(scene.path, ["los"], backend="example", examples=[(a, b)])
    assert [w.word for w in result.triggers] == ["los", "los"]


def test_an_example_outside_the_audio_is_refused(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "y.wav", [("capture", "rms/capture_1")])
    with pytest.raises(SpeechError, match="outside the audio"):
        detect_triggers(scene.path, ["capture"], backend="example", examples=[(50.0, 50.5)])
