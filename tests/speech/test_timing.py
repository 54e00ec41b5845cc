"""Word bounds from the energy around a recognised word, and whether its sound runs on."""

from __future__ import annotations

import numpy as np

from speechcal_core.speech.timing import (
    MAX_ONSET_DELAY_S,
    SEARCH_AFTER_S,
    SEARCH_BEFORE_S,
    refine_bounds,
    word_bounds,
)

RATE = 16000


def _bursts(*spans: tuple[float, float], duration_s: float = 3.0) -> np.ndarray:
    """Noise-like bursts at ``spans`` (seconds) over a quiet floor."""
    rng = np.random.default_rng(0)
    x = 0.001 * rng.standard_normal(int(duration_s * RATE))
    for a, b in spans:
        x[int(a * RATE):int(b * RATE)] += 0.1 * rng.standard_normal(int((b - a) * RATE))
    return x.astype(np.float32)


def _floor_db(x: np.ndarray) -> float:
    from speechcal_core.speech.vad import band_energy_db

    return float(np.percentile(band_energy_db(x, RATE), 20))


def test_bounds_move_to_the_energy_and_a_word_ending_in_a_pause_does_not_run_on() -> None:
    x = _bursts((1.0, 1.5), (1.8, 2.2))
    bounds = word_bounds(x, RATE, 1.04, 1.45, _floor_db(x))
    assert abs(bounds.start_s - 1.0) <= 0.03 and abs(bounds.end_s - 1.5) <= 0.03
    assert not bounds.runs_on  # 0.3 s of quiet before the next burst
    assert refine_bounds(x, RATE, 1.04, 1.45, _floor_db(x)) == bounds[:2]


def test_a_quiet_opening_sound_keeps_the_onset_near_the_recognised_start() -> None:
    # a hiss above the speech band ("s" of "snapshot") from 1.0, then the vowel from 1.15:
    # the speech band's energy starts with the vowel, the word with the hiss
    rng = np.random.default_rng(1)
    x = _bursts((1.15, 1.5))
    hiss = rng.standard_normal(int(0.15 * RATE))
    hiss = np.fft.irfft(np.fft.rfft(hiss) * (np.fft.rfftfreq(hiss.size, 1 / RATE) > 4500))
    x[int(1.0 * RATE):int(1.15 * RATE)] += (0.05 * hiss).astype(np.float32)
    bounds = word_bounds(x, RATE, 1.0, 1.5, _floor_db(x))
    assert bounds.start_s == 1.0 + MAX_ONSET_DELAY_S  # not the vowel's 1.15
    assert abs(bounds.end_s - 1.5) <= 0.03


def test_a_word_whose_sound_goes_on_past_the_search_runs_on() -> None:
    x = _bursts((1.0, 2.0))  # the recogniser's word ends at 1.5: more sound follows
    bounds = word_bounds(x, RATE, 1.0, 1.5, _floor_db(x))
    assert bounds.runs_on
    assert bounds.end_s >= 1.5 + SEARCH_AFTER_S
    short_pause = _bursts((1.0, 1.5), (1.53, 2.0))  # a stop closure, not a pause
    assert word_bounds(short_pause, RATE, 1.0, 1.5, _floor_db(short_pause)).runs_on


def test_a_word_followed_by_more_speech_after_a_short_pause_runs_on() -> None:
    """The "it" of "captured it?" after the /d/ closure: a pause longer than a closure but
    shorter than the one ending a phrase, then more speech."""
    x = _bursts((1.0, 1.5), (1.625, 1.875))  # 125 ms of quiet, then "it"
    bounds = word_bounds(x, RATE, 1.0, 1.5, _floor_db(x))
    assert abs(bounds.end_s - 1.5) <= 0.03  # the word itself ends at the pause
    assert bounds.runs_on
    # a short sound after the pause (a click) or a longer pause does not make it run on
    click = _bursts((1.0, 1.5), (1.625, 1.640625))
    assert not word_bounds(click, RATE, 1.0, 1.5, _floor_db(click)).runs_on
    apart = _bursts((1.0, 1.5), (1.75, 2.0))
    assert not word_bounds(apart, RATE, 1.0, 1.5, _floor_db(apart)).runs_on


def test_speech_running_into_the_word_keeps_the_recognised_start() -> None:
    """The "of" before "clubs", with no pause: the sound goes back past the onset search,
    so the onset found there would only be the search's limit, 0.12 s early."""
    x = _bursts((0.6, 1.5))  # the recogniser's word starts at 1.0
    bounds = word_bounds(x, RATE, 1.0, 1.45, _floor_db(x))
    assert bounds.start_s == 1.0
    assert abs(bounds.end_s - 1.5) <= 0.03
    # a fricative's hiss still loud there is the word's own: the onset goes back
    hiss_band = word_bounds(x, RATE, 1.0, 1.45, _floor_db(x), runs_in_keeps_start=False)
    assert hiss_band.start_s <= 1.0 - SEARCH_BEFORE_S
    # a pause before the word: its onset is found as before
    apart = _bursts((0.6, 0.8), (0.96, 1.5))
    assert abs(word_bounds(apart, RATE, 1.0, 1.45, _floor_db(apart)).start_s - 0.96) <= 0.03
