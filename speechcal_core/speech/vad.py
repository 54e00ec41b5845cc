"""Cheap voice-activity segmentation: band energy against an adaptive noise floor."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import maximum_filter1d, median_filter, minimum_filter1d

HOP_S = 0.010
WIN = 400  # samples at 16 kHz (25 ms)
BAND_HZ = (300.0, 4000.0)  # where speech stands out of room rumble and hum
BLOCK_FRAMES = 100  # noise-floor statistics per second
FLOOR_PERCENTILE = 20.0
FLOOR_SPAN_BLOCKS = 9  # the floor is the lowest block statistic within +-4 s
SILENCE_LEVEL = 1e-5  # below this everywhere (about -100 dBFS) a file is silent
LEVEL_PERCENTILE = 90.0  # a span's level: this percentile of its energy above the floor
CHUNK_FRAMES = 6000  # energies are computed a minute at a time (bounded memory)


@dataclass(frozen=True)
class VadSettings:
    """Thresholds of the speech/non-speech decision."""

    margin_db: float = 2.5  # a frame is active this far above the noise floor
    min_active_s: float = 0.08  # shorter bursts are clicks, not words
    bridge_s: float = 0.3  # gaps shorter than this join two segments
    pad_s: float = 0.35  # context kept either side for the recogniser
    max_len_s: float = 20.0  # longer segments are cut into overlapping pieces
    overlap_s: float = 2.0


def frame_count(n_samples: int, rate: int) -> int:
    """How many frames ``band_energy_db`` gives for ``n_samples`` samples."""
    win = round(rate * WIN / 16000)
    return 0 if n_samples < win else 1 + (n_samples - win) // round(rate * HOP_S)


def band_energy_db(samples: np.ndarray, rate: int,
                   band_hz: tuple[float, float] = BAND_HZ) -> np.ndarray:
    """Log energy (dB) of 25 ms frames every 10 ms in ``band_hz`` (the speech band)."""
    hop = round(rate * HOP_S)
    win = round(rate * WIN / 16000)
    n = frame_count(samples.size, rate)
    out = np.empty(n, dtype=np.float32)
    nfft = 1 << int(np.ceil(np.log2(win)))
    freqs = np.fft.rfftfreq(nfft, 1.0 / rate)
    band = (freqs >= band_hz[0]) & (freqs <= band_hz[1])
    window = np.hanning(win).astype(np.float32)
    for a in range(0, n, CHUNK_FRAMES):
        b = min(n, a + CHUNK_FRAMES)
        idx = (np.arange(a, b) * hop)[:, None] + np.arange(win)[None, :]
        frames = samples[idx] * window
        spec = np.abs(np.fft.rfft(frames, nfft, axis=1)[:, band]) ** 2
        out[a:b] = 10.0 * np.log10(np.sum(spec, axis=1) + 1e-12)
    return out


def noise_floor_db(energy_db: np.ndarray) -> np.ndarray:
    """Per-frame noise floor: low percentile per second, lowest within a few seconds."""
    n = energy_db.size
    if n == 0:
        return energy_db.copy()
    m = -(-n // BLOCK_FRAMES)
    padded = np.resize(energy_db, m * BLOCK_FRAMES)  # the last block repeats its start
    padded[n:] = energy_db[-1]
    blocks = np.percentile(padded.reshape(m, BLOCK_FRAMES), FLOOR_PERCENTILE, axis=1)
    floor = minimum_filter1d(blocks, FLOOR_SPAN_BLOCKS, mode="nearest")
    centres = (np.arange(m) + 0.5) * BLOCK_FRAMES
    return np.interp(np.arange(n), centres, floor).astype(np.float32)


@dataclass(frozen=True)
class VoiceActivity:
    """Speech spans (seconds) and the noise floor (dB per 10 ms frame) they were found on."""

    segments: list[tuple[float, float]]
    floor_db: np.ndarray
    energy_db: np.ndarray | None = None

    def level_db(self, start_s: float, end_s: float,
                 percentile: float = LEVEL_PERCENTILE) -> float:
        """How far the loud part of ``start_s``..``end_s`` stands above the noise floor (dB).

        The 90th percentile of band energy minus floor: a local signal-to-noise figure
        (``percentile`` near 100 gives the loudest moment instead).
        """
        if self.energy_db is None or self.energy_db.size == 0:
            return 0.0
        a = min(self.energy_db.size - 1, max(0, int(start_s / HOP_S)))
        b = min(self.energy_db.size, max(a + 1, int(end_s / HOP_S)))
        return float(np.percentile(self.energy_db[a:b] - self.floor_db[a:b], percentile))

    def floor_at(self, t_s: float) -> float:
        """The noise floor at audio time ``t_s``."""
        if self.floor_db.size == 0:
            return -120.0
        return float(self.floor_db[min(self.floor_db.size - 1, max(0, int(t_s / HOP_S)))])


def voice_activity(samples: np.ndarray, rate: int,
                   settings: VadSettings | None = None) -> VoiceActivity:
    """Find the speech spans of a recording."""
    if samples.size == 0 or not np.any(np.abs(samples) > SILENCE_LEVEL):
        return VoiceActivity([], np.zeros(0, dtype=np.float32))  # empty or digital silence
    energy = band_energy_db(samples, rate)
    floor = noise_floor_db(energy)
    return VoiceActivity(_segments(energy, floor, samples.size / rate, settings), floor, energy)


def speech_segments(samples: np.ndarray, rate: int,
                    settings: VadSettings | None = None) -> list[tuple[float, float]]:
    """Spans (seconds) that may hold speech, padded, merged and cut to a bounded length."""
    return voice_activity(samples, rate, settings).segments


def _segments(energy: np.ndarray, floor: np.ndarray, duration: float,
              settings: VadSettings | None) -> list[tuple[float, float]]:
    s = settings or VadSettings()
    if energy.size == 0 or float(np.max(energy)) < -100.0:  # nothing, or digital silence
        return []
    active = (energy - floor) > s.margin_db
    active = median_filter(active.astype(np.uint8), size=5, mode="nearest").astype(bool)
    bridge = max(1, round(s.bridge_s / HOP_S))
    joined = minimum_filter1d(maximum_filter1d(active.astype(np.uint8), bridge), bridge) > 0
    joined |= active
    spans: list[tuple[float, float]] = []
    for a, b in _runs(joined):
        if int(np.count_nonzero(active[a:b])) * HOP_S < s.min_active_s:
            continue
        start = max(0.0, a * HOP_S - s.pad_s)
        end = min(duration, b * HOP_S + WIN / 16000 + s.pad_s)
        if spans and start <= spans[-1][1]:
            spans[-1] = (spans[-1][0], end)
        else:
            spans.append((start, end))
    return [piece for span in spans for piece in _cut(span, s.max_len_s, s.overlap_s)]


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Start/stop indices of runs of True."""
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist(),
                    strict=True))


def _cut(span: tuple[float, float], max_len: float, overlap: float) -> list[tuple[float, float]]:
    """Split a long span into pieces of at most ``max_len`` overlapping by ``overlap``."""
    a, b = span
    if b - a <= max_len:
        return [span]
    pieces = []
    step = max_len - overlap
    while a < b:
        pieces.append((a, min(b, a + max_len)))
        if a + max_len >= b:
            break
        a += step
    return pieces
