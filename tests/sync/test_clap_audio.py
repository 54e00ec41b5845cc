"""The audio clap detector: sub-millisecond onset, claps ranked above plosives and bangs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from clap_signals import clap, door_bang, plosive_word, scene

from speechcal_core.audio import Audio, load_audio
from speechcal_core.sync.clap_audio import audio_levels, find_audio_claps
from speechcal_core.synth.audio import RT60_RANGE, SAMPLE_RATE
from speechcal_core.synth.audio import _clap as synth_clap


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


@pytest.mark.parametrize("seed", [1, 3])
def test_claps_through_vorbis_are_timed_past_its_pre_echo(tmp_path: Path, seed: int) -> None:
    """Twelve of the synthetic sessions' claps, written as Ogg Vorbis as their audio is.
    Seed 1: pre-echo a millisecond ahead of one reached 15% of its peak, where the onset
    was read (0.64 ms early); seed 3: one's noisy attack took over a millisecond to reach
    half the peak and was taken for pre-echo (1.86 ms late). Between two claps 37 s
    apart, either is 17-50 ppm of drift."""
    rng = np.random.default_rng(seed)
    times = [1.0 + 1.5 * k + float(rng.uniform(0.0, 1e-3)) for k in range(12)]
    x = 10 ** (-50 / 20) * rng.standard_normal(int(19.5 * SAMPLE_RATE))
    for t0 in times:
        c = 0.5 * synth_clap(rng, t0, float(rng.uniform(*RT60_RANGE)))
        i = math.ceil(t0 * SAMPLE_RATE)
        x[i:i + c.size] += c[: x.size - i]
    path = tmp_path / "claps.ogg"
    sf.write(str(path), x.astype(np.float32), SAMPLE_RATE, format="OGG", subtype="VORBIS")
    found = [c.time_s for c in find_audio_claps(load_audio(str(path)), max_candidates=24)
             if c.is_clap]
    errors_ms = [1e3 * min((f - t for f in found), key=abs) for t in times]
    # the attack's start, lagged a little by the level it is read at: never early
    assert all(0.0 <= e < 0.7 for e in errors_ms), errors_ms
