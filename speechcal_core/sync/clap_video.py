"""Find a hand clap in one camera: a brief local motion event, timed to a fraction of a frame."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, replace

import cv2
import numpy as np
from scipy.signal import find_peaks

from speechcal_core.sources.decode import sensor_depth

WORK_WIDTH = 160  # frames are analysed at about this width
GRID = 8  # cells across the width
EVENT_S = 0.35  # motion is smoothed over this long when looking for the event
MAX_EVENTS = 6  # motion bursts checked for the closing-and-parting shape of a clap
#: the least change (pixels) of the parts' distance that makes a V: a 1280x800 camera's
#: hands, seen at WORK_WIDTH, gave a flat 6.8-7.5 px of noise whose "V" was a frame off,
#: and it overruled the full-resolution fit (the two disagreed by more than half a frame)
MIN_V_DEPTH_PX = 2.0
#: a point of the parts' distance this far (pixels) above the line through its neighbours,
#: and well beyond their scatter, is left out of the V fit (:func:`_spikes`)
SPIKE_PX = 2.0
#: the event region's frames are worked on in blocks of about this many bytes (float32),
#: so that a region as large as the picture never needs all its frames as floats at once
BLOCK_BYTES = 16 << 20


@dataclass(frozen=True)
class VideoClap:
    """Where and when a camera saw the clap; ``clap_ns`` is in that camera's stamp clock."""

    stream: str
    clap_ns: int
    frame_index: int  # the frame nearest the clap
    score: float  # event contrast x uniqueness; higher is clearer
    method: str  # "v-fit" (sub-frame, from the hands' approach and separation) or "peak"
    roi: tuple[int, int, int, int]  # x, y, w, h in full-frame pixels
    period_ns: int  # median frame period of the stream
    #: the V fit's standard error of ``clap_ns`` (from how far its points scatter about the
    #: V); 0: unknown (method "peak")
    sigma_ns: int = 0

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return {"name": self.stream, "clap_ns": self.clap_ns, "frame_index": self.frame_index,
                "score": round(self.score, 3), "method": self.method, "roi": list(self.roi),
                "period_ns": self.period_ns, "sigma_ns": self.sigma_ns}


def to_gray_small(frame: np.ndarray, width: int = WORK_WIDTH,
                  depth: int | None = None) -> tuple[np.ndarray, float]:
    """Gray float32 image at about ``width`` pixels wide (0-255, a 16-bit frame scaled by
    its stream's sensor ``depth``, or its own), and the scale factor applied."""
    img = _to_float(*_gray_plane(frame, depth))
    scale = min(1.0, width / img.shape[1])
    if scale < 1.0:
        size = (max(1, round(img.shape[1] * scale)), max(1, round(img.shape[0] * scale)))
        img = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
    return img, scale


def gray_full(frame: np.ndarray, depth: int | None = None) -> np.ndarray:
    """The frame at full resolution with the values of :func:`to_gray_small` (no resize):
    an 8-bit frame's gray stays uint8 (a quarter of the float32 bytes; converting it gives
    those values exactly), a 16-bit frame's comes as float32 on the 0-255 scale."""
    plane, divisor = _gray_plane(frame, depth)
    if plane.dtype == np.uint8 and divisor == 1.0:
        # its own compact copy: not a view that keeps a decoded buffer or colour frame alive
        return plane if plane.base is None and plane.flags.c_contiguous else plane.copy()
    return _to_float(plane, divisor)


def _gray_plane(frame: np.ndarray, depth: int | None) -> tuple[np.ndarray, float]:
    """The gray plane in the frame's own type, and what divides it onto 0-255 (or 1)."""
    img = frame
    if img.ndim == 3:
        img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY) if img.shape[2] == 3 else img[..., 0]
    if img.dtype == np.uint16:
        if depth is None:
            depth = sensor_depth(int(img.max()) if img.size else 0)
        if depth is not None and depth > 8:
            return img, float(1 << (depth - 8))
    return img, 1.0


