"""Sync model straight from stamped bag audio: chunk header stamps against sample counts."""

from __future__ import annotations

import numpy as np

from speechcal_core.audio.bag_audio import BagAudio
from speechcal_core.sync.estimate import SyncResult
from speechcal_core.sync.model import SyncModel

MIN_DRIFT_SPAN_S = 10.0


def stamped_sync(bag: BagAudio, *, stamp_at: str = "end") -> SyncResult | None:
    """The model of stamped audio, or None when the topic carries no stamps.

    ``stamp_at`` says which sample a chunk's header stamp marks: ``"end"`` (the time the
    buffer was complete, as audio_capture does) or ``"start"``. Transport latency only
    ever delays a stamp, so the offset follows the earliest chunks (a low quantile); the
    drift is the slope over the recording when it spans long enough.
    """
    if bag.chunk_stamps_ns is None or bag.chunk_stamps_ns.size == 0:
        return None
    stamps = bag.chunk_stamps_ns.astype(np.int64)
    rate = float(bag.audio.rate)
    notes: list[str] = []
    if bag.chunk_starts is None or bag.chunk_starts.size != stamps.size:
        t_audio = np.zeros(1)
        stamps = stamps[:1]
        notes.append(f"{bag.topic}: compressed chunks; offset from the first stamp only")
    else:
        starts = bag.chunk_starts.astype(np.float64)
        ends = np.append(starts[1:], bag.audio.samples.size)
        t_audio = (ends if stamp_at == "end" else starts) / rate
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
