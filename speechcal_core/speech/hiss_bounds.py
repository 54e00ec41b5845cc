"""A word's bounds out to its hiss: the speech band the bounds are measured in misses most
of an opening "s" and a closing "z", which lie in a band up to 7.5 kHz."""

from __future__ import annotations

import math

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.span_decoding import RATE
from speechcal_core.speech.timing import FRICATIVE_BAND_HZ, word_bounds
from speechcal_core.speech.vad import HOP_S as VAD_HOP_S
from speechcal_core.speech.vad import VoiceActivity, band_energy_db, noise_floor_db

#: phones whose hiss lies mostly above the speech band the bounds are measured in
FRICATIVES = frozenset({"S", "SH", "Z", "ZH", "F", "TH", "V", "DH"})
#: how much later than the speech band's offset a closing fricative may end: a "z" after
#: a voiced stop lasts up to about 200 ms
MAX_HISS_AFTER_S = 0.25
#: a hiss that moves the offset less than this is taken as hidden in noise
HISS_HEARD_S = 0.05
FLOOR_AROUND_S = 4.0  # the noise floor of a band is measured this far either side


def hiss_bounds(x: np.ndarray, activity: VoiceActivity, words: list[Word],
                heard_ends: dict[Word, float], hiss_first: set[str], hiss_last: set[str]
                ) -> list[Word]:
    """``words``, those of a trigger opening with a fricative (``hiss_first``) started at
    its hiss and those closing with one (``hiss_last``) ended at its hiss; where noise
    hides that hiss, at the recogniser's end (``heard_ends``), or for words the similarity
    search found, as far past their speech-band end as the recognised ones' ends lay past
    theirs."""
    tails: dict[str, float] = {}  # per trigger: how far the recognised ends lay past
    for word in hiss_last:
        past = [end - w.end_s for w, end in heard_ends.items() if w.word == word]
        if past:
            tails[word] = float(np.clip(np.median(past), 0.0, MAX_HISS_AFTER_S))
    out = []
    for w in words:
        if w.word in hiss_first:
            w = _hiss_onset(x, activity, w)
        if w.word in hiss_last:
            heard = heard_ends.get(w, w.end_s + tails.get(w.word, 0.0))
            w = _hiss_offset(x, activity, w, min(heard, w.end_s + MAX_HISS_AFTER_S))
        out.append(w)
    return out


def _hiss_onset(x: np.ndarray, activity: VoiceActivity, word: Word) -> Word:
    """``word`` starting where its energy starts in FRICATIVE_BAND_HZ, if that is earlier:
    the speech band misses most of an opening "s". Reported words only (the similarity
    templates and the runs-on check keep the speech band's bounds). Seeds 1-3, "snapshot"
    median |t - truth| 20 / 10 / 5 dB: 24 / 44 / 53 ms -> 8 / 17 / 42 ms, the same words
    found; "capture" (a /k/) measured this way came out 1 ms later, so only words opening
    with a fricative take it. A hiss still loud where the search for it begins is the
    fricative itself, not speech before the word, so the onset goes that far back
    (keeping the recognised start: "snapshot" at 10 dB, median 15.5 -> 16.7 ms)."""
    bounds = word_bounds(x, RATE, word.start_s, word.end_s, activity.floor_at(word.t),
                         FRICATIVE_BAND_HZ, runs_in_keeps_start=False)
    if bounds.start_s >= word.start_s:
        return word
    return Word(word.word, bounds.start_s, word.end_s, word.score, word.source)


def _hiss_offset(x: np.ndarray, activity: VoiceActivity, word: Word,
                 hidden_end_s: float) -> Word:
    """``word`` ending where its energy ends in FRICATIVE_BAND_HZ, if that is later (at
    most MAX_HISS_AFTER_S later): the speech band misses most of a closing "z" or "s", and
    a voiced stop before it ("b" of "clubs") looks like the word's end. Where no hiss
    shows (noise hides it), the word ends at ``hidden_end_s`` instead, if later. Real
    speech (``../shared/speech-real``), "clubs" against its bounds marked by hand on the
    spectrograms: |t - marked| 18-98 ms -> 7-17 ms; in room noise at 5 dB
    (``bench_real_speech``) median 67.5 -> 13.0 ms."""
    bounds = word_bounds(x, RATE, word.start_s, word.end_s,
                         _band_floor(x, word.t, FRICATIVE_BAND_HZ), FRICATIVE_BAND_HZ,
                         after_s=MAX_HISS_AFTER_S)
    end = bounds.end_s if bounds.end_s >= word.end_s + HISS_HEARD_S else hidden_end_s
    if end <= word.end_s:
        return word
    return Word(word.word, word.start_s, end, word.score, word.source)


def _band_floor(x: np.ndarray, t_s: float, band_hz: tuple[float, float]) -> float:
    """The noise floor (dB) in ``band_hz`` at ``t_s``, from the audio around it: the
    voice activity's floor is the speech band's, and noise with much hiss in it stands
    higher above that in a wider band (a word's hiss then ran on into the noise)."""
    a = max(0, int((t_s - FLOOR_AROUND_S) * RATE))
    b = min(x.size, int((t_s + FLOOR_AROUND_S) * RATE))
    floor = noise_floor_db(band_energy_db(x[a:b], RATE, band_hz))
    if floor.size == 0:
        return -math.inf
    return float(floor[min(floor.size - 1, max(0, int((t_s - a / RATE) / VAD_HOP_S)))])
