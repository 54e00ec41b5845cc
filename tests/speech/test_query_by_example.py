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
    assert len(hits) == 3
    # each in a "mark" of its own (not "market"); the example itself as marked
    assert sorted(next(k for k, (a, b) in enumerate(scene.spans("mark")) if a <= h.t <= b)
                  for h in hits) == [0, 1, 2]
    assert (hits[0].start_s, hits[0].end_s) == first


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


def test_one_marked_instance_finds_the_others_in_noise(tmp_path: Path) -> None:
    # at 5 dB a fixed cost limit found none of the others: the search's limit follows
    # how closely the closest other span matches
    items = [("capture", "slt/capture_1"), ("okay", "slt/okay_1"),
             ("capture", "slt/capture_2"), ("good", "slt/good_1"),
             ("capture", "slt/capture_3"), ("hold on", "slt/hold_on_1"),
             ("capture", "slt/capture_4")]
    scene = make_scene(tmp_path / "noisy.wav", items, snr_db=5.0, seed=2)
    audio = load_audio(scene.path, rate=16000)
    spans = scene.spans("capture")
    hits = find_similar(audio, Example(*spans[0], word="capture"))
    inside = [k for h in hits for k, (a, b) in enumerate(spans) if a <= h.t <= b]
    assert len(inside) == len(hits)  # nothing else
    assert len(set(inside) - {0}) >= 2
