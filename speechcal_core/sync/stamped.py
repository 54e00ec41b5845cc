"""Sync model straight from stamped bag audio: chunk header stamps against sample counts."""

from __future__ import annotations

import numpy as np

from speechcal_core.audio.bag_audio import BagAudio
from speechcal_core.sync.estimate import SyncResult
from speechcal_core.sync.model import SyncModel

MIN_DRIFT_SPAN_S = 10.0
#: audio seconds the chunks' stamps must span to judge how fast they advance
MIN_RATE_SPAN_S = 1.0
#: how far the stamps' pace may be off the audio's (far beyond any clock's drift, and
#: the latency of one chunk over the span)
MAX_RATE_ERROR = 0.1


def stamped_sync(bag: BagAudio, *, stamp_at: str = "end") -> SyncResult | None:
    """The model of stamped audio, or None when the topic carries no stamps.

    ``stamp_at`` says which sample a chunk's header stamp marks: ``"end"`` (the time the
    buffer was complete, as audio_capture does) or ``"start"``. Transport latency only
    ever delays a stamp, so the offset follows the earliest chunks (a low quantile); the
    drift is the slope over the recording when it spans long enough.
    """
    if bag.chunk_stamps_ns is None or bag.chunk_stamps_ns.size == 0 or stamps_problem(bag):
        return None
    stamps, t_audio = _stamped_times(bag, stamp_at)
    notes: list[str] = []
    if t_audio.size < bag.chunk_stamps_ns.size:
        notes.append(f"{bag.topic}: compressed chunks; offset from the first stamp only")
    base = int(stamps[0])
    rel = (stamps - base).astype(np.float64)
    drift = 0.0
    if t_audio.size >= 3 and t_audio[-1] - t_audio[0] >= MIN_DRIFT_SPAN_S:
        slope = float(np.polyfit(t_audio, rel, 1)[0])  # ns per audio second
        drift = slope / 1e9 - 1.0
    resid = rel - t_audio * (1.0 + drift) * 1e9
    offset = base + round(float(np.quantile(resid, 0.05)))
    model = SyncModel(int(offset), float(drift), "stamped")
    return SyncResult(model, (), tuple(notes), {"audio_topic": bag.topic,
                                               "stamp_at": stamp_at})


def _stamped_times(bag: BagAudio, stamp_at: str = "end") -> tuple[np.ndarray, np.ndarray]:
    """The chunks' header stamps and the audio seconds each marks (of compressed chunks,
    whose samples are not counted per chunk, the first only)."""
    assert bag.chunk_stamps_ns is not None
    stamps = bag.chunk_stamps_ns.astype(np.int64)
    if bag.chunk_starts is None or bag.chunk_starts.size != stamps.size:
        return stamps[:1], np.zeros(1)
    starts = bag.chunk_starts.astype(np.float64)
    ends = np.append(starts[1:], bag.audio.samples.size)
    return stamps, (ends if stamp_at == "end" else starts) / float(bag.audio.rate)


def stamps_problem(bag: BagAudio) -> str | None:
    """Why the chunks' header stamps of ``bag`` cannot time its audio (a driver that left
    them unset, or stamps that do not advance with the samples), or None; taken as they
    were, unset stamps gave an offset of 0 and a drift of -1000000 ppm."""
    if bag.chunk_stamps_ns is None or bag.chunk_stamps_ns.size == 0:
        return None
    stamps, t_audio = _stamped_times(bag)
    if np.any(stamps <= 0):
        return (f"{bag.topic}: its chunks' header stamps are unset (0), so they cannot time "
                "the audio; the clap does")
    span_s = float(t_audio[-1] - t_audio[0])
    if span_s < MIN_RATE_SPAN_S:
        return None
    rate = float(stamps[-1] - stamps[0]) / 1e9 / span_s
    if abs(rate - 1.0) > MAX_RATE_ERROR:
        return (f"{bag.topic}: its chunks' header stamps advance {rate:.3g} s per second of "
                "audio, so they cannot time it; the clap does")
    return None
