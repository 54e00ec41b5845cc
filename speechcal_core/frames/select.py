"""Best still frame: one common time for all cameras maximizing the worst camera's quality."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from speechcal_core.frames.window import CameraWindow

#: a frame is still when its motion is at most this many times the camera's noise floor
STILL_RATIO = 2.0
#: the noise floor is taken as at least this (mean absolute grey difference of two frames
#: on the ~320 px previews): scaled down from a large image, sensor noise averages out and
#: the floor of still frames falls to ~0.1, where JPEG and target-region differences
#: between windows spread still frames over 1-3 floors (1920x1200 synthetic cameras: 28 of
#: 29 sets flagged "moving" or "skew" in perfectly still holds). 640x480 ones lie at ~1.0.
MIN_NOISE_FLOOR = 0.5
#: candidates within this fraction of the best score count as equally good
TIE_FRACTION = 0.9
#: a still stretch at least this long (ns) is preferred to a shorter one
MIN_RUN_NS = 150_000_000
#: among equally good times, being this far inside the still stretch is enough (ns)
MARGIN_NS = 100_000_000


@dataclass(frozen=True)
class CameraScore:
    """Per-frame quality of one camera's window (aligned with ``CameraWindow.indices``)."""

    quality: np.ndarray  # in [0, 1]: relative sharpness in the window times stillness
    still: np.ndarray  # bool
    motion_ratio: np.ndarray  # motion / the camera's noise floor (MIN_NOISE_FLOOR at least)


@dataclass(frozen=True)
class Choice:
    """The chosen common time and, per camera, the position in its window (-1: none)."""

    t_ns: int
    positions: tuple[int, ...]
    score: float
    still: bool
    still_ns: tuple[int, int] | None  # all cameras still around t_ns, as far as scanned
    #: where the chosen still stretch lies: "at" the trigger, "after" it, "before" it, or
    #: "none" when no moment has every camera still
    stretch: str = "at"


def score_camera(win: CameraWindow, noise_floor: float) -> CameraScore:
    """Quality in [0, 1] per frame: sharpness relative to the window's best, damped by motion."""
    usable = ~win.bad
    best = float(win.sharpness[usable & win.inside].max()) if (usable & win.inside).any() else 0.0
    rel = np.where(usable, win.sharpness / best, 0.0) if best > 0 else np.zeros(win.stamps.size)
    ratio = win.motion / max(noise_floor, MIN_NOISE_FLOOR)
    ratio = np.where(np.isfinite(ratio), ratio, 1e9)
    still = (ratio <= STILL_RATIO) & usable
    damp = np.where(still, 1.0, (STILL_RATIO / np.maximum(ratio, STILL_RATIO)) ** 2)
    return CameraScore(np.clip(rel, 0, 1) * damp, still, ratio)