def _to_float(plane: np.ndarray, divisor: float) -> np.ndarray:
    img = plane.astype(np.float32)
    return img / divisor if divisor != 1.0 else img


def find_video_clap(frames: Sequence[np.ndarray] | np.ndarray,
                    stamps_ns: Sequence[int] | np.ndarray,
                    *, stream: str = "", scale: float | None = None,
                    detail: Callable[[int], np.ndarray] | None = None) -> VideoClap | None:
    """The clap event in a run of frames (any size, gray or colour) with their stamps.

    Looks for grid cells with one sharp, unique burst of motion (periodic motion such
    as a fan or a blinking light repeats and is ignored), then times the event to a
    fraction of a frame from the closing and opening distance between the two moving
    parts. ``scale``: the frames are already gray float32 from :func:`to_gray_small` at
    this scale (the ROI is still reported in full-frame pixels), as a list or as one
    (n, h, w) float32 array (used as it is); ``detail(i)`` then gives frame i at full
    resolution for the final timing, as :func:`gray_full` does (uint8 or float32 gray).
    None when no event is there.
    """
    found = find_video_claps(frames, stamps_ns, stream=stream, scale=scale, detail=detail)
    return found[0] if found else None


def find_video_claps(frames: Sequence[np.ndarray] | np.ndarray,
                     stamps_ns: Sequence[int] | np.ndarray,
                     *, stream: str = "", scale: float | None = None,
                     detail: Callable[[int], np.ndarray] | None = None) -> list[VideoClap]:
    """Every clap-like burst, most likely first: those with the closing-and-parting shape
    (method "v-fit") by score, else the strongest burst alone (method "peak")."""
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    if len(frames) < 5 or stamps.size != len(frames):
        return []
    first = np.flatnonzero(np.r_[True, np.diff(stamps) != 0])
    if first.size < stamps.size:  # a topic recorded twice: each frame once, at its stamp
        kept = frames[first] if isinstance(frames, np.ndarray) else [frames[int(i)] for i in first]
        once = find_video_claps(kept, stamps[first], stream=stream,
                                scale=scale, detail=None if detail is None
                                else lambda i: detail(int(first[i])))
        return [replace(c, frame_index=int(first[c.frame_index])) for c in once]
    if scale is None:
        stack = np.stack([to_gray_small(f)[0] for f in frames])
        scale = to_gray_small(frames[0])[1]
        detail = detail or (lambda i: gray_full(frames[i]))
    elif isinstance(frames, np.ndarray) and frames.ndim == 3 and frames.dtype == np.float32:
        stack = frames  # already the work-size stack: no second copy
    else:
        stack = np.stack(list(frames)).astype(np.float32, copy=False)
    t = regular_times(stamps)
    period = float(np.median(np.diff(t))) if t.size > 1 else 1 / 30
    events = _events(stack, t, period)
    out: list[VideoClap] = []
    full_res = scale < 1.0 and detail is not None
    for k, (x, y, w, h), score in events:
        roi_full = (int(x / scale), int(y / scale), int(w / scale), int(h / scale))
        fit = _refine(stack[:, y:y + h, x:x + w], t, k, period)
        if full_res and (fit is not None or score >= 0.5 * events[0][2]):
            fine = _refine_full(detail, roi_full, t, k, period)
            if fine is not None and (fit is None or abs(fine[0] - fit[0]) < 0.5 * period):
                fit = fine
        if fit is not None:
            out.append(_clap(stream, stamps, fit[0], score, "v-fit", roi_full, period, fit[1]))
    if events and (not out or events[0][2] > 3.0 * max(c.score for c in out)):
        # a much clearer burst without the V shape still counts, timed to its frame
        k, (x, y, w, h), score = events[0]
        roi_full = (int(x / scale), int(y / scale), int(w / scale), int(h / scale))
        out.append(_clap(stream, stamps, float(t[k]), score, "peak", roi_full, period))
    return out


