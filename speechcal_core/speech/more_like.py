"""Find more like this: spans that sound like one trigger word the operator stands on.

The review's "find more like this" starts from a single instance, often one the operator
added by hand where the recogniser heard nothing, so neither recogniser scores nor other
triggers of that voice are at hand. The word is found in the audio near the trigger time
(:func:`word_near`), becomes a template, and the recording's voice-active frames are
searched with subsequence DTW over the same features as ``self_similarity``.

With one template there is no mutual cost of several seeds to set the limit. Two figures
of the search itself stand in: the cost of the closest other span (usually the same
voice saying the word) times :data:`CLOSEST_FACTOR`, capped at :data:`MEDIAN_RATIO` times
the median cost over all speech frames (when the voice says the word nowhere else the
closest span is another word, and the cap keeps the limit low). As in the detector, a
match whose sound runs on without a pause (the start of "captured it?") is not offered.
Measured on synthetic 120 s sessions at 5 dB SNR (seeds 101-124; one search per voice
from a trigger the detector missed, 22 searches): 57 more of the missed triggers found,
with 15 false hits in all (18 without the run-on check).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
from scipy.ndimage import uniform_filter1d

from speechcal_core.speech.backend import Word
from speechcal_core.speech.features import HOP_S
from speechcal_core.speech.query_by_example import subsequence_dtw
from speechcal_core.speech.self_similarity import fits_template
from speechcal_core.speech.speech_index import SpeechIndex
from speechcal_core.speech.timing import word_bounds
from speechcal_core.speech.vad import VoiceActivity

RATE = 16000
#: a frame belongs to a word this far above the noise floor (band energy, smoothed)
WORD_MARGIN_DB = 2.5
WORD_SMOOTH_FRAMES = 9  # moving average over 90 ms: noise does not split the word
WORD_GAP_S = 0.25  # quieter stretches this short stay inside the word ("cap-ture")
WORD_REACH_S = 0.35  # the word may start or end this far from the trigger time
MIN_WORD_S = 0.1
MAX_WORD_S = 0.9  # a longer loud stretch is cut to this around the trigger time
#: accepted cost: this times the closest other span's cost ...
CLOSEST_FACTOR = 1.3
#: ... but at most this times the median cost over all speech frames
MEDIAN_RATIO = 0.75
#: templates shorter than this many frames compare nothing
MIN_TEMPLATE_FRAMES = 5


def word_near(activity: VoiceActivity, t_s: float) -> tuple[float, float] | None:
    """Start and end (audio seconds) of the spoken word at or next to ``t_s``.

    The loud stretch of band energy (above the noise floor, short dips bridged) that holds
    ``t_s`` or lies within :data:`WORD_REACH_S` of it; None when there is none (no speech
    near that time). Within 0.1 s of the true bounds for 98 % of the synthetic triggers at
    5 dB SNR, for times up to 0.15 s off the word's middle.
    """
    energy = activity.energy_db
    if energy is None or energy.size == 0:
        return None
    lo = max(0, int((t_s - WORD_REACH_S - 1.5) / HOP_S))
    hi = min(energy.size, int((t_s + WORD_REACH_S + 1.5) / HOP_S))
    if hi - lo < 3:
        return None
    above = energy[lo:hi] - activity.floor_db[lo:hi]
    loud = np.flatnonzero(uniform_filter1d(above, WORD_SMOOTH_FRAMES) > WORD_MARGIN_DB)
    if loud.size == 0:
        return None
    breaks = np.flatnonzero(np.diff(loud) > round(WORD_GAP_S / HOP_S))
    runs = zip(loud[np.r_[0, breaks + 1]], loud[np.r_[breaks, loud.size - 1]], strict=True)
    at = t_s / HOP_S - lo
    best: tuple[float, int, int] | None = None
    for a, b in runs:
        if (b - a + 1) * HOP_S < MIN_WORD_S:
            continue
        distance = 0.0 if a <= at <= b else min(abs(at - a), abs(at - b)) * HOP_S
        if distance <= WORD_REACH_S and (best is None or distance < best[0]):
            best = (distance, int(a), int(b))
    if best is None:
        return None
    start, end = (lo + best[1]) * HOP_S, (lo + best[2] + 1) * HOP_S + 0.015
    if end - start > MAX_WORD_S:
        start = max(start, min(t_s - MAX_WORD_S / 2, end - MAX_WORD_S))
        end = start + MAX_WORD_S
    return float(start), float(end)


def find_more_like(index: SpeechIndex, start_s: float, end_s: float, word: str,
                   blocked: Sequence[tuple[float, float]] = (),
                   source: str = "similar",
                   closest_factor: float = CLOSEST_FACTOR) -> list[Word]:
    """Spans that sound like ``start_s``..``end_s``, in time order.

    Nothing overlapping the example itself or a span of ``blocked`` (the triggers the
    session already has) is returned; each hit's bounds move to its word's energy.
    ``closest_factor`` replaces CLOSEST_FACTOR (a looser or stricter search).
    """
    template = index.span(start_s, end_s)
    if template.shape[0] < MIN_TEMPLATE_FRAMES or index.seq.shape[0] == 0:
        return []
    cost, first = subsequence_dtw(template, index.seq)
    order = np.argsort(cost)
    own = [(start_s, end_s)]
    closest = next((c for _s, _e, c in _spans(index, cost, first, order, len(template),
                                               list(own))), None)
    if closest is None:
        return []
    limit = min(closest_factor * closest, MEDIAN_RATIO * float(np.median(cost)))
    out = []
    taken = [*own, *blocked]
    words = list(taken)  # the example's and the triggers' spans: a hit's bounds keep off them
    for ts, te, c in _spans(index, cost, first, order, len(template), taken):
        if c >= limit:
            break
        bounds = word_bounds(index.samples, index.rate, ts, te,
                             index.activity.floor_at((ts + te) / 2))
        if bounds.runs_on:
            continue  # the template matched the start of a longer word ("captured it?")
        if any(bounds.start_s < b and bounds.end_s > a for a, b in words):
            continue  # its sound reaches into a word already there
        words.append((bounds.start_s, bounds.end_s))
        out.append(Word(word, bounds.start_s, bounds.end_s, float(max(0.0, 1.0 - c / limit)),
                        source))
    return sorted(out, key=lambda w: w.start_s)


def _spans(index: SpeechIndex, cost: np.ndarray, first: np.ndarray, order: np.ndarray,
           length: int, taken: list[tuple[float, float]]
           ) -> Iterator[tuple[float, float, float]]:
    """Non-overlapping matches (start s, end s, cost), cheapest first; ``taken`` grows."""
    for j in order:
        s_frame, e_frame = int(index.frames[first[j]]), int(index.frames[j]) + 1
        if not fits_template(e_frame - s_frame, length):
            continue
        ts, te = s_frame * HOP_S, e_frame * HOP_S
        if any(ts < b and te > a for a, b in taken):
            continue
        taken.append((ts, te))
        yield ts, te, float(cost[j])
