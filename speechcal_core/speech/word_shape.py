"""How a word's voiced sound unfolds in time: a check the similarity search cannot make.

The search's DTW warps time freely, so it does not measure how long a word's parts last.
Near-homophones differ there: "rapture" is voiced from its first sound, "capture" only
after the burst of its /k/, and "picture"'s first vowel is short. A word's shape is its
low-band energy (80-1000 Hz, where voicing lies) above that band's noise floor, scaled to
its peak and read at :data:`POINTS` evenly spaced times from :data:`MARGIN_S` before the
word to as long after it (linear time: a word said slower keeps its shape). Two words'
shapes differ by the mean absolute difference of those points.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from speechcal_core.speech.backend import Word
from speechcal_core.speech.vad import HOP_S, band_energy_db, noise_floor_db

VOICED_BAND_HZ = (80.0, 1000.0)
POINTS = 40
MARGIN_S = 0.05
#: a find whose shape differs more than this from every trigger the recogniser heard is
#: dropped. 10 dB (seeds 101-124): 116 of the search's 117 true finds lie within it, 14 of
#: its 19 false ones beyond; at 5 dB 386 of 398 true finds, 20 of 45 false ones
SHAPE_LIMIT = 0.17
#: fewer heard triggers hold too few shapes to stand for every voice's way of saying the
#: word: nothing is dropped. "snapshot" at 5 dB (seeds 1-3), where the recogniser heard 5-9
#: a session, lost 25 of the search's 78 true finds for 4 of its 15 false ones; "capture"
#: at 10 dB has 33-40 a session
MIN_REFERENCES = 12


def voiced_level_db(samples: np.ndarray, rate: int) -> np.ndarray:
    """Low-band energy above its noise floor (dB), per 10 ms frame."""
    energy = band_energy_db(samples, rate, VOICED_BAND_HZ)
    return energy - noise_floor_db(energy)


def word_shape(level_db: np.ndarray, word: Word) -> np.ndarray:
    """The word's shape (:data:`POINTS` values in 0..1) from :func:`voiced_level_db`."""
    at = np.linspace((word.start_s - MARGIN_S) / HOP_S, (word.end_s + MARGIN_S) / HOP_S,
                     POINTS)
    shape = np.clip(np.interp(at, np.arange(level_db.size), level_db), 0.0, None)
    return shape / max(float(shape.max()), 1e-6)


def shaped_like(samples: np.ndarray, rate: int, references: Sequence[Word],
                finds: Sequence[Word], limit: float = SHAPE_LIMIT) -> list[Word]:
    """The ``finds`` whose shape lies within ``limit`` of some reference's; all of them
    where there are fewer than :data:`MIN_REFERENCES` references."""
    if len(references) < MIN_REFERENCES or not finds:
        return list(finds)
    level = voiced_level_db(samples, rate)
    if level.size == 0:
        return list(finds)
    shapes = np.array([word_shape(level, w) for w in references])
    return [w for w in finds
            if float(np.abs(shapes - word_shape(level, w)).mean(axis=1).min()) <= limit]