def regular_times(stamps: np.ndarray) -> np.ndarray:
    """Frame times (s from the first stamp) with the stamps' jitter taken out.

    A camera exposes at a steady rate while its header stamps scatter by a fraction of a
    millisecond; a line fitted through stamp vs. frame number (dropped frames counted)
    over the whole run gives each frame's time far more precisely than its own stamp.
    Stamps that are not regular enough for that are returned as they are.
    """
    raw = (stamps - stamps[0]).astype(np.float64) / 1e9
    if raw.size < 8:
        return raw
    period = float(np.median(np.diff(raw)))
    if period <= 0:
        return raw
    frame_no = np.round(raw / period)
    if np.any(np.diff(frame_no) <= 0):
        return raw
    keep = np.ones(raw.size, bool)
    for _ in range(3):
        slope, icept = np.polyfit(frame_no[keep], raw[keep], 1)
        resid = raw - (icept + slope * frame_no)
        spread = 1.4826 * float(np.median(np.abs(resid[keep]))) + 1e-6
        keep = np.abs(resid) < 4 * spread
    if spread > 0.1 * period or keep.sum() < raw.size // 2:
        return raw
    return icept + slope * frame_no


def _clap(stream: str, stamps: np.ndarray, t_clap: float, score: float, method: str,
          roi: tuple[int, int, int, int], period: float, sigma: float = 0.0) -> VideoClap:
    clap_ns = int(stamps[0] + round(t_clap * 1e9))
    nearest = int(np.argmin(np.abs(stamps - clap_ns)))
    sigma_ns = round(sigma * 1e9) if np.isfinite(sigma) else 0
    return VideoClap(stream, clap_ns, nearest, float(score), method, roi, round(period * 1e9),
                     sigma_ns)


