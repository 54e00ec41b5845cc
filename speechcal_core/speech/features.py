"""MFCC features (numpy only) for comparing spoken words by example."""

from __future__ import annotations

import functools

import numpy as np

HOP_S = 0.010
WIN_S = 0.025
N_MELS = 26
N_CEPS = 13
FMIN, FMAX = 200.0, 5000.0  # above room rumble and hum, below the noise-dominated top
CHUNK_FRAMES = 6000
NOISE_PERCENTILE = 30.0  # a band's noise power: this percentile over all frames


def mfcc(samples: np.ndarray, rate: int, noise_floor: float = 0.0) -> np.ndarray:
    """MFCC frames (n_frames x 12, c0 dropped) every 10 ms over 25 ms Hamming windows.

    ``noise_floor`` > 0 adds that many times the recording's noise power per mel band
    (its quiet-frame level) before the log: low-energy detail that the noise would
    overwrite is flattened alike everywhere, so noisy and clean instances compare better.
    """
    hop, win = round(rate * HOP_S), round(rate * WIN_S)
    x = np.asarray(samples, dtype=np.float32)
    if x.size < win:
        return np.zeros((0, N_CEPS - 1), dtype=np.float32)
    x = np.append(x[0], x[1:] - 0.97 * x[:-1]).astype(np.float32)
    n = 1 + (x.size - win) // hop
    nfft = 1 << int(np.ceil(np.log2(win)))
    fb = _mel_filterbank(rate, nfft)
    dct = _dct_matrix()
    window = np.hamming(win).astype(np.float32)
    mel = np.empty((n, N_MELS), dtype=np.float32)
    for a in range(0, n, CHUNK_FRAMES):
        b = min(n, a + CHUNK_FRAMES)
        idx = (np.arange(a, b) * hop)[:, None] + np.arange(win)[None, :]
        power = np.abs(np.fft.rfft(x[idx] * window, nfft, axis=1)) ** 2
        mel[a:b] = power @ fb.T
    if noise_floor > 0.0:
        mel += noise_floor * np.percentile(mel, NOISE_PERCENTILE, axis=0).astype(np.float32)
    return (np.log(mel + 1e-10) @ dct.T)[:, 1:]


def normalize(feats: np.ndarray) -> np.ndarray:
    """Per-utterance cepstral mean and variance normalisation."""
    if feats.shape[0] == 0:
        return feats
    return (feats - feats.mean(axis=0)) / (feats.std(axis=0) + 1e-6)


@functools.lru_cache(maxsize=4)
def _mel_filterbank(rate: int, nfft: int) -> np.ndarray:
    def mel(f: np.ndarray | float) -> np.ndarray:
        return 2595.0 * np.log10(1.0 + np.asarray(f) / 700.0)

    def hz(m: np.ndarray) -> np.ndarray:
        return 700.0 * (10 ** (m / 2595.0) - 1.0)

    edges = hz(np.linspace(mel(FMIN), mel(min(FMAX, rate / 2)), N_MELS + 2))
    freqs = np.fft.rfftfreq(nfft, 1.0 / rate)
    fb = np.zeros((N_MELS, freqs.size), dtype=np.float32)
    for i in range(N_MELS):
        lo, mid, hi = edges[i], edges[i + 1], edges[i + 2]
        fb[i] = np.clip(np.minimum((freqs - lo) / (mid - lo), (hi - freqs) / (hi - mid)), 0, None)
    return fb


@functools.lru_cache(maxsize=1)
def _dct_matrix() -> np.ndarray:
    k = np.arange(N_CEPS)[:, None]
    m = np.arange(N_MELS)[None, :]
    return (np.cos(np.pi * k * (2 * m + 1) / (2 * N_MELS)) * np.sqrt(2.0 / N_MELS)).astype(
        np.float32)
