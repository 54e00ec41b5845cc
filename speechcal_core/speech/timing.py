"""Refine a recognised word's bounds to the audible onset and offset of its energy."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from speechcal_core.speech.vad import BAND_HZ, HOP_S, band_energy_db, frame_count

if TYPE_CHECKING:
    from speechcal_core.speech.speech_index import Samples

SEARCH_BEFORE_S = 0.12  # how far before the recognised start the onset may lie
SEARCH_AFTER_S = 0.15  # how far after the recognised end the offset may lie
#: above the local noise floor counts as the word. At 5 dB a weak opening consonant
#: stays below it (real "clubs": onsets 55-92 ms late). Searching the onset further back
#: on energy smoothed over 30 ms, 2 dB above the floor: real speech median |t - marked|
#: 14.2 -> 12.5 ms at 5 dB (p95 64.6 -> 59.6 ms), but the synthetic sessions' 8.6 -> 10.8
#: ms (20 dB 10.8 -> 14.1 ms): left out
MARGIN_DB = 4.0
PEAK_RANGE_DB = 20.0  # ... and within this range of the word's loudest frame (reverb tails)
GAP_S = 0.06  # a closure this short (the stop in "cap-ture") does not end the word
#: the onset moves at most this much after the recognised start. Recognised starts run
#: 30-40 ms early on reverberant speech, but a word opening with a fricative ("s" of
#: "snapshot") has little energy in the speech band, and the onset jumped 100-190 ms on
#: to its vowel. Seeds 101-106, "snapshot" median |t - truth| 20 dB 58 -> 40 ms, 10 dB
#: 47 -> 43 ms; "capture" figures unchanged (seeds 1-3 and 101-124, 5-20 dB)
MAX_ONSET_DELAY_S = 0.08
#: speech resuming this soon after the offset (from FOLLOW_S[0] to FOLLOW_S[1] after it,
#: in more than FOLLOW_FRACTION of the frames) makes the word part of a phrase too: the
#: "it" of "captured it?" after the closure of its /d/, which noise lengthens past GAP_S.
#: Seeds 101-124, 5 dB: 8 of 10 "captured it?" false alarms have it, 0 of 895 triggers
#: found; false alarms 72 -> 65 (10 dB 52 -> 49, untouched seeds 125-148 5 dB 68 -> 55),
#: no trigger lost but one at 5 dB on seeds 125-148
FOLLOW_S = (0.03, 0.2)
FOLLOW_FRACTION = 0.25
#: the band a word opening with a fricative ("s" of "snapshot") shows its onset in: the
#: speech band (BAND_HZ) stops below most of a hiss's energy
FRICATIVE_BAND_HZ = (300.0, 7500.0)


class WordBounds(NamedTuple):
    """A word's audible bounds (audio seconds) and whether its sound runs on past them."""

    start_s: float
    end_s: float
    #: the energy lasted, with no pause, as far as the search for the offset looked:
    #: the word runs on into more speech, so it may be the start of a longer word or
    #: phrase ("captured it?" heard as "capture")
    runs_on: bool = False


def refine_bounds(samples: Samples, rate: int, start_s: float, end_s: float,
                  floor_db: float) -> tuple[float, float]:
    """Onset and offset of the energy around ``start_s``..``end_s`` above ``floor_db``.

    Keeps the recognised bound when the energy gives no clear answer (too noisy).
    """
    bounds = word_bounds(samples, rate, start_s, end_s, floor_db)
    return bounds.start_s, bounds.end_s


def word_bounds(samples: Samples, rate: int, start_s: float, end_s: float,
                floor_db: float, band_hz: tuple[float, float] = BAND_HZ,
                after_s: float = SEARCH_AFTER_S,
                runs_in_keeps_start: bool = True) -> WordBounds:
    """``refine_bounds`` plus whether the word's energy runs on past the offset search;
    ``band_hz`` is where the energy is measured, ``after_s`` how far after ``end_s`` the
    offset may lie.

    Sound that runs in from before the onset search (SEARCH_BEFORE_S) is speech before
    the word ("of" in "ten of clubs"): with ``runs_in_keeps_start`` the recognised start
    stays, instead of an onset 0.12 s early. Real speech (``bench_real_speech``), 10 dB:
    median |t - marked| 17.4 -> 12.5 ms, p95 62.5 -> 45.0 ms; the synthetic sessions'
    triggers, said on their own, are the same."""
    a = max(0, int((start_s - SEARCH_BEFORE_S - 0.03) * rate))
    b = min(samples.size, int((end_s + after_s + 0.03) * rate))
    # the energy runs on past the bounds search, for what follows the word
    follow = min(samples.size, int((end_s + after_s + FOLLOW_S[1] + 0.03) * rate))
    energy_on = band_energy_db(samples[a:follow], rate, band_hz)
    t_on = a / rate + np.arange(energy_on.size) * HOP_S + 0.0125  # frame centres
    searched = frame_count(b - a, rate)
    energy, t = energy_on[:searched], t_on[:searched]
    if energy.size < 3:
        return WordBounds(start_s, end_s)
    peak = float(np.max(energy))
    threshold = max(floor_db + MARGIN_DB, peak - PEAK_RANGE_DB)
    loud = energy > threshold
    inside = (t >= start_s) & (t <= end_s)
    if not loud[inside].any():
        return WordBounds(start_s, end_s)
    gap = max(1, round(GAP_S / HOP_S))
    first = int(np.flatnonzero(inside & loud)[0])
    last = int(np.flatnonzero(inside & loud)[-1])
    i = first
    while i > 0 and t[i - 1] >= start_s - SEARCH_BEFORE_S and loud[max(0, i - gap):i].any():
        i -= 1
    j = last
    while j < energy.size - 1 and t[j + 1] <= end_s + after_s and \
            loud[j + 1:j + 1 + gap].any():
        j += 1
    offset = float(t[j] + 0.0125)
    onset = min(float(t[i] - 0.0125), start_s + MAX_ONSET_DELAY_S)
    if runs_in_keeps_start and i > 0 and loud[max(0, i - gap):i].any():
        onset = start_s  # the sound ran in from before the search: speech before the word
    # the sound lasted as far as the search looked (no pause ended the word), or more
    # speech follows after a pause too short to end a phrase
    return WordBounds(onset, offset, offset >= end_s + after_s
                      or _speech_follows(energy_on, t_on, offset, threshold))


def _speech_follows(energy: np.ndarray, t: np.ndarray, offset_s: float,
                    threshold_db: float) -> bool:
    """Whether sound above ``threshold_db`` fills more than FOLLOW_FRACTION of the frames
    from FOLLOW_S[0] to FOLLOW_S[1] after ``offset_s``."""
    window = (t >= offset_s + FOLLOW_S[0]) & (t <= offset_s + FOLLOW_S[1])
    return bool(window.any()) and float(np.mean(energy[window] > threshold_db)) > \
        FOLLOW_FRACTION
