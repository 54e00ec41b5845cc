"""Scan one camera's frames in a time window: target region, sharpness and motion per frame."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.frames.preview import preview_gray
from speechcal_core.frames.quality import (
    difference,
    mask_box,
    motion_against_neighbours,
    region_mask,
    sharpness,
)
from speechcal_core.sources.errors import BadFrameError

if TYPE_CHECKING:
    from speechcal_core.frames.detect import TargetDetector
    from speechcal_core.sources.base import FrameSource

#: the target region grows by this fraction of its own size (holds are not perfectly still
#: in real life, and the end of a move must fall inside the region)
ROI_GROWTH = 0.15


@dataclass(frozen=True)
class CameraWindow:
    """Raw quality figures of the frames of one camera inside one search window.

    ``indices``/``stamps`` cover the window plus one neighbour each side (for motion);
    ``inside`` marks the frames that lie in the window itself. ``motion`` is the larger
    difference to the previous and next frame over the target region; ``bad`` frames could
    not be decoded. ``target_found`` tells whether the region came from a detection.
    """

    stream: str
    indices: np.ndarray
    stamps: np.ndarray
    inside: np.ndarray
    sharpness: np.ndarray
    motion: np.ndarray
    bad: np.ndarray
    target_found: bool
    period_ns: int
    roi_factor: int = 0  # reduction of the frame the target region was found on (0: none)
    stride: int = 1  # every stride-th frame was read (period_ns is stride frame periods)


def window_indices(stamps: np.ndarray, t0_ns: int, t1_ns: int, stride: int = 1) -> np.ndarray:
    """Indices of every ``stride``-th frame in [t0, t1] plus one more on each side."""
    a = int(np.searchsorted(stamps, t0_ns, "left"))
    b = int(np.searchsorted(stamps, t1_ns, "right"))
    inside = np.arange(a, b, stride)
    if inside.size and inside[-1] != b - 1 and b - 1 - inside[-1] >= stride / 2:
        inside = np.append(inside, b - 1)
    first = inside[0] if inside.size else a
    last = inside[-1] if inside.size else a - 1
    idx = np.concatenate([[first - stride], inside, [last + stride]])
    return idx[(idx >= 0) & (idx < len(stamps))].astype(np.int64)


def scan_window(
    source: FrameSource,
    stream: str,
    stamps: np.ndarray,
    t0_ns: int,
    t1_ns: int,
    *,
    detector: TargetDetector | None,
    factor: int,
    detect_factor: int | None = None,
    compressed: bool | None,
    period_ns: int,
    stride: int = 1,
    roi_hint_ns: tuple[int, ...] = (),
) -> CameraWindow:
    """Decode the window's frames at ``1/factor`` size and measure them.

    The target region comes from detecting the target (at ``1/detect_factor`` size,
    default ``factor``) in the frame nearest each time of ``roi_hint_ns`` in turn (default:
    the window's end, middle, start) until one is found; without a target the whole image
    counts. With ``stride`` > 1 only every stride-th frame is read (motion is then measured
    between frames that far apart, and ``period_ns`` of the result grows to match).
    """
    detect_factor = detect_factor or factor
    idx = window_indices(stamps, t0_ns, t1_ns, stride)
    st = stamps[idx]
    period_ns *= stride
    n = idx.size
    frames: list[np.ndarray | None] = []
    bad = np.zeros(n, bool)
    for k in range(n):
        try:
            frames.append(preview_gray(source, stream, int(idx[k]), factor, compressed))
        except BadFrameError:
            frames.append(None)
            bad[k] = True
    good = [f for f in frames if f is not None]
    if not good:
        zeros = np.zeros(n)
        return CameraWindow(stream, idx, st, (st >= t0_ns) & (st <= t1_ns), zeros, zeros,
                            bad, False, period_ns, 0, stride)
    shape = good[0].shape[:2]
    hulls = []
    roi_factor = 0
    if detector is not None:
        hints = roi_hint_ns or (t1_ns, (t0_ns + t1_ns) // 2, t0_ns)
        # a small board needs more pixels: the first hint is tried at full size as well
        tries = [(t, detect_factor) for t in hints]
        if detect_factor > 1:
            tries.insert(1, (hints[0], 1))
        for t, f in tries:
            k = int(np.argmin(np.abs(st - t)))
            if frames[k] is None:
                continue
            try:
                img = frames[k] if f == factor else preview_gray(source, stream, int(idx[k]),
                                                                 f, compressed)
            except BadFrameError:
                continue
            det = detector.detect(img)
            if det is not None:
                hull = det.hull().astype(np.float64) * (f / factor)
                centre = hull.mean(axis=0)
                hulls.append(centre + (hull - centre) * (1 + ROI_GROWTH))
                roi_factor = f
                break
    mask = region_mask(shape, hulls, grow_px=max(2, shape[1] // 100))
    rows, cols = mask_box(mask)
    sub_mask = mask[rows, cols]
    crops = [f[rows, cols] if f is not None and f.shape[:2] == shape else None for f in frames]
    sharp = np.array([sharpness(c, sub_mask) if c is not None else 0.0 for c in crops])
    diffs = np.zeros(max(0, n - 1))
    for k in range(n - 1):
        a, b = crops[k], crops[k + 1]
        diffs[k] = difference(a, b, sub_mask) if a is not None and b is not None else np.inf
    motion = motion_against_neighbours(diffs)
    bad |= np.array([c is None for c in crops])
    inside = (st >= t0_ns) & (st <= t1_ns)
    return CameraWindow(stream, idx, st, inside, sharp, motion, bad, bool(hulls), period_ns,
                        roi_factor, stride)
