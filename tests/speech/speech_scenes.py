"""Helpers for the speech tests: bundled voice clips placed in noise, real speech look-up."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.resources import resource

RATE = 16000
REAL_SPEECH = Path(__file__).resolve().parents[2] / ".." / "shared" / "speech-real"


@dataclass
class Scene:
    """A WAV file of clips in noise, and where each clip was placed (audio seconds)."""

    path: Path
    samples: np.ndarray
    placed: list[tuple[str, float, float]]  # text, start, end

    def spans(self, text: str) -> list[tuple[float, float]]:
        return [(a, b) for t, a, b in self.placed if t == text]


def clip(name: str) -> np.ndarray:
    """A bundled voice clip (16 kHz mono) such as ``"slt/capture_1"``."""
    x, rate = sf.read(str(resource("voices", f"{name}.flac")), dtype="float32")
    assert rate == RATE
    return x


def run_together(first: str, second: str, overlap_s: float = 0.1) -> np.ndarray:
    """Two clips spoken without a pause: the second starts ``overlap_s`` before the first
    ends."""
    a, b = clip(first), clip(second)
    n = int(overlap_s * RATE)
    out = np.concatenate([a, np.zeros(b.size - n, np.float32)])
    out[a.size - n:] += b
    return out


def make_scene(path: Path, items: list[tuple[str, str]] | list[tuple[str, str, float]]
               | list[tuple[str, str | np.ndarray]], *,
               gap_s: float = 0.9, snr_db: float = 25.0, seed: int = 0) -> Scene:
    """Clips ``(text, clip name or samples[, gain dB])`` one after another with ``gap_s``
    between, in pink-ish noise; ``snr_db`` holds for clips at gain 0."""
    rng = np.random.default_rng(seed)
    parts, placed, t = [np.zeros(int(0.8 * RATE), np.float32)], [], 0.8
    for text, name, *gain in items:
        x = clip(name) if isinstance(name, str) else name
        x = x * (0.1 / (np.sqrt(np.mean(x**2)) + 1e-9)) * 10 ** ((gain[0] if gain else 0.0) / 20)
        placed.append((text, t, t + x.size / RATE))
        parts += [x.astype(np.float32), np.zeros(int(gap_s * RATE), np.float32)]
        t += x.size / RATE + gap_s
    speech = np.concatenate(parts)
    noise = np.cumsum(rng.standard_normal(speech.size)) * 0.02 + rng.standard_normal(speech.size)
    noise -= np.convolve(noise, np.ones(400) / 400, mode="same")
    noise *= 0.1 / 10 ** (snr_db / 20) / np.std(noise)
    mix = (speech + noise).astype(np.float32)
    sf.write(str(path), mix, RATE)
    return Scene(path, mix, placed)


def real_speech(name: str) -> Path:
    """A file of ../shared/speech-real, or skip the test when that folder is absent."""
    p = REAL_SPEECH / name
    if not p.is_file():
        pytest.skip(f"real speech recordings not found at {REAL_SPEECH.resolve()} "
                    f"(they sit beside the checkout in CI)")
    return p
