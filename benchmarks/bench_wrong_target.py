"""A wrong --target against the right one: checkerboard detection time and found rate.

Makes two 14 s, 1-camera synthetic sessions (``speechcal synth``'s generator, 256x192 or
``--size``), one filming a checkerboard, one an AprilGrid, and looks for the checkerboard
in their frames with the detector as it is and with a baseline, the detector as it was,
in the same run: at 256x192 the exhaustive ``findChessboardCornersSB`` on every frame; on
frames wider than 800 px (``--size 1280x720``) the plain search at the shrunk scale, then
again at 1.0x and 1.5x wherever it failed, even where the frame showed an AprilGrid's tags.

- every frame of the checkerboard session: the share with the board found (and whether
  both find the same corners), median ms a frame;
- every ``--stride``-th frame of the AprilGrid session (no checkerboard): median ms a frame;
- ``process`` of the AprilGrid session with the checkerboard target (the user's mistake),
  on the true clock offset: wall time with each detector (``--no-process`` skips it).

    .venv/bin/python benchmarks/bench_wrong_target.py [--stride 8] [--no-process]
        [--size 1280x720]

At 1280x720 (2 shared cores, seed 21), one run: the checkerboard session's 413 frames
all found, as by the baseline, all with the same corners (median 39 ms a frame, baseline
44); AprilGrid frames 0.14 s a frame where they took 1.47 s; ``process`` with the wrong
target 5.6 s where it took 19.5 s.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from speechcal_core.frames import sets
from speechcal_core.frames.detect import (
    DETECT_MAX_SIDE,
    TargetDetector,
    _classic_finds_checkerboard,
    to_gray,
    upright_checkerboard,
)
from speechcal_core.pipeline import process_recording
from speechcal_core.sources import open_recording
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.session import generate_session
from speechcal_core.target import TargetSpec

SESSION = dict(cameras=1, fisheye=0, duration=14.0, seed=21, claps=1)
CHECKERBOARD = TargetSpec("checkerboard", 6, 8, 0.045)


def _found(corners: np.ndarray):
    """What ``_detect_checkerboard`` returned for the corners OpenCV found (both
    baselines)."""
    points = upright_checkerboard(corners.reshape(-1, 2).astype(np.float64))
    step = np.linalg.norm(points[1] - points[0])
    return points, np.arange(points.shape[0]), max(1.5, step * 0.3)


def baseline_checkerboard(self: TargetDetector, small: np.ndarray):
    """``TargetDetector._detect_checkerboard`` as it was (the baseline): the exhaustive
    search on every frame."""
    size = (self.target.cols, self.target.rows)
    flags = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE
    ok, corners = cv2.findChessboardCornersSB(small, size, flags=flags)
    return _found(corners) if ok else None


class BaselineDetector(TargetDetector):
    """The detector with :func:`baseline_checkerboard`."""

    _detect_checkerboard = baseline_checkerboard


def rescale_baseline_checkerboard(self: TargetDetector, small: np.ndarray):
    """``TargetDetector._detect_checkerboard`` as it was before AprilGrid tags ended the
    search (the baseline on frames wider than 800 px): the plain search, the exhaustive
    one where the classic detector finds the board; ``detect`` then looks again at 1.0x
    and 1.5x wherever it failed."""
    size = (self.target.cols, self.target.rows)
    ok, corners = cv2.findChessboardCornersSB(small, size, flags=cv2.CALIB_CB_NORMALIZE_IMAGE)
    if not ok and _classic_finds_checkerboard(small, size):
        flags = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE
        ok, corners = cv2.findChessboardCornersSB(small, size, flags=flags)
    return _found(corners) if ok else None


class RescaleBaselineDetector(TargetDetector):
    """The detector with :func:`rescale_baseline_checkerboard`."""

    _detect_checkerboard = rescale_baseline_checkerboard


def _frames(folder: Path, truth: dict, stride: int) -> list[np.ndarray]:
    with open_recording([str(folder / truth["recording"])]) as src:
        s = src.streams[0]
        return [to_gray(src.frame(s.name, i)) for i in range(0, s.count, stride)]


def _detect_all(kind: type[TargetDetector], frames: list[np.ndarray]) -> tuple[list, float]:
    detector = kind(CHECKERBOARD)
    found, times = [], []
    for f in frames:
        t0 = time.perf_counter()
        found.append(detector.detect(f))
        times.append(time.perf_counter() - t0)
    return found, statistics.median(times) * 1000


def _same(a, b) -> bool:
    """Both found nothing, or the same corners."""
    if a is None or b is None:
        return a is None and b is None
    return bool(np.array_equal(a.points, b.points) and np.array_equal(a.ids, b.ids))


def _process_s(folder: Path, truth: dict, target: Path,
               baseline: type[TargetDetector] | None) -> float:
    """Wall time of ``process`` (on the true offset) with the detector or the baseline."""
    kept = sets.TargetDetector
    sets.TargetDetector = baseline or kept  # what sets.py makes
    try:
        t0 = time.perf_counter()
        session = process_recording([str(folder / truth["recording"])],
                                    str(folder / truth["audio"]),
                                    offset_ns=truth["sync"]["offset_ns"],
                                    target=TargetSpec.from_kalibr_yaml(target))
        elapsed = time.perf_counter() - t0
    finally:
        sets.TargetDetector = kept
    assert not any(f.corners for s in session.sets for f in s.frames)
    return elapsed


def main() -> int:
    """Make the sessions, measure, print one JSON document."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--stride", type=int, default=8, help="AprilGrid frames: every n-th")
    ap.add_argument("--no-process", action="store_true")
    ap.add_argument("--size", default="256x192", help="frame size, WxH")
    args = ap.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    if max(width, height) > DETECT_MAX_SIDE:
        baseline: type[TargetDetector] = RescaleBaselineDetector
        out: dict = {"baseline": "plain findChessboardCornersSB at the shrunk scale, then "
                                 "at 1.0x and 1.5x wherever it failed, tags or none"}
    else:
        baseline = BaselineDetector
        out = {"baseline": "exhaustive findChessboardCornersSB on every frame"}
    out["size"] = args.size
    with tempfile.TemporaryDirectory() as tmp:
        made = {}
        for kind in ("checkerboard", "aprilgrid"):
            folder = Path(tmp) / kind
            generate_session(folder, SynthOptions(**SESSION, width=width, height=height,
                                                  target_kind=kind))
            made[kind] = folder, json.loads((folder / "truth.json").read_text())
        frames = _frames(*made["checkerboard"], 1)
        new, new_ms = _detect_all(TargetDetector, frames)
        old, old_ms = _detect_all(baseline, frames)
        same = sum(_same(a, b) for a, b in zip(new, old, strict=True))
        out["checkerboard_frames"] = {
            "frames": len(frames), "found": sum(d is not None for d in new),
            "found_baseline": sum(d is not None for d in old), "same_corners": same,
            "median_ms": round(new_ms, 1), "median_ms_baseline": round(old_ms, 1)}
        frames = _frames(*made["aprilgrid"], args.stride)
        new, new_ms = _detect_all(TargetDetector, frames)
        old, old_ms = _detect_all(baseline, frames)
        out["aprilgrid_frames"] = {
            "frames": len(frames), "found": sum(d is not None for d in new),
            "found_baseline": sum(d is not None for d in old),
            "median_ms": round(new_ms, 1), "median_ms_baseline": round(old_ms, 1),
            "ratio": round(old_ms / new_ms, 1)}
        if not args.no_process:
            folder, truth = made["aprilgrid"]
            target = made["checkerboard"][0] / "target.yaml"
            new_s = _process_s(folder, truth, target, None)
            old_s = _process_s(folder, truth, target, baseline)
            out["process_wrong_target"] = {"s": round(new_s, 1), "s_baseline": round(old_s, 1),
                                           "ratio": round(old_s / new_s, 1)}
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