def _events(stack: np.ndarray, t: np.ndarray, period: float,
            limit: int = MAX_EVENTS) -> list[tuple[int, tuple[int, int, int, int], float]]:
    """(frame index, cell box, score) of the most clap-like motion bursts, best first."""
    n, hgt, wid = stack.shape
    cell = max(4, wid // GRID)
    ny, nx = hgt // cell, wid // cell
    if ny < 1 or nx < 1:
        return []
    # mean absolute frame difference per cell, a block of frames at a time (a copy of the
    # whole stack per step would be several times its size); energy[0] copies energy[1]
    energy = np.empty((n, ny, nx), np.float32)
    step = max(1, BLOCK_BYTES // (4 * hgt * wid))
    for a in range(0, n - 1, step):
        b = min(n - 1, a + step)
        diff = np.diff(stack[a:b + 1, : ny * cell, : nx * cell], axis=0)
        np.abs(diff, out=diff)
        energy[a + 1:b + 1] = diff.reshape(b - a, ny, cell, nx, cell).mean(axis=(2, 4))
    energy[0] = energy[1]  # align with frames
    # never longer than the clip: np.convolve's "same" is as long as the longer input
    w = max(1, min(n, round(EVENT_S / period)))
    kernel = np.ones(w) / w
    smooth = np.apply_along_axis(lambda v: np.convolve(v, kernel, mode="same"), 0, energy)
    noise = max(float(np.median(energy)), 0.05)
    base = np.median(smooth, axis=0)  # per cell
    # how many cells are busy at each moment: a local event keeps most cells quiet
    busy = smooth > 3 * (base + noise)[None]
    busy_frac = busy.reshape(n, -1).mean(axis=1)
    apart = max(1, round(0.5 / period))
    found: list[tuple[float, int, tuple[int, int]]] = []
    for cy in range(ny):
        for cx in range(nx):
            v, b = smooth[:, cy, cx], float(base[cy, cx])
            peaks, props = find_peaks(v, height=b + 2.0, distance=apart)
            heights = props["peak_heights"]
            for p, h in zip(peaks, heights, strict=True):
                contrast = (h - b) / (b + noise)
                # periodic motion (a blinking light) repeats at about the same height
                similar = int(np.sum((heights >= 0.6 * h) & (heights <= 1.6 * h)))
                unique = 5.0 / similar
                local = 1.0 / (1.0 + 20.0 * busy_frac[p])
                found.append((min(contrast, 20.0) * unique * local, int(p), (cy, cx)))
    found.sort(reverse=True)
    events: list[tuple[int, tuple[int, int, int, int], float]] = []
    for score, k, best in found:
        if score < 2.0 or len(events) >= 4 * limit:
            break
        if any(abs(k - e[0]) <= apart for e in events):
            continue
        box = _region(energy, base, noise, k, best, period, cell)
        # a clap is small in the picture; a region over most of it is the board moving
        area = box[2] * box[3] / float(wid * hgt)
        events.append((k, box, float(score) / (1.0 + 6.0 * area * area)))
    events.sort(key=lambda e: e[2], reverse=True)
    return events[:limit]


def _region(energy: np.ndarray, base: np.ndarray, noise: float, k: int,
            best: tuple[int, ...], period: float, cell: int) -> tuple[int, int, int, int]:
    """Pixel box of the connected cells busy around frame k and quiet otherwise."""
    n, ny, nx = energy.shape
    # the event region: connected cells busy around the event and quiet otherwise
    span = max(1, round(0.8 / period))
    lo, hi = max(0, k - span), min(n, k + span + 1)
    around = energy[lo:hi].mean(axis=0)
    rest = np.concatenate([energy[:lo], energy[hi:]], axis=0)
    calm = np.median(rest, axis=0) if rest.shape[0] >= 3 else base
    ev = (around - calm) / (calm + noise)
    near = ev > max(0.5, 0.05 * float(ev[best]))
    near[best] = True
    near &= _connected(near, best)
    ys, xs = np.nonzero(near)
    y0, y1 = max(0, ys.min() - 1), min(ny, ys.max() + 2)
    x0, x1 = max(0, xs.min() - 1), min(nx, xs.max() + 2)
    return (x0 * cell, y0 * cell, (x1 - x0) * cell, (y1 - y0) * cell)


def _connected(mask: np.ndarray, seed: tuple[int, ...]) -> np.ndarray:
    """The 8-connected component of ``mask`` holding ``seed``."""
    _, labels = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)
    return labels == labels[seed]


class _Frames:
    """The frames of an event region as float32 blocks: slices of a stack, or full-resolution
    crops blurred when a block is asked for (each pass blurs them again: a little time, where
    keeping every blurred crop would take four bytes a pixel for the whole window)."""

    def __init__(self, count: int, shape: tuple[int, int],
                 read: Callable[[int, int, slice], np.ndarray], owned: bool,
                 release: Callable[[], None] = lambda: None) -> None:
        self.count, self.shape, self.read = count, shape, read
        self.owned = owned  # the blocks read are new arrays, free to overwrite
        self.release = release  # lets go of the crops once they are no longer read

    @classmethod
    def of_stack(cls, roi: np.ndarray) -> _Frames:
        return cls(roi.shape[0], roi.shape[1:], lambda a, b, rows: roi[a:b, rows], False)

    @classmethod
    def of_crops(cls, crops: list[np.ndarray]) -> _Frames:
        def read(a: int, b: int, rows: slice) -> np.ndarray:
            first = crops[a][rows]
            out = np.empty((b - a, *first.shape), np.float32)
            for i in range(a, b):
                src = np.ascontiguousarray(crops[i], dtype=np.float32)
                out[i - a] = cv2.GaussianBlur(src, (5, 5), 1.0)[rows]  # sensor noise off edges
            return out
        return cls(len(crops), crops[0].shape, read, True, crops.clear)

    def blocks(self, a: int, b: int) -> Iterator[tuple[int, np.ndarray]]:
        """(first frame, frames) of [a, b) a block at a time."""
        step = max(1, BLOCK_BYTES // (4 * self.shape[0] * self.shape[1]))
        for s in range(a, b, step):
            yield s, self.read(s, min(b, s + step), slice(None))

    def resid(self, a: int, b: int, bg: np.ndarray) -> Iterator[tuple[int, np.ndarray]]:
        """(first frame, |frames - bg|) of [a, b) a block at a time."""
        for s, block in self.blocks(a, b):
            out = np.subtract(block, bg, out=block if self.owned else None)
            yield s, np.abs(out, out=out)

    def median(self, a: int, b: int) -> np.ndarray:
        """Per-pixel median of frames [a, b), a band of rows at a time."""
        hgt, wid = self.shape
        out = np.empty((hgt, wid), np.float32)
        band = max(1, BLOCK_BYTES // (4 * wid * (b - a)))
        for r in range(0, hgt, band):
            rows = slice(r, r + band)
            out[rows] = np.median(self.read(a, b, rows), axis=0, overwrite_input=self.owned)
        return out


def _refine(roi: np.ndarray | _Frames, t: np.ndarray, k: int,
            period: float) -> tuple[float, float] | None:
    """Sub-frame clap time and its standard error (:func:`_vertex_fit`) from the V of the
    distance between the two moving parts.

    ``roi``: the region's frames, an (n, h, w) array or :class:`_Frames`; they are read a
    block at a time, pass after pass, instead of being held as residuals all at once.
    """
    frames = roi if isinstance(roi, _Frames) else _Frames.of_stack(roi)
    n, (hgt, wid) = frames.count, frames.shape
    bg = _background(frames, k, period)
    noise = _median_of(lambda: (r for _, r in frames.resid(0, n, bg))) * 1.4826 + 1.0
    thr = max(10.0, 4.0 * noise)
    lo, hi = max(0, k - round(0.8 / period)), min(n, k + round(0.8 / period) + 1)
    fg = np.empty((hi - lo, hgt, wid), dtype=bool)
    for s, r in frames.resid(lo, hi, bg):
        np.greater(r, thr, out=fg[s - lo: s - lo + r.shape[0]])
    frames.release()  # crops of a large region: their memory goes to the points below
    count = int(np.count_nonzero(fg))
    if count < 20:
        return None
    # (y, x) of every foreground pixel frame by frame, as rows: np.cov's own layout
    coords = np.empty((2, count))
    at = 0
    for m in fg:
        ys, xs = np.nonzero(m)
        coords[0, at:at + ys.size] = ys
        coords[1, at:at + ys.size] = xs
        at += ys.size
    centre = coords.mean(axis=1)  # whole-number sums: exact in any order
    coords -= centre[:, None]
    _, vecs = np.linalg.eigh(_cov_rows(coords))
    del coords
    axis = vecs[:, -1]  # major axis: the approach direction
    yy, xx = np.arange(hgt)[:, None], np.arange(wid)[None, :]
    proj = (yy - centre[0]) * axis[0] + (xx - centre[1]) * axis[1]
    times, dists = [], []
    for j in range(lo, hi):
        m = fg[j - lo]
        if m.sum() < 6:
            continue
        d = _blob_distance(proj[m])
        if d is not None:
            times.append(t[j])
            dists.append(d)
    if len(times) < 4:
        return None
    return _vertex_fit(np.array(times), np.array(dists), t[k], period)


def _refine_full(detail: Callable[[int], np.ndarray], box: tuple[int, int, int, int],
                 t: np.ndarray, k: int, period: float) -> tuple[float, float] | None:
    """The V fit again on full-resolution crops of the event region (finer distances)."""
    span = round(1.9 / period)
    j0, j1 = max(0, k - span), min(t.size, k + span + 1)
    frames = _crops(detail, box, j0, j1)
    if frames is None:
        return None
    return _refine(frames, t[j0:j1], k - j0, period)


def _crops(detail: Callable[[int], np.ndarray], box: tuple[int, int, int, int],
           j0: int, j1: int) -> _Frames | None:
    """Crops of frames [j0, j1) as they come (uint8 where they are), blurred when read;
    None when they differ in size."""
    x, y, w, h = box
    crops = []
    for j in range(j0, j1):
        full = detail(j)
        crop = full[y:y + h, x:x + w]
        # a small crop is copied: its view would keep the whole frame alive
        crops.append(crop if 2 * crop.nbytes >= full.nbytes else crop.copy())
    if len({c.shape for c in crops}) != 1:
        return None
    return _Frames.of_crops(crops)


def _background(frames: _Frames, k: int, period: float) -> np.ndarray:
    """Median of the frames just before the event (or just after, if it starts the clip)."""
    n = frames.count
    near, far = round(0.9 / period), round(1.8 / period)
    if max(0, k - near) - max(0, k - far) >= 3:
        return frames.median(max(0, k - far), max(0, k - near))
    if min(n, k + far) - min(n, k + near) >= 3:
        return frames.median(min(n, k + near), min(n, k + far))
    return frames.median(0, n)


def _median_of(chunks: Callable[[], Iterable[np.ndarray]]) -> float:
    """``float(np.median(...))`` of the values of non-negative float32 arrays, exactly,
    without putting them together: two passes of ``chunks()`` count the values' bit
    patterns (which sort as the values do) by their upper, then lower 16 bits."""
    top = np.zeros(1 << 16, np.int64)
    for c in chunks():
        for part in _bits(c):
            top += np.bincount(part >> 16, minlength=1 << 16)
    if top[0x7F80:].any() or not top.any():  # inf, NaN or negative values; or none at all
        return float(np.median(np.concatenate([np.ravel(c) for c in chunks()])))
    n = int(top.sum())
    ranks = (n // 2 - 1, n // 2) if n % 2 == 0 else (n // 2,)
    cum = np.cumsum(top)
    where = [(int(np.searchsorted(cum, r, side="right")), r) for r in ranks]
    low = {b: np.zeros(1 << 16, np.int64) for b, _ in where}
    for c in chunks():
        for part in _bits(c):
            upper = part >> 16
            for b, hist in low.items():
                hist += np.bincount(part[upper == b] & 0xFFFF, minlength=1 << 16)
    values = []
    for b, r in where:
        before = int(cum[b - 1]) if b else 0
        lo = int(np.searchsorted(np.cumsum(low[b]), r - before, side="right"))
        values.append(np.array([(b << 16) | lo], np.uint32).view(np.float32)[0])
    return float(np.mean(np.array(values, np.float32)))  # np.median's mean of the middle


def _bits(c: np.ndarray, size: int = 1 << 20) -> Iterator[np.ndarray]:
    """The float32 values' bit patterns, ``size`` at a time (bincount copies them to int64)."""
    flat = np.ascontiguousarray(c, dtype=np.float32).reshape(-1).view(np.uint32)
    for s in range(0, flat.size, size):
        yield flat[s:s + size]


def _cov_rows(m: np.ndarray) -> np.ndarray:
    """``np.cov(m)`` of a C-ordered (rows, n) float64 array, which is overwritten: the same
    arithmetic on the same layout as np.cov's copy of its input, without that copy (the
    foreground of a large region has tens of millions of points)."""
    avg = np.average(m, axis=1)
    m -= avg[:, None]
    c = np.dot(m, m.T.conj())
    c *= np.true_divide(1, m.shape[1] - 1)
    return c.squeeze()


def _blob_distance(p: np.ndarray) -> float | None:
    """Distance between the centroids of two parts split by the widest gap."""
    ps = np.sort(p)
    ws = np.ones(ps.size)
    gaps = np.diff(ps)
    if gaps.size == 0:
        return None
    g = int(np.argmax(gaps))
    if gaps[g] < 1.5:  # touching: no gap between the parts
        return None
    left, right = slice(0, g + 1), slice(g + 1, None)
    wl, wr = ws[left].sum(), ws[right].sum()
    if min(wl, wr) < 0.15 * max(wl, wr):
        return None
    return float(np.dot(ps[right], ws[right]) / wr - np.dot(ps[left], ws[left]) / wl)


def _vertex(times: np.ndarray, dists: np.ndarray, t_peak: float, period: float) -> float | None:
    """Time where the closing line meets the opening line (:func:`_vertex_fit`)."""
    fit = _vertex_fit(times, dists, t_peak, period)
    return None if fit is None else fit[0]


def _vertex_fit(times: np.ndarray, dists: np.ndarray, t_peak: float,
                period: float) -> tuple[float, float] | None:
    """Time where the closing line meets the opening line (continuous two-line fit), and
    its standard error (:func:`_vertex_sd`; seconds, nan when it cannot be told).

    A first fit around the closest pair finds the touch; a second keeps only the closing
    half second before it and the opening before the hands move off.
    """
    if float(np.ptp(dists)) < MIN_V_DEPTH_PX:
        return None  # parts that neither close nor part: noise, no V to time
    t_min = float(times[int(np.argmin(dists))])
    fit = _fit_window(times, dists, t_min, 0.55, 0.3, period)
    if fit is not None:
        fit = _fit_window(times, dists, fit[0], 0.5, 0.28, period) or fit
    if fit is None or not np.isfinite(fit[0]) or abs(fit[0] - t_peak) > 0.6 + period:
        return None
    return float(fit[0]), fit[1]


def _fit_window(times: np.ndarray, dists: np.ndarray, centre: float, before: float,
                after: float, period: float) -> tuple[float, float] | None:
    """Robust V fit of the points in ``[centre - before, centre + after]``: the vertex
    and its standard error from the points kept."""
    sel = (times >= centre - before) & (times <= centre + after)
    x, y = times[sel], dists[sel]
    if x.size < 4 or (x <= centre).sum() < 2 or (x >= centre).sum() < 1:
        return None
    keep = ~_spikes(x, y)
    if keep.sum() < 4:
        keep[:] = True
    tc = None
    for _ in range(3):
        tc, _ = _fit_v(x[keep], y[keep], centre, period)
        if tc is None:
            return None
        r = np.abs(y - _v_model(x, y, keep, tc))
        tol = max(0.75, 3.0 * 1.4826 * float(np.median(r[keep])))
        new_keep = r <= tol
        if new_keep.sum() < 4 or np.array_equal(new_keep, keep):
            break
        keep = new_keep
    return tc, _vertex_sd(x[keep], y[keep], tc)


def _spikes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Points well above the line through their two neighbours.

    The parts' distance closes and opens in a V, which never rises above such a line; a
    frame whose parts were split wrongly (the flash, a touch seen as a gap elsewhere) can
    sit far above it, and one such point drew the least-squares V three frames early
    (the residual check after that fit, made with it, did not drop it).
    """
    out = np.zeros(x.size, dtype=bool)
    if x.size < 5:
        return out
    span = x[2:] - x[:-2]
    f = np.divide(x[1:-1] - x[:-2], span, out=np.full(span.shape, 0.5), where=span > 0)
    above = y[1:-1] - (y[:-2] + f * (y[2:] - y[:-2]))
    noise = 1.4826 * float(np.median(np.abs(above - np.median(above))))
    out[1:-1] = above > max(SPIKE_PX, 6.0 * noise)
    return out


def _vertex_sd(x: np.ndarray, y: np.ndarray, tc: float) -> float:
    """Standard error of a V's vertex time: the Gauss-Newton covariance of the fit
    (offset, closing slope, opening slope, vertex) scaled by its residual variance.

    A V whose points bend away from two straight lines (parts of the hands lost against
    a background like them) scatters more about the fit and gets a larger error.
    """
    b = _basis(x, tc)
    coef, *_ = np.linalg.lstsq(b, y, rcond=None)
    resid = y - b @ coef
    if x.size <= 4:
        return float("nan")
    var = float(resid @ resid) / (x.size - 4)
    dvertex = -coef[1] * (x < tc) - coef[2] * (x > tc)
    jac = np.column_stack([b, dvertex])
    try:
        cov = np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return float("nan")
    sd = float(np.sqrt(max(cov[3, 3], 0.0) * var))
    return sd if np.isfinite(sd) else float("nan")


def _basis(x: np.ndarray, tc: float) -> np.ndarray:
    return np.stack([np.ones_like(x), np.minimum(x - tc, 0.0), np.maximum(x - tc, 0.0)], axis=1)


def _v_model(x: np.ndarray, y: np.ndarray, keep: np.ndarray, tc: float) -> np.ndarray:
    coef, *_ = np.linalg.lstsq(_basis(x[keep], tc), y[keep], rcond=None)
    return _basis(x, tc) @ coef


def _fit_v(x: np.ndarray, y: np.ndarray, t_min: float,
           period: float) -> tuple[float | None, float]:
    """Vertex time minimising the squared residual of a V (closing slope < 0 < opening).

    Every vertex of the grid is fitted at once, in closed form: the V's columns (1,
    closing, opening) have closing * opening = 0, so each vertex's normal equations
    reduce to one division (the same fit as a least-squares solve per vertex, to about
    1e-12 of the residual; of vertices that fit alike to that, the earliest).
    """
    # the hands touch for a few frames with no measurable gap: search the whole hole
    grid = np.arange(t_min - 0.25 - period, t_min + 0.25 + period, 2.5e-4)
    d = x[None, :] - grid[:, None]  # (vertex, point)
    usable = ((d < 0).sum(axis=1) >= 2) & ((d > 0).sum(axis=1) >= 1)
    tcs, d = grid[usable], d[usable]
    close, part = np.minimum(d, 0.0), np.maximum(d, 0.0)
    # normal equations [[n, sc, sp], [sc, cc, 0], [sp, 0, pp]] @ coef = [sy, cy, py]
    sc, sp = close.sum(axis=1), part.sum(axis=1)
    cc, pp = np.einsum("ij,ij->i", close, close), np.einsum("ij,ij->i", part, part)
    cy, py = close @ y, part @ y
    schur = x.size - sc * sc / cc - sp * sp / pp  # > 0 unless the fit is not unique
    solvable = schur > 1e-9 * x.size
    schur[~solvable] = 1.0
    c0 = (y.sum() - sc * cy / cc - sp * py / pp) / schur
    c1, c2 = (cy - sc * c0) / cc, (py - sp * c0) / pp
    resid = c0[:, None] + c1[:, None] * close + c2[:, None] * part - y[None, :]
    err = np.einsum("ij,ij->i", resid, resid)
    err[~solvable | (c1 >= 0) | (c2 <= 0)] = np.inf
    if not np.isfinite(err).any():
        return None, np.inf
    # the earliest of the vertices that fit equally well (one point past the vertex, or a
    # perfect V, fits alike over a stretch of the grid, where rounding picked one)
    least = float(err.min())
    best = int(np.argmax(err <= least + 1e-9 * least + 1e-12 * float(y @ y)))
    return float(tcs[best]), float(err[best])


def _robust_line(x: np.ndarray, y: np.ndarray) -> tuple[float, float] | None:
    """Least-squares line, refitted without points far off it."""
    if x.size < 2:
        return None
    keep = np.ones(x.size, dtype=bool)
    for _ in range(2):
        if keep.sum() < 2:
            return None
        a, b = np.polyfit(x[keep], y[keep], 1)
        r = np.abs(y - (a * x + b))
        tol = max(1.0, 3.0 * float(np.median(r[keep])) * 1.4826)
        keep = r <= tol
    if keep.sum() < 2:
        return None
    a, b = np.polyfit(x[keep], y[keep], 1)
    return float(a), float(b)
