"""Same-speaker similarity: found triggers lead to the ones the recogniser missed."""

from __future__ import annotations

from pathlib import Path

from speech_scenes import make_scene

from speechcal_core.speech import Word
from speechcal_core.speech.self_similarity import expand_by_similarity
from speechcal_core.speech.vad import voice_activity


def test_two_found_instances_lead_to_the_missed_ones_only(tmp_path: Path) -> None:
    items = [("capture", "rms/capture_1"), ("okay", "rms/okay_1"),
             ("capture", "rms/capture_2"), ("picture", "rms/picture_1"),
             ("capture", "rms/capture_3"), ("hold on", "rms/hold_on_1"),
             ("capture", "rms/capture_5")]
    scene = make_scene(tmp_path / "rms.wav", items, snr_db=12.0, seed=7)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:2]]
    activity = voice_activity(scene.samples, 16000)
    extra = expand_by_similarity(scene.samples, 16000, seeds, activity, blocked=[])
    missed = [(a + b) / 2 for a, b in spans[2:]]
    assert len(extra) == 2
    assert all(min(abs(w.t - t) for t in missed) < 0.05 for w in extra)
    assert all(w.word == "capture" and w.source.endswith("similarity") for w in extra)


def test_a_single_seed_is_not_enough_to_judge_similarity(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "one.wav", [("capture", "rms/capture_1"),
                                              ("capture", "rms/capture_2")])
    a, b = scene.spans("capture")[0]
    activity = voice_activity(scene.samples, 16000)
    assert expand_by_similarity(scene.samples, 16000, [Word("capture", a, b)], activity,
                                blocked=[]) == []
