"""Same-speaker similarity: found triggers lead to the ones the recogniser missed."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import numpy as np
from speech_scenes import Scene, clip, make_scene, run_together

from speechcal_core.speech import Word, self_similarity
from speechcal_core.speech.features import mfcc, normalize
from speechcal_core.speech.query_by_example import unit_rows
from speechcal_core.speech.self_similarity import confirm_and_expand, expand_by_similarity
from speechcal_core.speech.vad import voice_activity


def expand_from_first(scene: Scene, n_seeds: int) -> list[Word]:
    """What the similarity search adds to the scene's first ``n_seeds`` triggers."""
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx")
             for a, b in scene.spans("capture")[:n_seeds]]
    activity = voice_activity(scene.samples, 16000)
    return expand_by_similarity(scene.samples, 16000, seeds, activity, blocked=[])


def test_two_found_instances_lead_to_the_missed_ones_only(tmp_path: Path) -> None:
    items = [("capture", "rms/capture_1"), ("okay", "rms/okay_1"),
             ("capture", "rms/capture_2"), ("picture", "rms/picture_1"),
             ("capture", "rms/capture_3"), ("hold on", "rms/hold_on_1"),
             ("capture", "rms/capture_5")]
    scene = make_scene(tmp_path / "rms.wav", items, snr_db=12.0, seed=7)
    spans = scene.spans("capture")
    extra = expand_from_first(scene, 2)
    missed = [(a + b) / 2 for a, b in spans[2:]]
    assert len(extra) == 2
    assert all(min(abs(w.t - t) for t in missed) < 0.05 for w in extra)
    assert all(w.word == "capture" and w.source.endswith("similarity") for w in extra)


def test_posteriorgrams_lead_to_the_missed_instances_in_noise(tmp_path: Path) -> None:
    items = [("capture", "awb/capture_1"), ("okay", "awb/okay_1"),
             ("capture", "awb/capture_2"), ("capsule", "awb/capsule_1"),
             ("capture", "awb/capture_3"), ("hold on", "awb/hold_on_1"),
             ("capture", "awb/capture_4", -4.0), ("captain", "awb/captain_1"),
             ("capture", "awb/capture_5", -4.0)]
    scene = make_scene(tmp_path / "awb.wav", items, snr_db=6.0, seed=0)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:3]]
    activity = voice_activity(scene.samples, 16000)
    kept, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                     factor=1.3, search="posteriorgram")
    assert kept == seeds
    missed = [(a + b) / 2 for a, b in spans[3:]]
    assert [round(w.t - t, 1) for w, t in zip(extra, missed, strict=True)] == [0.0, 0.0]


def test_a_single_seed_is_not_enough_to_judge_similarity(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "one.wav", [("capture", "rms/capture_1"),
                                              ("capture", "rms/capture_2")])
    a, b = scene.spans("capture")[0]
    activity = voice_activity(scene.samples, 16000)
    assert expand_by_similarity(scene.samples, 16000, [Word("capture", a, b)], activity,
                                blocked=[]) == []


def test_seeds_in_two_voices_heard_once_each_lead_to_no_search(tmp_path: Path) -> None:
    items = [("capture", "awb/capture_1"), ("okay", "slt/okay_1"),
             ("capture", "kal16/capture_2"), ("rapture", "slt/rapture_1"),
             ("picture", "rms/picture_1"), ("hold on", "awb/hold_on_1")]
    scene = make_scene(tmp_path / "two.wav", items, snr_db=20.0, seed=5)
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in scene.spans("capture")]
    activity = voice_activity(scene.samples, 16000)
    assert expand_by_similarity(scene.samples, 16000, seeds, activity, blocked=[]) == []
    # the same seeds in one voice do search, and find its third instance
    items[2] = ("capture", "awb/capture_2")
    scene = make_scene(tmp_path / "one.wav", [*items, ("capture", "awb/capture_3")],
                       snr_db=20.0, seed=5)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:2]]
    extra = expand_by_similarity(scene.samples, 16000, seeds,
                                 voice_activity(scene.samples, 16000), blocked=[])
    assert [round(w.t - sum(spans[2]) / 2, 1) for w in extra] == [0.0]