def choose_common_time(
    windows: Sequence[CameraWindow],
    scores: Sequence[CameraScore],
    t_trigger_ns: int,
    full_stamps: Sequence[np.ndarray] | None = None,
) -> Choice | None:
    """The common time (a frame stamp in the window) whose worst camera quality is highest.

    Each camera contributes its frame nearest the candidate time if it lies within half a
    frame period; a camera with no frame there is left out (its position is -1), and
    times where more cameras have frames win over times with fewer. Only one stretch
    where every camera is still competes: the one around the trigger, else the first
    after it, else the last before it. Near-ties go to a time at least ``MARGIN_NS``
    inside the stretch (or the deepest), then to the smallest skew between the cameras'
    nearest frames (from ``full_stamps``, every frame of each camera, when the scan
    skipped some), then to the time nearest the trigger.
    """
    cands = np.unique(np.concatenate([w.stamps[w.inside] for w in windows] or [np.zeros(0)]))
    if cands.size == 0:
        return None
    if full_stamps is not None:  # every frame time in the scanned span is a candidate
        lo, hi = cands[0], cands[-1]
        extra = [st[(st >= lo) & (st <= hi)] for st in full_stamps]
        cands = np.unique(np.concatenate([cands, *extra]))
    n = cands.size
    worst = np.full(n, np.inf)
    all_still = np.ones(n, bool)
    present = np.zeros(n, np.int64)  # how many cameras have a frame at each time
    pos = np.full((len(windows), n), -1, np.int64)
    for c, (w, s) in enumerate(zip(windows, scores, strict=True)):
        if w.stamps.size == 0:  # no frames near the word (started late, dropped): left out
            continue
        j = nearest_indices(w.stamps, cands)
        # a skipped frame between two read ones may be the one nearest (refined later)
        tol = (w.period_ns // 2 + 1 if w.stride == 1 else w.period_ns) if w.period_ns else np.inf
        ok = np.abs(w.stamps[j] - cands) <= tol
        if full_stamps is not None and w.stride > 1 and w.period_ns:
            # ... but not across a gap in its frames: then it has no frame there
            every = full_stamps[c]
            near = every[nearest_indices(every, cands)]
            ok &= np.abs(near - cands) <= w.period_ns // w.stride // 2 + 1
        worst = np.where(ok, np.minimum(worst, s.quality[j]), worst)
        all_still &= ~ok | s.still[j]
        present += ok
        pos[c] = np.where(ok, j, -1)
    # a camera missing at a time (a gap in its frames) leaves that time to the others only
    # where no time has it: times with the most cameras come first
    worst = np.where(present > 0, worst, 0.0)
    all_still &= present > 0
    most = present == present.max()
    runs = _runs(all_still & most) or _runs(all_still)
    # the operator holds still when (or just after) saying the word: prefer the still
    # stretch around the trigger, then the first one after it, then the last one before
    at = [r for r in runs if cands[r[0]] <= t_trigger_ns <= cands[r[1]]]
    after = [r for r in runs if cands[r[0]] > t_trigger_ns]
    before = [r for r in runs if cands[r[1]] < t_trigger_ns]
    def long(r: tuple[int, int]) -> bool:
        return bool(cands[r[1]] - cands[r[0]] >= MIN_RUN_NS)

    # a short stretch is often the cameras' frames lining up by chance while settling
    options = ([("at", r) for r in at if long(r)] + [("after", r) for r in after if long(r)]
               + [("at", r) for r in at]
               + [("after", r) for r in sorted(after, key=lambda r: cands[r[0]] - cands[r[1]])]
               + [("before", r) for r in before[::-1]])
    if options:
        stretch, (a, b) = options[0]
        pool = np.arange(a, b + 1)
    else:
        stretch, pool = "none", np.arange(n)
    pool = pool[present[pool] == present[pool].max()]
    best = float(worst[pool].max())
    good = pool[worst[pool] >= best * TIE_FRACTION] if best > 0 else pool
    depth = _still_depth_ns(cands, all_still)
    seen = [c for c, w in enumerate(windows) if w.stamps.size]  # cameras left out skew nothing
    skew = _skew(cands, [full_stamps[c] for c in seen] if full_stamps is not None
                 else [windows[c].stamps for c in seen])
    key = [(-min(depth[k], MARGIN_NS), skew[k], abs(int(cands[k]) - t_trigger_ns))
           for k in good]
    k = int(good[min(range(len(good)), key=key.__getitem__)])
    return Choice(int(cands[k]), tuple(int(p) for p in pos[:, k]), float(worst[k]),
                  bool(all_still[k]), _still_run(cands, all_still, k), stretch)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of ``mask``."""
    out, start = [], None
    for k, v in enumerate(mask):
        if v and start is None:
            start = k
        elif not v and start is not None:
            out.append((start, k - 1))
            start = None
    if start is not None:
        out.append((start, mask.size - 1))
    return out


def nearest_indices(stamps: np.ndarray, times: np.ndarray) -> np.ndarray:
    """For each time, the index of the nearest stamp (stamps sorted, not empty)."""
    right = np.clip(np.searchsorted(stamps, times), 0, stamps.size - 1)
    left = np.clip(right - 1, 0, stamps.size - 1)
    closer_left = np.abs(stamps[left] - times) <= np.abs(stamps[right] - times)
    return np.where(closer_left, left, right)


def _still_depth_ns(cands: np.ndarray, still: np.ndarray) -> np.ndarray:
    """Per candidate, how far (ns) it lies inside its still stretch (0 when not still)."""
    depth = np.zeros(cands.size, np.int64)
    for a, b in _runs(still):
        span = cands[a:b + 1]
        depth[a:b + 1] = np.minimum(span - cands[a], cands[b] - span)
    return depth


def _skew(cands: np.ndarray, stamps: Sequence[np.ndarray]) -> np.ndarray:
    """Per candidate time, the spread of the cameras' nearest frame stamps."""
    if not stamps:
        return np.zeros(cands.size, np.int64)
    near = np.stack([st[nearest_indices(st, cands)] for st in stamps if st.size])
    return near.max(axis=0) - near.min(axis=0)


def _still_run(cands: np.ndarray, still: np.ndarray, k: int) -> tuple[int, int] | None:
    if not still[k]:
        return None
    a = k
    while a > 0 and still[a - 1]:
        a -= 1
    b = k
    while b < still.size - 1 and still[b + 1]:
        b += 1
    return int(cands[a]), int(cands[b])
