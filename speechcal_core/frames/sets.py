"""Frame sets per trigger: nearest frames, best still frame search, target corners, flags."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from speechcal_core.frames.detect import Detection, Target, TargetDetector
from speechcal_core.frames.nearest import frame_period_ns, nearest_choice
from speechcal_core.frames.preview import preview_factor, preview_gray
from speechcal_core.frames.quality import mask_box, region_mask, sharpness
from speechcal_core.frames.select import (
    MIN_RUN_NS,
    CameraScore,
    Choice,
    choose_common_time,
    score_camera,
)
from speechcal_core.frames.window import CameraWindow, scan_window
from speechcal_core.processes import usable_cores
from speechcal_core.session.model import FrameChoice, FrameSet, Trigger
from speechcal_core.sources.base import COMPRESSED_MSGTYPE
from speechcal_core.sources.errors import BadFrameError

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource, StreamInfo
    from speechcal_core.sync.model import SyncModel

Progress = Callable[[str, float], None]
NS = 1_000_000_000
#: sharpness (relative to the camera's board held still around the trigger, see
#: :func:`_frame_choice`) under which a frame is flagged blurred. Relative to the session's
#: sharp frames instead, as it was, frames of a still board scored by the board's distance
#: (its edges per pixel), 0.25-1.37, and were flagged under 0.25; relative to the same board
#: still, still frames score 1.00 and mid-move ones 0.14-2.5, 42 of 151 under 0.7, 18 under
#: 0.5 (synthetic sessions, benchmarks/bench_blur_flag.py).
BLURRED_BELOW = 0.7
#: the same for a frame whose window has no still frame, judged against the session's sharp
#: frames (the figure as it was, and its threshold: such a frame may be far closer or further
#: than those, so only far less sharp is blurred for sure)
BLURRED_BELOW_SESSION = 0.25
MIN_CORNERS = 8
#: a still chosen frame in which the target is not found, while the camera's search found
#: it in that window, gives way to the first of this many of its still neighbours (nearest
#: first) that shows it: a board at the detector's limit is read in some frames of a still
#: hold and not in others, noise deciding (the tiny test session's 256 x 192 fisheye read
#: one tag of 36, and from it 88-104 corners a median 0.1 px from the truth, in 26 of the
#: 36 frames of one hold; the still search, which picks by stillness and time, had chosen
#: one of the other ten)
STILL_RETRIES = 4


@dataclass(frozen=True)
class FrameSetOptions:
    """How frame sets are built.

    ``window_s``: search window around the trigger (seconds); ``search``: best still frame
    (False: nearest frame only); ``extend_s``: how far the window grows forward, once, when
    no still moment is found in it; ``workers``: threads (0: one per CPU);
    ``scan_rate_hz``: faster cameras are scanned at every n-th frame to about this rate
    (0: every frame), and the chosen frame is then the nearest one inside the still span.
    """

    window_s: tuple[float, float] = (-0.3, 0.7)
    search: bool = True
    extend_s: float = 0.5
    workers: int = 0
    scan_rate_hz: float = 8.0


@dataclass
class FrameSetResult:
    """Frame sets plus what the session keeps beside them (details, corner detections)."""

    sets: list[FrameSet]
    details: dict[str, Any] = field(default_factory=dict)  # set id (str) -> JSON-ready dict
    detections: dict[tuple[int, str], Detection] = field(default_factory=dict)
    image_sizes: dict[str, tuple[int, int]] = field(default_factory=dict)  # stream -> (w, h)
    references: FrameReferences | None = None  # what the figures were judged against


@dataclass(frozen=True)
class FrameReferences:
    """Per camera, the session-wide figures each set's measurements are judged against.

    ``noise_floor``: the frame-to-frame difference of still frames (a frame is still within
    a few times it); ``sharpness``: the raw sharpness of the camera's sharp chosen frames
    (90th percentile), which is 1.0 of the figure of a frame whose window has no still
    frame to judge it against (see :func:`_frame_choice`). Both come from all sets of a
    session; re-scoring a few sets with them keeps their figures comparable to the rest.
    """

    noise_floor: dict[str, float]
    sharpness: dict[str, float]

    def to_dict(self) -> dict[str, dict[str, float]]:
        return {"noise_floor": dict(self.noise_floor), "sharpness": dict(self.sharpness)}

    @classmethod
    def from_dict(cls, data: object) -> FrameReferences | None:
        """Inverse of :meth:`to_dict`; None for anything else (an older session)."""
        try:
            return cls({str(k): float(v) for k, v in data["noise_floor"].items()},  # type: ignore[index]
                       {str(k): float(v) for k, v in data["sharpness"].items()})  # type: ignore[index]
        except (KeyError, TypeError, ValueError, AttributeError):
            return None


class _Detectors(threading.local):
    """One detector per thread (OpenCV detectors and the corner-order memory are stateful),
    made on the thread's first use: none on the thread that only builds this (a Qt pool
    thread in the window). A detector in that thread's slot outliving its task is freed
    as PySide tears the thread's Python state down, and OpenCV's clean-up then crashes
    the process (seen while a stack sampler held the frame that held this)."""

    def __init__(self, target: Target | None) -> None:
        self.target = target
        self._made: tuple[TargetDetector, TargetDetector] | None = None

    def _detectors(self) -> tuple[TargetDetector, TargetDetector] | None:
        if self._made is None and self.target is not None:
            self._made = (TargetDetector(self.target), TargetDetector(self.target))
        return self._made

    @property
    def preview(self) -> TargetDetector | None:
        """This thread's detector for the reduced frames of the still search."""
        made = self._detectors()
        return made[0] if made else None

    @property
    def full(self) -> TargetDetector | None:
        """This thread's detector for full-resolution frames."""
        made = self._detectors()
        return made[1] if made else None


