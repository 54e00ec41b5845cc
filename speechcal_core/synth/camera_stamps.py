"""When each synthetic camera exposes a frame, what it stamps it with, and which frames drop.

Exposure mid-times run at the camera's fps (free-running, random phase) over the session;
``header.stamp`` = true mid-exposure time + the camera's clock offset + Gaussian jitter;
the bag's receive (log) time adds a small positive transport delay. Frames near a clap
are never dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from speechcal_core.synth.timeline import Timeline

NS = 1_000_000_000
KEEP_NEAR_CLAP_NS = 300_000_000  # no drops within this distance of a clap
TRANSPORT_DELAY_NS = (2_000_000, 9_000_000)  # receive time - header stamp


@dataclass(frozen=True)
class CameraFrames:
    """The frames one camera writes (all int64 ns, sorted by header stamp)."""

    camera_index: int
    true_ns: np.ndarray  # true (reference clock) mid-exposure time
    header_ns: np.ndarray  # header.stamp
    log_ns: np.ndarray  # bag receive time
    dropped: int


def plan_frames(timeline: Timeline) -> list[CameraFrames]:
    """Frame times of every camera of ``timeline``, deterministic by its seed."""
    claps = np.asarray(timeline.claps_ns, dtype=np.int64)
    out = []
    for i, cam in enumerate(timeline.cameras):
        rng = timeline.rng(f"stamps{i}")
        period = NS / cam.fps
        phase = rng.uniform(0.0, period)
        n = int(np.floor((timeline.end_ns - timeline.start_ns - phase) / period)) + 1
        true_ns = timeline.start_ns + np.round(phase + np.arange(n) * period).astype(np.int64)
        true_ns = true_ns[true_ns <= timeline.end_ns]
        jitter = np.round(rng.normal(0.0, cam.jitter_ns, true_ns.size)).astype(np.int64)
        drop = rng.random(true_ns.size) < cam.drop_rate
        if claps.size:
            near = np.abs(true_ns[:, None] - claps[None, :]).min(axis=1) <= KEEP_NEAR_CLAP_NS
            drop &= ~near
        delay = rng.integers(*TRANSPORT_DELAY_NS, size=true_ns.size)
        keep = ~drop
        header = true_ns + cam.clock_offset_ns + jitter
        # jitter is far below the frame period; keep stamps strictly increasing regardless
        order = np.argsort(header[keep], kind="stable")
        t_keep, h_keep = true_ns[keep][order], header[keep][order]
        h_keep = np.maximum.accumulate(h_keep + np.arange(h_keep.size)) - np.arange(h_keep.size)
        out.append(CameraFrames(i, t_keep, h_keep, h_keep + delay[keep][order],
                                int(drop.sum())))
    return out
