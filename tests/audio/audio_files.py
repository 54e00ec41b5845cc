"""Audio files for the audio tests: a gated tone in noise, in any format and layout."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import soundfile as sf


def write_gated_tone(path: Path, rate: int, seconds: float, channels: int, *, seed: int,
                     tone_hz: float, gate_hz: float, **kw) -> Path:
    """A tone switched on and off at ``gate_hz`` plus noise per channel; ``kw`` goes to
    ``soundfile.SoundFile`` (format, subtype)."""
    rng = np.random.default_rng(seed)
    n = int(rate * seconds)
    t = np.arange(n) / rate
    tone = 0.3 * np.sin(2 * np.pi * tone_hz * t) * (np.sin(2 * np.pi * gate_hz * t) > 0)
    data = (tone[:, None] + 0.05 * rng.standard_normal((n, channels))).astype(np.float32)
    with sf.SoundFile(str(path), "w", samplerate=rate, channels=channels, **kw) as f:
        for i in range(0, n, 4096):  # DESIGN §5: write Ogg in blocks
            f.write(data[i:i + 4096])
    return path


def write_spliced_ogg(path: Path, rate: int, seconds: float, *, seed: int) -> Path:
    """An Ogg Vorbis file whose pages switch part way to another encoding of the same
    audio (another stream serial), as when two programs wrote the file at once. Where
    the switch lies more than libsndfile's search for the last page looks back from the
    end (about 64 kB: 40 s of noise at 16 kHz), it does not know the file's length."""
    rng = np.random.default_rng(seed)
    data = (0.1 * rng.standard_normal(int(rate * seconds))).astype(np.float32)
    takes = []
    for _ in range(2):  # each write picks a new stream serial
        buf = io.BytesIO()
        sf.write(buf, data, rate, format="OGG", subtype="VORBIS")
        takes.append(buf.getvalue())
    switch = len(takes[0]) // 4
    path.write_bytes(takes[1][:switch] + takes[0][switch:])
    return path


def write_chained_ogg(path: Path, parts: list[tuple[np.ndarray, int]]) -> Path:
    """Whole Ogg Vorbis files of ``(samples, rate)`` one after another in one file, as a
    recorder that resumed or ``cat a.ogg b.ogg`` writes them (a chained Ogg file)."""
    takes = []
    for data, rate in parts:
        buf = io.BytesIO()
        sf.write(buf, data, rate, format="OGG", subtype="VORBIS")
        takes.append(buf.getvalue())
    path.write_bytes(b"".join(takes))
    return path