def build_frame_sets(
    source: FrameSource,
    sync: SyncModel,
    triggers: Sequence[Trigger],
    target: Target | None,
    options: FrameSetOptions | None = None,
    progress: Progress | None = None,
) -> FrameSetResult:
    """One frame set per trigger (sorted by time), every camera's frame chosen and measured."""
    trig = sorted(triggers, key=lambda t: t.t_s)
    return _build(source, sync, list(enumerate(trig, 1)), target, options, progress)


def rescore_frame_sets(
    source: FrameSource,
    sync: SyncModel,
    sets: Sequence[FrameSet],
    target: Target | None,
    options: FrameSetOptions | None = None,
    references: FrameReferences | None = None,
    progress: Progress | None = None,
) -> FrameSetResult:
    """``sets`` chosen and measured again for ``sync``, as :func:`build_frame_sets` does it
    for detected triggers (after a clock offset edit, or for a set the operator added).

    Ids, triggers, decisions and order are kept; times, frames and figures are new. With
    ``references`` (a session's, see :class:`FrameReferences`) a few sets are scored like
    the rest of their session; without, the references come from ``sets`` themselves, so
    re-scoring all of a session's sets gives what the pipeline gives for that sync.
    ``progress`` may raise to cancel (between frames).
    """
    result = _build(source, sync, [(s.id, s.trigger) for s in sets], target, options,
                    progress, references)
    result.sets = [replace(new, decision=old.decision)
                   for new, old in zip(result.sets, sets, strict=True)]
    return result


