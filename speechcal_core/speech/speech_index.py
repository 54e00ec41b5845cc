"""A recording prepared for similarity searches: voice activity and the normalised
features of its voice-active frames, computed once and shared by every search."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal, Protocol

import numpy as np

from speechcal_core.speech.features import HOP_S, mfcc
from speechcal_core.speech.posteriorgram import gaussian_posteriorgram
from speechcal_core.speech.query_by_example import unit_rows
from speechcal_core.speech.vad import VoiceActivity, voice_activity

#: mel noise floor added before the log (see ``features.mfcc``): noisy near-homophones
#: look less like the triggers. With the backend's wider limit, tuning seeds 101-112 at
#: 5 and 10 dB gained 2-3 points of recall at about the same precision (1-2 points more
#: precision at the old limit)
NOISE_FLOOR = 3.0

#: what a frame row holds: normalised MFCCs, or their Gaussian posteriorgram (see
#: ``posteriorgram``: compares instances said by other voices or in more noise better)
Representation = Literal["mfcc", "posteriorgram"]


class Samples(Protocol):
    """What the searches read of the samples: the length and short slices ``x[a:b]``
    (a numpy array, or :class:`~speechcal_core.audio.file_samples.FileSamples` reading
    them back from the file)."""

    @property
    def size(self) -> int: ...

    def __getitem__(self, key: slice) -> np.ndarray: ...


@dataclass(frozen=True)
class SpeechIndex:
    """Samples, voice activity and features of the voice-active frames, each row scaled
    to unit length after normalising over those frames (cosine distance in the DTW)."""

    samples: Samples
    rate: int
    activity: VoiceActivity
    frames: np.ndarray  # indices (10 ms frames) of the voice-active frames
    seq: np.ndarray  # their unit-length features, one row per entry of ``frames``
    n_frames: int  # 10 ms frames of the whole recording, voice-active or not

    @classmethod
    def build(cls, samples: np.ndarray, rate: int, activity: VoiceActivity | None = None,
              noise_floor: float = NOISE_FLOOR,
              representation: Representation = "mfcc") -> SpeechIndex:
        """Index ``samples`` (a 200 s file: about 0.2 s, 0.5 s as a posteriorgram);
        ``activity`` if already known."""
        if activity is None:
            activity = voice_activity(samples, rate)
        feats = mfcc(samples, rate, noise_floor=noise_floor)
        mask = np.zeros(feats.shape[0], dtype=bool)
        for s0, s1 in activity.segments:
            mask[int(s0 / HOP_S):int(np.ceil(s1 / HOP_S))] = True
        frames = np.flatnonzero(mask)
        sel = feats[frames]
        normalised = (sel - sel.mean(axis=0)) / (sel.std(axis=0) + 1e-6) if frames.size \
            else sel
        if representation == "posteriorgram":
            seq = gaussian_posteriorgram(normalised)
        else:
            seq = unit_rows(normalised).astype(np.float32)
        return cls(samples, rate, activity, frames, seq, feats.shape[0])

    def with_samples(self, samples: Samples) -> SpeechIndex:
        """This index reading its samples from ``samples`` (same length and values), e.g.
        from the file instead of an array of the whole recording."""
        if samples.size != self.samples.size:
            raise ValueError(f"{samples.size} samples given for an index of "
                             f"{self.samples.size}")
        return replace(self, samples=samples)

    @property
    def duration_s(self) -> float:
        return self.samples.size / self.rate

    def span(self, start_s: float, end_s: float) -> np.ndarray:
        """Feature rows of ``start_s``..``end_s`` (a template), one per 10 ms frame:
        zeros where no voice is active."""
        a = max(0, int(start_s / HOP_S))
        b = min(self.n_frames, int(end_s / HOP_S))
        rows = np.zeros((max(0, b - a), self.seq.shape[1]), dtype=np.float32)
        i, j = np.searchsorted(self.frames, [a, b])
        rows[self.frames[i:j] - a] = self.seq[i:j]
        return rows
