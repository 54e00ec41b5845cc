"""Query by example: find words that sound like one operator-marked instance (MFCC + DTW).

Works for any language or word, since nothing is recognised: the marked span becomes a
template and every voice-active span is searched with subsequence dynamic time warping.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.errors import SpeechUsageError
from speechcal_core.speech.features import HOP_S, mfcc
from speechcal_core.speech.vad import speech_segments

if TYPE_CHECKING:
    from speechcal_core.audio import Audio
    from speechcal_core.speech.matching import TriggerSpec

RATE = 16000
#: normalised DTW cost (mean cosine distance per template frame) accepted at sensitivity 0/1
COST_LIMITS = (0.15, 0.45)
VERTICAL_PENALTY = 0.1  # cost added when the template stretches over one audio frame


@dataclass(frozen=True)
class Example:
    """One operator-marked instance of the trigger word, in audio seconds."""

    start_s: float
    end_s: float
    word: str = "example"


class QueryByExampleBackend:
    """Words acoustically similar to marked examples; the example's word names each hit."""

    name = "example"

    def __init__(self, examples: list[Example]) -> None:
        if not examples:
            raise SpeechUsageError("query by example needs one marked instance (start and end)")
        self.examples = examples

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        """Hits for every example, strongest first where two overlap."""
        found: list[Word] = []
        for ex in self.examples:
            found.extend(find_similar(audio, ex, sensitivity=spec.sensitivity))
        found.sort(key=lambda w: -w.score)
        kept: list[Word] = []
        for w in found:
            if all(w.end_s <= k.start_s or w.start_s >= k.end_s for k in kept):
                kept.append(w)
        return sorted(kept, key=lambda w: w.start_s)


def find_similar(audio: Audio, example: Example, *, sensitivity: float = 0.5) -> list[Word]:
    """Spans of ``audio`` that match the example span, the example itself included."""
    x = audio.resampled(RATE).samples if audio.rate != RATE else audio.samples
    duration = x.size / RATE
    if not 0.0 <= example.start_s < example.end_s <= duration + 1e-6:
        raise SpeechUsageError(
            f"example {example.start_s:.2f}-{example.end_s:.2f} s lies outside the audio "
            f"(0-{duration:.2f} s); mark the word inside the recording"
        )
    if example.end_s - example.start_s < 0.1:
        raise SpeechUsageError("example is shorter than 0.1 s; mark the whole word")
    feats = mfcc(x, RATE)
    if feats.shape[0] == 0:
        return []
    segments = speech_segments(x, RATE)
    mean, std = _speech_stats(feats, segments)
    unit = unit_rows((feats - mean) / std)
    a = round(example.start_s / HOP_S)
    b = max(a + 1, round(example.end_s / HOP_S))
    template = unit[a:b]
    limit = COST_LIMITS[0] + (COST_LIMITS[1] - COST_LIMITS[0]) * sensitivity
    hits: list[Word] = []
    for s0, s1 in segments:
        f0, f1 = int(s0 / HOP_S), min(unit.shape[0], int(np.ceil(s1 / HOP_S)))
        if f1 - f0 < len(template) // 2:
            continue
        for start, end, cost in _matches(template, unit[f0:f1], limit):
            hits.append(Word(example.word, (f0 + start) * HOP_S, (f0 + end) * HOP_S,
                             float(max(0.0, 1.0 - cost / limit)), "example"))
    return hits


def _speech_stats(feats: np.ndarray, segments: list[tuple[float, float]]
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Mean and spread of the features over voice-active frames (all frames if none)."""
    mask = np.zeros(feats.shape[0], dtype=bool)
    for s0, s1 in segments:
        mask[int(s0 / HOP_S):int(s1 / HOP_S)] = True
    sel = feats[mask] if mask.any() else feats
    return sel.mean(axis=0), sel.std(axis=0) + 1e-6


def unit_rows(m: np.ndarray) -> np.ndarray:
    return m / (np.linalg.norm(m, axis=1, keepdims=True) + 1e-9)


def subsequence_dtw(template: np.ndarray, seq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cost (mean cosine distance per template frame) and start of the best match ending
    at each frame of ``seq``; both arrays have ``len(seq)`` entries."""
    n, m = template.shape[0], seq.shape[0]
    cost = (1.0 - template @ seq.T).astype(np.float32)  # cosine distance, n x m
    d = cost[0].copy()
    start = np.arange(m)
    diag = np.empty_like(d)
    skip = np.empty_like(d)
    s_diag = np.zeros_like(start)
    s_skip = np.zeros_like(start)
    diag[0] = skip[:2] = np.inf
    for i in range(1, n):
        diag[1:] = d[:-1]
        skip[2:] = d[:-2]
        s_diag[1:] = start[:-1]
        s_skip[2:] = start[:-2]
        vert = d + VERTICAL_PENALTY
        take_diag = diag <= skip
        step = np.where(take_diag, diag, skip)
        s_step = np.where(take_diag, s_diag, s_skip)
        take_step = step <= vert
        start = np.where(take_step, s_step, start)
        d = cost[i] + np.where(take_step, step, vert)
    return d / n, start


def _matches(template: np.ndarray, seq: np.ndarray, limit: float) -> list[tuple[int, int, float]]:
    """Non-overlapping (start, end, cost) subsequence matches with cost below ``limit``."""
    n, m = template.shape[0], seq.shape[0]
    norm, start = subsequence_dtw(template, seq)
    out: list[tuple[int, int, float]] = []
    order = np.argsort(norm)
    taken = np.zeros(m, dtype=bool)
    for j in order:
        c = float(norm[j])
        if c >= limit:
            break
        s = int(start[j])
        if taken[s:j + 1].any():
            continue
        taken[max(0, s - n // 2):j + 1 + n // 2] = True
        out.append((s, j + 1, c))
    return sorted(out)
