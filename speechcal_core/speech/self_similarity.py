"""Find more instances of a trigger by how much they sound like the ones already found.

An operator repeats the trigger word in one voice, so the instances the recogniser is
sure of serve as templates (query by example without a mark): spans that match a template
about as well as the templates match each other are triggers too. This recovers words the
recogniser loses in noise, where a same-speaker comparison still holds.
"""

from __future__ import annotations

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.features import HOP_S, mfcc
from speechcal_core.speech.query_by_example import subsequence_dtw, unit_rows
from speechcal_core.speech.timing import refine_bounds
from speechcal_core.speech.vad import VoiceActivity

#: a span is accepted when its cost is below this times the seeds' typical mutual cost
COST_FACTOR = 1.1
MIN_SEEDS = 2
SEED_END_TOLERANCE = 10  # frames: where another seed's match may end
MAX_STRETCH = 1.6  # a match may be at most this much longer than its template
ROUNDS = 1  # searches; >1 makes found instances templates too (little gain, more false)


def expand_by_similarity(samples: np.ndarray, rate: int, seeds: list[Word],
                         activity: VoiceActivity, blocked: list[Word],
                         factor: float = COST_FACTOR, rounds: int = ROUNDS) -> list[Word]:
    """New trigger instances similar to ``seeds``; nothing overlapping seeds or ``blocked``.

    The acceptance limit comes from the seeds alone; instances found in one round serve
    as further templates in the next.
    """
    if len(seeds) < MIN_SEEDS or not activity.segments:
        return []
    feats = mfcc(samples, rate)
    mask = np.zeros(feats.shape[0], dtype=bool)
    for s0, s1 in activity.segments:
        mask[int(s0 / HOP_S):int(np.ceil(s1 / HOP_S))] = True
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    sel = feats[idx]
    seq = unit_rows((sel - sel.mean(axis=0)) / (sel.std(axis=0) + 1e-6))
    full = np.zeros((feats.shape[0], seq.shape[1]), dtype=np.float32)
    full[idx] = seq
    best = _BestMatch(idx.size)
    ends = np.searchsorted(idx, [int(s.end_s / HOP_S) for s in seeds])
    mutual = []
    for k, seed in enumerate(seeds):
        cost = best.add(full, seq, seed)
        if cost is None:
            continue
        near = [cost[max(0, e - SEED_END_TOLERANCE):e + SEED_END_TOLERANCE].min()
                for q, e in enumerate(ends) if q != k and e < cost.size]
        if near:
            mutual.append(min(near))
    if not mutual:
        return []
    limit = factor * float(np.median(mutual))
    taken = [(w.start_s, w.end_s) for w in [*seeds, *blocked]]
    out: list[Word] = []
    for _ in range(rounds):
        new = _pick(best, idx, limit, taken, samples, rate, activity, seeds[0].word)
        if not new:
            break
        out += new
        for w in new:
            best.add(full, seq, w)
    return sorted(out, key=lambda w: w.start_s)


class _BestMatch:
    """The lowest DTW cost over all templates at each speech frame, and its match start."""

    def __init__(self, n: int) -> None:
        self.cost = np.full(n, np.inf)
        self.start = np.zeros(n, dtype=np.int64)
        self.length = np.zeros(n, dtype=np.int64)

    def add(self, full: np.ndarray, seq: np.ndarray, word: Word) -> np.ndarray | None:
        """Match one instance as a template; its cost per end frame (None if too short)."""
        template = full[int(word.start_s / HOP_S):int(word.end_s / HOP_S)]
        if template.shape[0] < 5:
            return None
        cost, start = subsequence_dtw(template, seq)
        better = cost < self.cost
        self.cost[better] = cost[better]
        self.start[better] = start[better]
        self.length[better] = template.shape[0]
        return cost


def _pick(best: _BestMatch, idx: np.ndarray, limit: float, taken: list[tuple[float, float]],
          samples: np.ndarray, rate: int, activity: VoiceActivity, word: str) -> list[Word]:
    """Non-overlapping matches below ``limit``, best first; ``taken`` grows with them."""
    out = []
    for j in np.argsort(best.cost):
        c = float(best.cost[j])
        if c >= limit:
            break
        s_frame, e_frame = int(idx[best.start[j]]), int(idx[j]) + 1
        if not 0 < e_frame - s_frame <= MAX_STRETCH * best.length[j]:
            continue
        ts, te = s_frame * HOP_S, e_frame * HOP_S
        if any(ts < b and te > a for a, b in taken):
            continue
        taken.append((ts, te))
        rs, re_ = refine_bounds(samples, rate, ts, te, activity.floor_at((ts + te) / 2))
        out.append(Word(word, rs, re_, max(0.0, 1.0 - c), "pocketsphinx+similarity"))
    return out
