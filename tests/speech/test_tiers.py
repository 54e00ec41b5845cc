"""Decoding tiers: how clearly a span is heard decides which rivals a trigger must beat."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from speech_scenes import Scene, make_scene

from speechcal_core.speech import detect_triggers
from speechcal_core.speech.lexicon import (
    commoner_words_ending_alike,
    confusable_words,
    pronunciations,
)
from speechcal_core.speech.pocketsphinx_backend import (
    POSTERIORGRAM_BELOW_DB,
    POSTERIORGRAM_FACTOR,
    POSTERIORGRAM_LEVEL_SLOPE,
    SIMILARITY_FACTOR,
    _search_for,
)
from speechcal_core.speech.self_similarity import LEVEL_SLOPE
from speechcal_core.speech.spot_grammar import TIERS, tier_index
from speechcal_core.speech.vad import voice_activity


def test_confusables_are_common_words_one_phone_away() -> None:
    assert confusable_words("capture", pronunciations("capture"), {"capture"}) \
        == ["captor", "rapture"]
    near_mark = confusable_words("mark", pronunciations("mark"), {"mark"})
    assert {"park", "dark", "march"} <= set(near_mark)
    assert "market" not in near_mark and "mark" not in near_mark  # longer; the word itself
    assert "marv" not in near_mark  # a hundred times rarer than "mark": hardly said


def test_a_word_the_language_model_does_not_know_keeps_every_common_neighbour() -> None:
    # a user pronunciation for a made-up word: no unigram to compare the neighbours with
    assert "marv" in confusable_words("marq", pronunciations("mark"), {"marq"})


def test_span_level_tracks_how_far_speech_stands_above_the_noise(tmp_path: Path) -> None:
    levels = {}
    for snr in (30.0, 10.0):
        scene = make_scene(tmp_path / f"l{snr:g}.wav", [("capture", "rms/capture_1")],
                           snr_db=snr)
        activity = voice_activity(scene.samples, 16000)
        (a, b), = scene.spans("capture")
        levels[snr] = activity.level_db(a, b)
        assert activity.level_db(0.0, 0.5) < 6.0  # the lead-in is noise only
    assert levels[30.0] > levels[10.0] + 10.0


def test_clear_spans_use_the_first_tier_and_noisy_ones_the_last() -> None:
    assert tier_index(TIERS[0].min_level_db + 5.0) == 0
    assert tier_index(-20.0) == len(TIERS) - 1
    assert TIERS[-1].min_level_db == -np.inf


def test_noisier_spans_weigh_near_homophones_at_a_smaller_prior() -> None:
    priors = [tier.confusable_log10 for tier in TIERS]
    assert all(p is not None for p in priors)  # "rapture" competes in every span
    assert all(p < priors[0] for p in priors[1:])  # noise lets it beat real triggers


def test_a_quiet_span_with_a_loud_moment_is_not_decoded_as_the_noisiest() -> None:
    noisiest, above = len(TIERS) - 1, len(TIERS) - 2
    assert TIERS[-2].min_peak_db is not None
    assert tier_index(TIERS[-2].min_level_db - 3.0) == noisiest
    assert tier_index(TIERS[-2].min_level_db - 3.0, TIERS[-2].min_peak_db - 1.0) == noisiest
    # a short word in a long span: low level, but its loudest moment stands out
    assert tier_index(TIERS[-2].min_level_db - 3.0, TIERS[-2].min_peak_db + 1.0) == above


def test_quietly_heard_triggers_are_searched_for_by_posteriorgram() -> None:
    quiet = [POSTERIORGRAM_BELOW_DB - 3.0, POSTERIORGRAM_BELOW_DB - 1.0, 30.0]
    clear = [POSTERIORGRAM_BELOW_DB + 1.0, POSTERIORGRAM_BELOW_DB + 2.0, 5.0]
    # by the median; a buried span may cost more on posteriorgrams than on MFCCs
    assert _search_for(quiet) == ("posteriorgram", POSTERIORGRAM_FACTOR,
                                  POSTERIORGRAM_LEVEL_SLOPE)
    assert POSTERIORGRAM_LEVEL_SLOPE > LEVEL_SLOPE
    assert _search_for(clear) == ("mfcc", SIMILARITY_FACTOR, None)  # LEVEL_SLOPE
    assert _search_for([]) == ("mfcc", SIMILARITY_FACTOR, None)


def _found(scene: Scene, text: str) -> int:
    result = detect_triggers(scene.path, ["capture"])
    return sum(any(a - 0.1 <= w.t <= b + 0.1 for w in result.triggers)
               for a, b in scene.spans(text))


def test_commoner_words_ending_like_the_trigger_compete_with_it() -> None:
    def alike(word: str, user: dict[str, str] | None = None) -> list[str]:
        return commoner_words_ending_alike(word, pronunciations(word, user), {word})

    assert alike("capture") == ["culture", "picture"]
    # commoner and ending alike, but made of other sounds: "hundred", "whatnot"
    assert alike("record") == [] and alike("snapshot") == []
    assert alike("kaptcha", {"kaptcha": "K AE P CH AH"}) == []  # unknown to the model


def test_picture_is_not_taken_for_capture(tmp_path: Path) -> None:
    """Every voice says "picture" and "capture" in turn; the recogniser took 4 of the 8
    pictures for the trigger at 20 dB before "picture" competed in its grammar."""
    items = [(word, f"{voice}/{word}_{k}") for voice in ("slt", "rms", "awb", "kal16")
             for k in (1, 2) for word in ("picture", "capture")]
    scene = make_scene(tmp_path / "pictures.wav", items, snr_db=20.0, seed=3)
    assert _found(scene, "picture") == 0
    assert _found(scene, "capture") == 8


def test_clearly_heard_rapture_is_not_a_trigger_but_capture_is(tmp_path: Path) -> None:
    scene = make_scene(tmp_path / "rapture.wav",
                       [("rapture", "slt/rapture_1"), ("capture", "slt/capture_2"),
                        ("rapture", "slt/rapture_2"), ("capture", "rms/capture_3")], snr_db=30.0)
    assert _found(scene, "rapture") == 0
    assert _found(scene, "capture") == 2


def test_noisy_spans_still_give_most_triggers(tmp_path: Path) -> None:
    items = [("capture", f"{voice}/capture_{k}") for voice in ("slt", "rms", "awb", "kal16")
             for k in (1, 2, 3)]
    scene = make_scene(tmp_path / "noisy.wav", items, snr_db=10.0)
    activity = voice_activity(scene.samples, 16000)
    levels = [activity.level_db(a, b) for a, b in scene.spans("capture")]
    assert sum(level < TIERS[0].min_level_db for level in levels) >= 8  # mostly the noisy tier
    assert _found(scene, "capture") >= 9