def seeds_with_near_homophones(tmp_path: Path) -> tuple[Scene, list[Word], list[Word]]:
    """A scene of one voice's "capture"s among a "rapture", a "capsule" and a "picture",
    all of them as seeds, and the true ones."""
    items = [("capture", "rms/capture_1"), ("rapture", "rms/rapture_1"),
             ("capture", "rms/capture_2"), ("capture", "rms/capture_3"),
             ("capsule", "rms/capsule_1"), ("capture", "rms/capture_5"),
             ("capture", "rms/capture_1"), ("capture", "rms/capture_3"),
             ("picture", "rms/picture_1"), ("capture", "rms/capture_2")]
    scene = make_scene(tmp_path / "verify.wav", items, snr_db=15.0, seed=3)
    true_seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in scene.spans("capture")]
    false_seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for text, a, b in scene.placed
                   if text != "capture"]
    return scene, sorted(true_seeds + false_seeds, key=lambda w: w.start_s), true_seeds


def test_a_seed_unlike_the_other_seeds_is_dropped_the_real_ones_stay(tmp_path: Path) -> None:
    scene, seeds, true_seeds = seeds_with_near_homophones(tmp_path)
    activity = voice_activity(scene.samples, 16000)
    kept, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                     noise_floor=3.0)
    kept_spans = {(w.start_s, w.end_s) for w in kept}
    assert {(w.start_s, w.end_s) for w in true_seeds} <= kept_spans
    assert scene.spans("capsule")[0] not in kept_spans
    assert extra == []
    kept_all, _ = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                     verify=None, noise_floor=3.0)
    assert len(kept_all) == len(seeds)
    only_capsule = [(s.start_s, s.end_s) == scene.spans("capsule")[0] for s in seeds]
    kept_some, _ = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                      noise_floor=3.0, checked=only_capsule)
    assert [w for w in seeds if w not in kept_some] == [seeds[only_capsule.index(True)]]


def test_a_second_opinion_keeps_the_dropped_seeds_it_vouches_for(tmp_path: Path) -> None:
    # the seed check asks about the seeds it would drop, and keeps those the second
    # opinion returns (the backend's: still heard with a cheaper filler)
    scene, seeds, true_seeds = seeds_with_near_homophones(tmp_path)
    activity = voice_activity(scene.samples, 16000)
    capsule = next(w for w in seeds if (w.start_s, w.end_s) == scene.spans("capsule")[0])
    asked: list[Word] = []

    def vouch_for_capsule(doubted: list[Word]) -> list[Word]:
        asked.extend(doubted)
        return [w for w in doubted if w == capsule]

    kept, _ = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                 noise_floor=3.0, second_opinion=vouch_for_capsule)
    assert capsule in asked
    assert not set(asked) & set(true_seeds)
    assert capsule in kept
    assert set(true_seeds) <= set(kept)
    assert [w for w in seeds if w not in kept] == [w for w in asked if w != capsule]


def test_noise_floored_features_bring_noisy_and_clean_instances_closer() -> None:
    word = clip("slt/capture_2")
    word = word / np.sqrt(np.mean(word**2)) * 0.1
    rng = np.random.default_rng(5)
    noisy = word + rng.standard_normal(word.size).astype(np.float32) * 0.1 / 10 ** (6 / 20)

    def distance(floor: float) -> float:
        a = normalize(mfcc(word, 16000, noise_floor=floor))
        b = normalize(mfcc(noisy, 16000, noise_floor=floor))
        return float(np.mean(1.0 - np.sum(unit_rows(a) * unit_rows(b), axis=1)))

    assert distance(3.0) < distance(0.0)


def test_a_quieter_instance_may_cost_more_than_the_seeds_cost_each_other(
        tmp_path: Path) -> None:
    items = [("capture", "rms/capture_1"), ("okay", "rms/okay_1"),
             ("capture", "rms/capture_2"), ("picture", "rms/picture_1"),
             ("capture", "rms/capture_1"), ("hold on", "rms/hold_on_1"),
             ("capture", "rms/capture_2", -8.0), ("rapture", "rms/rapture_1")]
    scene = make_scene(tmp_path / "quiet.wav", items, snr_db=12.0, seed=4)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:3]]
    activity = voice_activity(scene.samples, 16000)

    def found(level_slope: float) -> list[float]:
        extra = expand_by_similarity(scene.samples, 16000, seeds, activity, blocked=[],
                                     factor=1.0, level_slope=level_slope)
        return [w.t for w in extra]

    assert found(0.0) == []  # 8 dB quieter: noise makes it cost more than the limit
    quiet = (spans[3][0] + spans[3][1]) / 2
    assert [round(t - quiet, 1) for t in found(0.05)] == [0.0]  # not rapture nor picture


