"""The audio clap detector: sub-millisecond onset, claps ranked above plosives and bangs."""

from __future__ import annotations

import numpy as np
import pytest
from clap_signals import clap, door_bang, plosive_word, scene

from speechcal_core.audio import Audio
from speechcal_core.sync.clap_audio import audio_levels, find_audio_claps


@pytest.mark.parametrize("rate", [8000, 16000, 44100, 96000])
@pytest.mark.parametrize("seed", [0, 1])
def test_clap_beats_plosives_and_door_bang(rate: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    t_clap = 2.0
    events = [(1.0, plosive_word(rate, rng)), (t_clap - 0.3, plosive_word(rate, rng)),
              (t_clap, clap(rate, rng)), (3.0, door_bang(rate, rng)),
              (4.0, plosive_word(rate, rng))]
    x = scene(rate, 5.0, events, noise_db=-45, seed=seed)
    cands = find_audio_claps(Audio(x, rate))
    best = cands[0]
    assert best.is_clap
    # at 8 kHz a clap landing on the tail of a loud vowel is timed to ~2 ms only
    assert abs(best.time_s - t_clap) < (0.0005 if rate >= 16000 else 0.002)
    assert all(not c.is_clap for c in cands[1:])


def test_clap_right_after_speech_is_found() -> None:
    rate, rng = 16000, np.random.default_rng(3)
    events = [(0.9, plosive_word(rate, rng, amp=0.6)), (1.2, clap(rate, rng, amp=0.4))]
    cands = find_audio_claps(Audio(scene(rate, 3.0, events, seed=3), rate))
    assert cands[0].is_clap and abs(cands[0].time_s - 1.2) < 0.0005


def test_two_claps_both_rank_as_claps() -> None:
    rate, rng = 16000, np.random.default_rng(4)
    events = [(1.0, clap(rate, rng)), (2.5, door_bang(rate, rng)), (8.0, clap(rate, rng, 0.3))]
    cands = find_audio_claps(Audio(scene(rate, 9.0, events, seed=4), rate))
    claps = sorted(c.time_s for c in cands if c.is_clap)
    assert len(claps) == 2
    assert abs(claps[0] - 1.0) < 5e-4 and abs(claps[1] - 8.0) < 5e-4


def test_clipped_clap_is_flagged_and_still_timed() -> None:
    rate, rng = 48000, np.random.default_rng(5)
    x = scene(rate, 3.0, [(1.5, clap(rate, rng, amp=4.0))], noise_db=-40, seed=5)
    x = np.clip(x, -1.0, 1.0)
    a = Audio(x, rate)
    assert audio_levels(a).clipped
    best = find_audio_claps(a)[0]
    assert best.clipped and abs(best.time_s - 1.5) < 0.0005


def test_silence_has_no_candidates() -> None:
    a = Audio(np.zeros(16000 * 3, np.float32), 16000)
    assert audio_levels(a).silent
    assert find_audio_claps(a) == []
    noise = scene(16000, 3.0, [], noise_db=-30)
    assert not any(c.is_clap for c in find_audio_claps(Audio(noise, 16000)))
