"""A word's shape in time: near-homophones the similarity search takes unfold differently."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import resample
from speech_scenes import RATE, Scene, clip, make_scene

from speechcal_core.audio import load_audio
from speechcal_core.speech import TriggerSpec, Word
from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend
from speechcal_core.speech.timing import word_bounds
from speechcal_core.speech.vad import voice_activity
from speechcal_core.speech.word_shape import (
    MIN_REFERENCES,
    SHAPE_LIMIT,
    shaped_like,
    voiced_level_db,
    word_shape,
)
from speechcal_core.synth.audio import render_audio
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import plan_session


def words_of(scene: Scene, text: str) -> list[Word]:
    """The scene's clips of ``text``, bounded by their energy as the detector bounds words."""
    activity = voice_activity(scene.samples, RATE)
    out = []
    for a, b in scene.spans(text):
        bounds = word_bounds(scene.samples, RATE, a, b, activity.floor_at((a + b) / 2))
        out.append(Word(text, bounds.start_s, bounds.end_s, 1.0, "test"))
    return out


def distance_to_closest(scene: Scene, references: list[Word], word: Word) -> float:
    level = voiced_level_db(scene.samples, RATE)
    shapes = np.array([word_shape(level, r) for r in references if r != word])
    return float(np.abs(shapes - word_shape(level, word)).mean(axis=1).min())


@pytest.mark.parametrize(("voice", "snr_db"), [("slt", 10.0), ("rms", 20.0)])
def test_rapture_unfolds_unlike_capture_in_the_same_voice(tmp_path: Path, voice: str,
                                                         snr_db: float) -> None:
    # "rapture" is voiced from its first sound, "capture" only after the /k/'s burst
    items = [("capture", f"{voice}/capture_{k}") for k in range(1, 6)]
    items += [("rapture", f"{voice}/rapture_{k}") for k in (1, 2)]
    scene = make_scene(tmp_path / "takes.wav", items, snr_db=snr_db, seed=1)
    captures, raptures = words_of(scene, "capture"), words_of(scene, "rapture")
    among_captures = [distance_to_closest(scene, captures, w) for w in captures]
    to_raptures = [distance_to_closest(scene, captures, w) for w in raptures]
    assert max(among_captures) < 0.5 * min(to_raptures)
    assert max(among_captures) < SHAPE_LIMIT


def test_a_word_said_slower_keeps_its_shape(tmp_path: Path) -> None:
    take = clip("kal16/capture_1")
    slower = resample(take, int(take.size * 1.25)).astype(np.float32)
    items = [("capture", "kal16/capture_1"), ("capture", "kal16/capture_2"),
             ("capture", "kal16/capture_3"), ("slower", slower)]
    scene = make_scene(tmp_path / "slower.wav", items, snr_db=20.0, seed=2)
    captures = words_of(scene, "capture")
    (slow,) = words_of(scene, "slower")
    assert slow.end_s - slow.start_s > 1.2 * (captures[0].end_s - captures[0].start_s)
    assert distance_to_closest(scene, captures, slow) < 0.08


def test_finds_unlike_enough_heard_triggers_are_dropped_too_few_drop_nothing(
        tmp_path: Path) -> None:
    takes = [("capture", f"slt/capture_{k % 5 + 1}") for k in range(MIN_REFERENCES + 1)]
    items = [*takes, ("rapture", "slt/rapture_1"), ("rapture", "slt/rapture_2")]
    scene = make_scene(tmp_path / "many.wav", items, snr_db=10.0, seed=1)
    captures, raptures = words_of(scene, "capture"), words_of(scene, "rapture")
    heard, finds = captures[:MIN_REFERENCES], [captures[-1], *raptures]
    # a limit between the two: the last take lies 0.02 from the others, raptures 0.16-0.2
    assert shaped_like(scene.samples, RATE, heard, finds, limit=0.12) == [captures[-1]]
    # a voice's shapes in fewer heard triggers do not stand for the word: all are kept
    assert shaped_like(scene.samples, RATE, heard[1:], finds, limit=0.12) == finds


def test_the_detector_drops_the_raptures_its_search_took_in_a_clear_session(
        tmp_path: Path) -> None:
    # a 10 dB session (seed 115): the similarity search matched two raptures to the
    # triggers heard, as closely as the triggers match each other
    path = tmp_path / "audio.ogg"
    truth = render_audio(plan_session(SynthOptions(duration=120, seed=115, snr_db=10.0)),
                         path)
    words = PocketsphinxBackend().words(load_audio(path, rate=RATE), TriggerSpec(("capture",)))
    found = [w.t for w in words if w.word == "capture"]

    def said(spans: list[dict]) -> int:
        return sum(any(s["start_s"] - 0.1 <= t <= s["end_s"] + 0.1 for s in spans)
                   for t in found)

    raptures = [d for d in truth.distractors if d["text"] == "rapture"]
    assert len(raptures) == 3
    assert said(raptures) == 0
    assert said(truth.triggers) == len(truth.triggers) == len(found)