#: one voice: four captures (the last the same take as the first) among two raptures
RAPTURE_SCENE = [("capture", "rms/capture_1"), ("okay", "rms/okay_1"),
                 ("capture", "rms/capture_2"), ("rapture", "rms/rapture_1"),
                 ("capture", "rms/capture_3"), ("hold on", "rms/hold_on_1"),
                 ("capture", "rms/capture_1"), ("rapture", "rms/rapture_2")]


def test_a_span_heard_as_a_near_homophone_needs_a_much_closer_match(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "rapture.wav", RAPTURE_SCENE, snr_db=10.0, seed=0)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:3]]
    activity = voice_activity(scene.samples, 16000)
    # the recogniser heard "rapture" in both raptures and in the last capture
    heard = [Word("rapture", a, b, 0.8, "pocketsphinx")
             for a, b in [*scene.spans("rapture"), spans[3]]]

    def found(contested: list[Word]) -> list[float]:
        _, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                      factor=1.6, verify=None, contested=contested)
        return [w.t for w in extra]

    def near(found_t: list[float], said: list[float]) -> bool:
        return len(found_t) == len(said) and all(
            abs(f - t) < 0.05 for f, t in zip(found_t, sorted(said), strict=True))

    raptures = [(a + b) / 2 for a, b in scene.spans("rapture")]
    capture = (spans[3][0] + spans[3][1]) / 2
    assert near(found([]), [*raptures, capture])  # a loose limit takes the raptures
    assert near(found(heard), [capture])  # the same take as a seed matches closely enough


def test_a_match_at_the_start_of_longer_speech_is_no_trigger(tmp_path: Path) -> None:
    # "capture" said straight into "higher": the template matches its start, but the sound
    # runs on without a pause, as in "captured it?"; the same take said alone is found
    items = [("capture", "rms/capture_1"), ("capture", "rms/capture_2"),
             ("capture", "rms/capture_3"),
             ("capture higher", run_together("rms/capture_2", "rms/higher_1")),
             ("capture", "rms/capture_2")]
    scene = make_scene(tmp_path / "run_on.wav", items, snr_db=12.0, seed=1)
    spans = scene.spans("capture")
    extra = expand_from_first(scene, 3)
    alone = (spans[3][0] + spans[3][1]) / 2
    assert [round(w.t - alone, 1) for w in extra] == [0.0]


def test_a_span_heard_clearly_needs_a_closer_match(tmp_path: Path) -> None:
    """Where the recogniser heard clearly and heard no trigger, only a close match is
    taken (CLEAR_SHARE): the same take as a seed, not the raptures a loose limit takes."""
    scene = make_scene(tmp_path / "clear.wav", RAPTURE_SCENE, snr_db=10.0, seed=0)
    spans = scene.spans("capture")
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in spans[:3]]
    activity = voice_activity(scene.samples, 16000)

    def found(clear_from_db: float) -> list[float]:
        _, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                      factor=1.6, verify=None, clear_from_db=clear_from_db)
        return [round(w.t, 1) for w in extra]

    capture = round((spans[3][0] + spans[3][1]) / 2, 1)
    assert len(found(float("inf"))) == 3  # nothing counts as clear: the raptures too
    assert found(float("-inf")) == [capture]  # everything clear: the close match only


TWO_VOICES = [("record", "rms/record_1"), ("okay", "rms/okay_1"), ("record", "rms/record_2"),
              ("record", "slt/record_1"), ("recorder", "rms/recorder_1"),
              ("record", "rms/record_3"), ("record", "slt/record_2"),
              ("hold on", "slt/hold_on_1"), ("record", "rms/record_4"),
              ("record", "slt/record_3"), ("recorder", "slt/recorder_1"),
              ("record", "slt/record_4")]


