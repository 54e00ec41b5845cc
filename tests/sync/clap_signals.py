"""Synthetic test sounds: hand claps, speech plosives, door bangs, noise."""

from __future__ import annotations

import numpy as np
from scipy.signal import butter, sosfilt


def clap(rate: int, rng: np.random.Generator, amp: float = 0.5,
         tau_s: float = 0.006) -> np.ndarray:
    """A hand clap: band-passed noise, 0.2 ms attack, exponential decay; onset at sample 0."""
    n = int(rate * 0.12)
    t = np.arange(n) / rate
    env = np.minimum(t / 2e-4, 1.0) * np.exp(-t / tau_s)
    hi = min(6000.0, 0.45 * rate)
    sos = butter(2, [500.0, hi], btype="band", fs=rate, output="sos")
    noise = sosfilt(sos, rng.standard_normal(n))
    x = noise * env
    return (amp * x / np.max(np.abs(x))).astype(np.float32)


def plosive_word(rate: int, rng: np.random.Generator, amp: float = 0.4) -> np.ndarray:
    """A /k/-like burst (3 ms rise) followed by a voiced vowel: speech, not a clap."""
    n_burst, gap, n_vowel = int(rate * 0.02), int(rate * 0.03), int(rate * 0.25)
    t = np.arange(n_burst) / rate
    env = np.minimum(t / 0.004, 1.0) * np.exp(-t / 0.01)
    sos = butter(2, [1000.0, min(3500.0, 0.45 * rate)], btype="band", fs=rate, output="sos")
    burst = sosfilt(sos, rng.standard_normal(n_burst)) * env
    burst = burst / np.max(np.abs(burst))
    tv = np.arange(n_vowel) / rate
    f0 = 120.0 + 10 * np.sin(2 * np.pi * 3 * tv)
    phase = 2 * np.pi * np.cumsum(f0) / rate
    vowel = sum((1.0 / k) * np.sin(k * phase) for k in range(1, 25) if k * 120 < 0.45 * rate)
    vowel = vowel * np.minimum(tv / 0.03, 1.0) * np.minimum((tv[-1] - tv) / 0.05, 1.0)
    vowel = vowel / np.max(np.abs(vowel))
    x = np.concatenate([burst, np.zeros(gap), 0.9 * vowel])
    return (amp * x).astype(np.float32)


def door_bang(rate: int, rng: np.random.Generator, amp: float = 0.7) -> np.ndarray:
    """A door slam: low resonances ringing 100-200 ms plus a small click."""
    n = int(rate * 0.8)
    t = np.arange(n) / rate
    x = np.zeros(n)
    for f, tau in ((70.0, 0.18), (140.0, 0.12), (230.0, 0.08)):
        x += np.sin(2 * np.pi * f * t + rng.uniform(0, 6)) * np.exp(-t / tau)
    x *= np.minimum(t / 0.001, 1.0)
    x += 0.15 * rng.standard_normal(n) * np.exp(-t / 0.002)
    return (amp * x / np.max(np.abs(x))).astype(np.float32)


def scene(rate: int, seconds: float, events: list[tuple[float, np.ndarray]],
          noise_db: float = -50.0, seed: int = 0) -> np.ndarray:
    """Mix ``events`` (start second, sound) into background noise at ``noise_db`` dBFS."""
    rng = np.random.default_rng(seed)
    x = (10 ** (noise_db / 20) * rng.standard_normal(int(rate * seconds))).astype(np.float32)
    for start, sound in events:
        i = round(start * rate)
        k = min(sound.size, x.size - i)
        x[i:i + k] += sound[:k]
    return x
