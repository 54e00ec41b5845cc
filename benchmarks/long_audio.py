"""Shared by the long-recording benchmarks: a long synthetic WAV, memory held, child runs.

Each measurement runs in a fresh process (``run_child``) so its peak RSS is its own.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

RATE = 48000


def write_tone_bursts(path: Path, minutes: float,
                      pitches: Sequence[float] = (300.0, 450.0, 700.0)) -> None:
    """Room noise with word-length (0.4 s) tone bursts every ~3 s, written a minute at a
    time (no speech needed, and nothing long in memory)."""
    import soundfile as sf

    rng = np.random.default_rng(3)
    with sf.SoundFile(str(path), "w", samplerate=RATE, channels=1, subtype="PCM_16") as f:
        for _minute in range(int(np.ceil(minutes))):
            x = 0.01 * rng.standard_normal(RATE * 60)
            for start in np.arange(0.5, 59.0, 3.0) + rng.uniform(0, 1.5, 20):
                a = int(start * RATE)
                t = np.arange(int(0.4 * RATE)) / RATE
                hz = pitches[int(rng.integers(0, len(pitches)))]
                x[a:a + t.size] += 0.2 * np.sin(2 * np.pi * hz * t) * np.hanning(t.size)
            f.write(x.astype(np.float32))


def rss_mb() -> float:
    """This process's resident memory now, in MB."""
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * resource.getpagesize() / 1e6


def peak_rss_mb() -> float:
    """This process's peak resident memory so far, in MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3


def run_child(script: str, mode: str, path: Path) -> dict:
    """``script --child MODE PATH`` in a fresh Python; the JSON document it prints."""
    out = subprocess.run([sys.executable, script, "--child", mode, str(path)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)