def test_a_clear_match_of_a_far_flung_seed_is_measured_more_loosely(tmp_path: Path,
                                                                     monkeypatch) -> None:
    """Two voices, clearly heard, six records found: a seed whose closest sibling is
    further than the seeds' median (its voice's takes differ more) has its matches taken
    at up to CLEAR_VOICE_BOOST times the clear share; the recorders stay out."""
    scene = make_scene(tmp_path / "two_voices.wav", TWO_VOICES, snr_db=20.0, seed=3)
    spans = scene.spans("record")
    seeds = [Word("record", a, b, 0.9, "pocketsphinx") for a, b in spans[:6]]
    activity = voice_activity(scene.samples, 16000)

    def found() -> list[float]:
        _, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                      factor=1.1, verify=None, clear_from_db=-np.inf)
        return [round(w.t, 1) for w in extra]

    missed = [round((a + b) / 2, 1) for a, b in spans[6:]]
    assert self_similarity.CLEAR_VOICE_BOOST > 1.0
    assert [abs(t - m) <= 0.1 for t, m in zip(found(), missed, strict=True)] == [True, True]
    monkeypatch.setattr(self_similarity, "CLEAR_VOICE_BOOST", 1.0)
    assert found() == missed[1:]  # one limit for both voices: the rms take is lost


def test_finds_in_a_door_bangs_echo_neither_overlap_nor_squeeze_the_word(
        tmp_path: Path) -> None:
    # a 12 s session: two triggers, a "captain", and a door bang at 11.3 s. The search
    # matched its echo twice with a 0.42 s template: in 0.09 s (the template squeezed by
    # vertical DTW steps) and in 0.19 s, whose sound reached into the first find
    from speechcal_core.audio import load_audio
    from speechcal_core.speech import TriggerSpec
    from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend
    from speechcal_core.synth.audio import render_audio
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.timeline import plan_session

    path = tmp_path / "audio.ogg"
    truth = render_audio(plan_session(SynthOptions(duration=12.0, triggers=2, cameras=1,
                                                   seed=0)), path)
    assert [e["kind"] for e in truth.events] == ["door"]
    words = PocketsphinxBackend(workers=1).words(load_audio(path, rate=16000),
                                                 TriggerSpec(("capture",)))
    spans = sorted((w.start_s, w.end_s) for w in words)
    assert all(b <= c for (_, b), (c, _) in pairwise(spans))
    truth_t = [(t["start_s"] + t["end_s"]) / 2 for t in truth.triggers]
    assert all(any(abs(w.t - t) < 0.1 for w in words) for t in truth_t)
    assert len([w for w in words if w.source.endswith("similarity")]) <= 1


def test_a_span_heard_as_an_inflection_that_finds_its_voice_is_taken_with_it(
        tmp_path: Path) -> None:
    """A voice whose triggers the recogniser hears as "captured" has no seed, and the
    other voice's seeds do not find it. One of its spans said on its own, searched with,
    finds the others it sounds like; with two or more found it is taken with them. One
    that finds fewer is not (an operator may say "captured", and repeat it)."""
    items = [("capture", "rms/capture_1"), ("capture", "slt/capture_1"),
             ("capture", "rms/capture_2"), ("okay", "slt/okay_1"),
             ("capture", "slt/capture_2"), ("capture", "rms/capture_3"),
             ("hold on", "rms/hold_on_1"), ("capture", "slt/capture_3"),
             ("picture", "slt/picture_1"), ("capture", "slt/capture_4"),
             ("capture", "slt/capture_5")]
    scene = make_scene(tmp_path / "voices.wav", items, snr_db=12.0, seed=3)
    spans = scene.spans("capture")
    rms, slt = [spans[0], spans[2], spans[4]], [spans[1], spans[3], spans[5], spans[6]]
    seeds = [Word("capture", a, b, 0.9, "pocketsphinx") for a, b in rms]
    activity = voice_activity(scene.samples, 16000)

    def search(heard_as_captured: tuple[float, float]) -> list[Word]:
        inflected = [Word("captured", *heard_as_captured, 0.5, "pocketsphinx")]
        _, extra = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[],
                                      inflected=inflected)
        return extra

    _, without = confirm_and_expand(scene.samples, 16000, seeds, activity, blocked=[])
    assert without == []
    found = search(slt[2])
    assert [round(w.t - (a + b) / 2, 1) for w, (a, b) in zip(found, slt, strict=True)] \
        == [0.0] * 4
    assert all(w.word == "capture" and w.source.endswith("similarity") for w in found)
    assert search(slt[0]) == []  # it finds fewer than two like it
    assert search(scene.spans("okay")[0]) == []