def _build(
    source: FrameSource,
    sync: SyncModel,
    items: Sequence[tuple[int, Trigger]],
    target: Target | None,
    options: FrameSetOptions | None = None,
    progress: Progress | None = None,
    references: FrameReferences | None = None,
) -> FrameSetResult:
    """Frame sets with these ids and triggers, in this order (see :func:`build_frame_sets`)."""
    options = options or FrameSetOptions()
    report = progress or (lambda _stage, _f: None)
    infos = list(source.streams)
    stamps = {s.name: source.stamps(s.name) for s in infos}
    periods = {s.name: s.median_period_ns or frame_period_ns(stamps[s.name]) for s in infos}
    ids = [set_id for set_id, _ in items]
    trig = [trigger for _, trigger in items]
    t_ns = [int(sync.to_session(t.t_s)) for t in trig]
    nearest = [{s.name: nearest_choice(s.name, stamps[s.name], t) for s in infos} for t in t_ns]
    local = _Detectors(target)
    compressed = {s.name: _is_compressed(s) for s in infos}
    workers = options.workers or min(4, usable_cores())

    with ThreadPoolExecutor(max_workers=workers) as pool:
        if options.search and infos and trig:
            choices, windows, scores, floors = _search(source, infos, stamps, periods, t_ns,
                                                       options, local, pool, report, references)
        else:
            choices, windows, scores = [None] * len(trig), [None] * len(trig), [None] * len(trig)
            floors = dict(references.noise_floor) if references else {}
        picks = [_pick(infos, stamps, nearest[n], choices[n], windows[n], scores[n], t)
                 for n, t in enumerate(t_ns)]
        measured = _measure(source, picks, compressed, local, pool, report)
        _retry_still_neighbours(source, infos, stamps, picks, measured, choices, windows,
                                scores, compressed, local, pool)
        # a moving chosen frame is judged against the still board nearby, at full size too
        still_refs = [_reference_picks(infos, choices[n], windows[n], scores[n])
                      for n in range(len(t_ns))]
        ref_measured = _measure(source, still_refs, compressed, local, pool,
                                lambda _stage, _f: None)

    result = FrameSetResult([])
    for (n, name), (_sharp, det, size) in measured.items():
        if det is not None:
            result.detections[(ids[n], name)] = det
        if size is not None:
            result.image_sizes[name] = size
    refs = {}
    for s in infos:
        if references is not None and s.name in references.sharpness:
            refs[s.name] = references.sharpness[s.name]
            continue
        vals = [v[0] for (_n, name), v in measured.items()
                if name == s.name and v[0] is not None and v[0] > 0]
        refs[s.name] = float(np.percentile(vals, 90)) if vals else 0.0
    result.references = FrameReferences(floors, refs)
    # free-running cameras cannot always do better than the two longest half periods
    halves = sorted((p // 2 for p in periods.values() if p), reverse=True)
    tol = sum(halves[:2]) if len(halves) > 1 else 0
    for n, (trigger, t) in enumerate(zip(trig, t_ns, strict=True)):
        set_id = ids[n]
        frames = []
        for c, s in enumerate(infos):
            idx, stamp = picks[n][s.name]
            sharp, det, _size = measured.get((n, s.name), (-1.0, None, None))
            still = None
            local_ref = None
            if choices[n] is not None and scores[n] is not None and windows[n] is not None:
                p = choices[n].positions[c]
                still = p >= 0 and bool(scores[n][c].still[p])
                ref_sharp = ref_measured.get((n, s.name), (None, None, None))[0]
                local_ref = _still_relative(windows[n][c], scores[n][c], p, sharp, ref_sharp)
            frames.append(_frame_choice(s.name, idx, stamp, sharp, refs[s.name], det,
                                        target is not None, still, local_ref))
        fs = FrameSet(set_id, t, trigger, tuple(frames))
        if tol and fs.skew_ns > tol:
            fs = FrameSet(set_id, t, trigger, tuple(
                FrameChoice(f.stream, f.index, f.stamp_ns, f.sharpness, f.corners,
                            (*f.flags, "skew")) for f in frames))
        result.sets.append(fs)
        result.details[str(set_id)] = _details(set_id, t, choices[n], windows[n], scores[n],
                                               nearest[n], infos, result.detections, options,
                                               picks[n])
    return result


def _pick(
    infos: list[StreamInfo],
    stamps: dict[str, np.ndarray],
    nearest: dict[str, FrameChoice],
    choice: Choice | None,
    wins: list[CameraWindow] | None,
    scores: list[CameraScore] | None,
    t_ns: int,
) -> dict[str, tuple[int, int]]:
    """Per stream, the (index, stamp) chosen for one set: the search's, else the nearest."""
    row = {}
    for c, s in enumerate(infos):
        if choice is None or wins is None or scores is None:
            row[s.name] = (nearest[s.name].index, nearest[s.name].stamp_ns)
            continue
        p = choice.positions[c]
        if p < 0:
            row[s.name] = (-1, t_ns)
        else:
            j = _refine(stamps[s.name], wins[c], scores[c], p, choice.t_ns, choice.still)
            row[s.name] = (j, int(stamps[s.name][j]))
    return row


def _measure(
    source: FrameSource,
    picks: list[dict[str, tuple[int, int]]],
    compressed: dict[str, bool | None],
    local: _Detectors,
    pool: ThreadPoolExecutor,
    report: Progress,
) -> dict[tuple[int, str], tuple[float | None, Detection | None, tuple[int, int] | None]]:
    """Full-resolution corners and raw sharpness of every chosen frame (-1: undecodable).

    Sharpness is measured on the target; with a target wanted and not found it is None (a
    whole frame's sharpness says nothing of the target and does not compare with it).
    """
    jobs = [(n, name, idx) for n, row in enumerate(picks) for name, (idx, _) in row.items()
            if idx >= 0]
    done = [0]

    def one(job: tuple[int, str, int]) -> tuple[float | None, Detection | None,
                                                tuple[int, int] | None]:
        _n, name, idx = job
        try:  # grey straight from the JPEG/PNG payload when there is one
            img = preview_gray(source, name, idx, 1, compressed[name])
        except BadFrameError:
            return -1.0, None, None
        det = local.full.detect(img) if local.full is not None else None
        sharp = None
        if det is not None or local.full is None:
            mask = region_mask(img.shape[:2], [det.hull()] if det is not None else [], 0)
            rows, cols = mask_box(mask)
            sharp = sharpness(img[rows, cols], mask[rows, cols])
        done[0] += 1
        report("corners", done[0] / max(1, len(jobs)))
        return sharp, det, (img.shape[1], img.shape[0])

    return {(n, name): r for (n, name, _), r in zip(jobs, pool.map(one, jobs), strict=True)}


def _retry_still_neighbours(
    source: FrameSource,
    infos: list[StreamInfo],
    stamps: dict[str, np.ndarray],
    picks: list[dict[str, tuple[int, int]]],
    measured: dict[tuple[int, str], tuple[float | None, Detection | None,
                                          tuple[int, int] | None]],
    choices: list[Choice | None],
    windows: list[list[CameraWindow] | None],
    scores: list[list[CameraScore] | None],
    compressed: dict[str, bool | None],
    local: _Detectors,
    pool: ThreadPoolExecutor,
) -> None:
    """Where a still chosen frame shows no target and the camera's search saw it in that
    window, the nearest of ``STILL_RETRIES`` still neighbours that shows it takes its place
    (``picks`` and ``measured`` are updated)."""
    if local.full is None:
        return
    queues: dict[tuple[int, str], list[int]] = {}
    for (n, name), (_sharp, det, _size) in measured.items():
        ch, wins, sc = choices[n], windows[n], scores[n]
        if det is not None or ch is None or wins is None or sc is None:
            continue
        c = next(k for k, s in enumerate(infos) if s.name == name)
        p = ch.positions[c]
        win, still = wins[c], sc[c].still
        if p < 0 or not win.target_found or not still[p]:
            continue
        lo = hi = p  # the still scanned frames around p; the frames between them are still
        while lo > 0 and still[lo - 1]:
            lo -= 1
        while hi + 1 < still.size and still[hi + 1]:
            hi += 1
        chosen = picks[n][name][0]
        near = np.arange(int(win.indices[lo]), int(win.indices[hi]) + 1)
        near = near[near != chosen]
        order = np.argsort(np.abs(stamps[name][near] - stamps[name][chosen]), kind="stable")
        if near.size:
            queues[(n, name)] = [int(i) for i in near[order][:STILL_RETRIES]]
    for k in range(STILL_RETRIES):
        tries = {key: q[k] for key, q in queues.items() if k < len(q)}
        if not tries:
            return
        rows: list[dict[str, tuple[int, int]]] = [{} for _ in picks]
        for (n, name), i in tries.items():
            rows[n][name] = (i, int(stamps[name][i]))
        found = _measure(source, rows, compressed, local, pool, lambda _stage, _f: None)
        for key, result in found.items():
            if result[1] is not None:
                n, name = key
                picks[n][name] = rows[n][name]
                measured[key] = result
                del queues[key]


def _still_reference(win: CameraWindow, score: CameraScore, p: int) -> int | None:
    """The window position of the sharpest frame of the still stretch nearest position
    ``p`` (its own when it is still): the board held still at about the pose ``p`` shows,
    where another hold in the window may show it at another distance. None when ``p`` is
    none or no frame of the window is still (the board never stops around the trigger)."""
    if p < 0 or win.bad[p]:
        return None
    still = score.still & win.inside & ~win.bad
    if not still.any():
        return None
    # still stretches as [start, end) position ranges; the nearest one to p
    edges = np.diff(np.concatenate([[0], still.astype(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    k = int(np.argmin(np.maximum(starts - p, 0) + np.maximum(p - (ends - 1), 0)))
    return int(starts[k] + np.argmax(win.sharpness[starts[k]:ends[k]]))


def _reference_picks(infos: list[StreamInfo], choice: Choice | None,
                     wins: list[CameraWindow] | None, scores: list[CameraScore] | None,
                     ) -> dict[str, tuple[int, int]]:
    """Per stream whose chosen frame is not still, the (index, stamp) of the frame its
    sharpness is judged against (see :func:`_still_reference`); (-1, 0) for the others."""
    row = {s.name: (-1, 0) for s in infos}
    if choice is None or wins is None or scores is None:
        return row
    for c, s in enumerate(infos):
        p = choice.positions[c]
        if p < 0 or scores[c].still[p]:
            continue
        q = _still_reference(wins[c], scores[c], p)
        if q is not None:
            row[s.name] = (int(wins[c].indices[q]), int(wins[c].stamps[q]))
    return row


def _still_relative(win: CameraWindow, score: CameraScore, p: int, sharp: float | None,
                    ref_sharp: float | None) -> float | None:
    """Window position ``p``'s sharpness relative to the frame of :func:`_still_reference`.

    For a still ``p`` that frame lies in the same still stretch and the figures of the
    window's reduced frames are compared; for a moving one those miss the few pixels of
    motion blur, and the full-size figures ``sharp`` (of ``p``'s frame) and ``ref_sharp``
    (of that frame) are compared when both are known. None without a still stretch.
    """
    q = _still_reference(win, score, p)
    if q is None:
        return None
    if not score.still[p] and sharp and ref_sharp and sharp > 0 and ref_sharp > 0:
        return sharp / ref_sharp
    best = float(win.sharpness[q])
    return float(win.sharpness[p]) / best if best > 0 else None


def _frame_choice(stream: str, idx: int, stamp: int, sharp: float | None, ref: float,
                  det: Detection | None, want_target: bool, still: bool | None,
                  local_ref: float | None = None) -> FrameChoice:
    """The chosen frame with its relative sharpness, corner count and flags.

    Sharpness is ``local_ref`` when given: the frame's over the sharpest still frame of
    its camera around the trigger (see :func:`_still_relative`), which a board held still
    at any distance scores ~1.0 and a motion-blurred one far less. Without it (no still
    frame in the window, or no search) it is the raw sharpness ``sharp`` over ``ref``, the
    camera's sharp frames in the session, which also follows the board's distance, so it
    is flagged only further below (``BLURRED_BELOW_SESSION``); a frame blurred all through
    the window still lies there. Either way a frame whose target was wanted and not found
    has none (nothing to judge blur on).
    """
    if idx < 0:
        return FrameChoice(stream, -1, stamp, flags=("no-frame",))
    flags: list[str] = []
    sharp_norm = None
    if sharp is not None and sharp < 0:
        flags.append("bad-frame")
    elif sharp is not None and (local_ref is not None or ref > 0):
        sharp_norm = round(local_ref if local_ref is not None else sharp / ref, 3)
        if sharp_norm < (BLURRED_BELOW if local_ref is not None else BLURRED_BELOW_SESSION):
            flags.append("blurred")
    corners = det.count if det is not None else 0
    if want_target and corners < MIN_CORNERS:
        flags.append("no-target")
    if still is False:
        flags.append("moving")
    return FrameChoice(stream, idx, stamp, sharp_norm, corners, tuple(flags))


def _refine(stamps: np.ndarray, win: CameraWindow, score: CameraScore, p: int,
            t_ns: int, still_at_t: bool = False) -> int:
    """The frame nearest ``t_ns`` when the scan skipped frames and the span around it is still.

    A skipped frame between two scanned still frames saw the board where they saw it; so
    did one between a still scanned frame and ``t_ns`` when every camera is still there
    (``still_at_t``: the next scanned frame may lie across a gap in this camera's frames).
    """
    i = int(win.indices[p])
    j = int(np.argmin(np.abs(stamps[max(0, i - 8):i + 9] - t_ns))) + max(0, i - 8)
    if j == i or not score.still[p]:
        return i
    if still_at_t and min(stamps[i], t_ns) <= stamps[j] <= max(stamps[i], t_ns) + \
            win.period_ns // max(win.stride, 1) // 2:
        return j
    q = p - 1 if j < i else p + 1
    if 0 <= q < win.indices.size and score.still[q] and \
            min(win.indices[q], i) < j < max(win.indices[q], i):
        return j
    return i


def _search(
    source: FrameSource,
    infos: list[StreamInfo],
    stamps: dict[str, np.ndarray],
    periods: dict[str, int],
    t_ns: list[int],
    options: FrameSetOptions,
    local: _Detectors,
    pool: ThreadPoolExecutor,
    report: Progress,
    references: FrameReferences | None = None,
) -> tuple[list[Choice | None], list[list[CameraWindow] | None],
           list[list[CameraScore] | None], dict[str, float]]:
    """Scan every trigger's window in every camera, then pick each set's common time.

    Also returns each camera's noise floor: the references' when given, else measured
    over these windows.
    """
    w0, w1 = (int(v * NS) for v in options.window_s)
    # motion and sharpness on ~320 px wide frames, the target region found on ~640 px ones
    factors = {s.name: preview_factor(s.width, s.height, 320) if s.width else 1 for s in infos}
    det_factors = {s.name: preview_factor(s.width, s.height, 640) if s.width else 1
                   for s in infos}
    compressed = {s.name: _is_compressed(s) for s in infos}
    done = [0]
    total = len(t_ns) * len(infos)

    strides = {s.name: max(1, round(NS / options.scan_rate_hz / periods[s.name]))
               if options.scan_rate_hz > 0 and periods[s.name] else 1 for s in infos}

    def scan(job: tuple[int, int, int]) -> CameraWindow:
        n, c, extra = job
        s = infos[c]
        win = scan_window(source, s.name, stamps[s.name], t_ns[n] + w0, t_ns[n] + w1 + extra,
                          detector=local.preview, factor=factors[s.name],
                          detect_factor=det_factors[s.name], compressed=compressed[s.name],
                          period_ns=periods[s.name], stride=strides[s.name])
        if win.roi_factor == 1 and det_factors[s.name] > 1:
            det_factors[s.name] = 1  # this camera's board is small: look at full size
        done[0] += 1
        report("windows", min(1.0, done[0] / total))
        return win

    jobs = [(n, c, 0) for n in range(len(t_ns)) for c in range(len(infos))]
    flat = list(pool.map(scan, jobs))
    windows: list[list[CameraWindow] | None] = [
        flat[n * len(infos):(n + 1) * len(infos)] for n in range(len(t_ns))]
    floors = _noise_floors(infos, windows)
    if references is not None:
        floors.update({k: v for k, v in references.noise_floor.items() if k in floors})
    full = [stamps[s.name] for s in infos]
    choices: list[Choice | None] = []
    scores: list[list[CameraScore] | None] = []
    retry = []
    for n, wins in enumerate(windows):
        assert wins is not None
        sc = [score_camera(w, floors[w.stream]) for w in wins]
        ch = choose_common_time(wins, sc, t_ns[n], full)
        choices.append(ch)
        scores.append(sc)
        if options.extend_s > 0 and _worth_extending(ch):
            retry.append(n)
    if retry:
        extra = int(options.extend_s * NS)
        more = list(pool.map(scan, [(n, c, extra) for n in retry for c in range(len(infos))]))
        report("windows", 1.0)
        for k, n in enumerate(retry):
            wins = more[k * len(infos):(k + 1) * len(infos)]
            sc = [score_camera(w, floors[w.stream]) for w in wins]
            ch = choose_common_time(wins, sc, t_ns[n], full)
            if ch is not None and _better(ch, choices[n]):
                choices[n], windows[n], scores[n] = ch, wins, sc
    return choices, windows, scores, floors


_RANK = ("at", "after", "before", "none")


def _still_length(ch: Choice) -> int:
    return ch.still_ns[1] - ch.still_ns[0] if ch.still_ns else -1


def _worth_extending(ch: Choice | None) -> bool:
    """No still moment at or after the word, or only a short one (it may go on later)."""
    if ch is None or ch.stretch in ("before", "none"):
        return True
    return _still_length(ch) < MIN_RUN_NS


def _better(new: Choice, old: Choice | None) -> bool:
    """Whether a choice from the extended window beats the first one."""
    if old is None:
        return True
    a, b = _RANK.index(new.stretch), _RANK.index(old.stretch)
    return a < b or (a == b and _still_length(new) > _still_length(old))


def _noise_floors(infos: list[StreamInfo],
                  windows: list[list[CameraWindow] | None]) -> dict[str, float]:
    """Per camera, the frame-to-frame difference of still frames: a low percentile."""
    floors = {}
    for c, s in enumerate(infos):
        vals = np.concatenate([w[c].motion[w[c].inside & ~w[c].bad & np.isfinite(w[c].motion)]
                               for w in windows if w is not None] or [np.zeros(0)])
        vals = vals[vals > 0]
        floors[s.name] = float(np.percentile(vals, 10)) if vals.size else 0.0
    return floors


def _is_compressed(info: StreamInfo) -> bool | None:
    if info.msgtype == COMPRESSED_MSGTYPE:
        return True
    if info.msgtype == "file":
        return None
    return False


def _details(
    set_id: int,
    t_ns: int,
    choice: Choice | None,
    wins: list[CameraWindow] | None,
    scores: list[CameraScore] | None,
    nearest: dict[str, FrameChoice],
    infos: list[StreamInfo],
    detections: dict[tuple[int, str], Detection],
    options: FrameSetOptions,
    picks: dict[str, tuple[int, int]] | None = None,
) -> dict[str, Any]:
    """JSON-ready figures of one set: chosen time, stillness, nearest frames, corners (with
    the stamp of the frame they were found in, from ``picks``: stream -> (index, stamp))."""
    out: dict[str, Any] = {
        "trigger_ns": t_ns,
        "chosen_ns": choice.t_ns if choice else t_ns,
        "method": "best-still" if choice else "nearest",
        "window_s": list(options.window_s),
        "score": round(choice.score, 4) if choice else None,
        "still_ns": list(choice.still_ns) if choice and choice.still_ns else None,
        "stretch": choice.stretch if choice else None,
        "nearest": {name: {"index": f.index, "stamp_ns": f.stamp_ns}
                    for name, f in nearest.items()},
        "frames": {},
    }
    for c, s in enumerate(infos):
        entry: dict[str, Any] = {}
        if choice is not None and wins is not None and scores is not None \
                and choice.positions[c] >= 0:
            w, p = wins[c], choice.positions[c]
            # motion in units of the camera's still-frame noise; quality in [0, 1]
            entry["motion"] = round(float(min(scores[c].motion_ratio[p], 1e6)), 3)
            entry["quality"] = round(float(scores[c].quality[p]), 4)
            entry["still"] = bool(scores[c].still[p])
            entry["target_region"] = w.target_found
        det = detections.get((set_id, s.name))
        if det is not None:
            entry["ids"] = det.ids.tolist()
            entry["points"] = np.round(det.points, 2).tolist()
            if picks is not None and s.name in picks:
                entry["stamp_ns"] = int(picks[s.name][1])
        out["frames"][s.name] = entry
    return out
