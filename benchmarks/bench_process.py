"""Benchmark frame processing: 50 triggers x 5 cameras, 1280x720 JPEG, best-still search.

Generates a synthetic session (``speechcal synth``'s generator) in a temporary folder, then
times the frame analysis (window search, target corners, coverage, calibration check) with
the search on and with nearest frames only (the baseline), on the truth clock offset and
trigger words so that clap and speech detection stay out of the figure. Prints the median of
the runs, the ratio to the baseline, how many chosen frames fall outside their hold, and the
recovered intrinsics.

    .venv/bin/python benchmarks/bench_process.py [--runs 3] [--data DIR] [--keep]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from bench_data import session_folder

from speechcal_core.errors import UsageError
from speechcal_core.frames.analysis import FrameAnalysis, analyse_frames
from speechcal_core.frames.sets import FrameSetOptions
from speechcal_core.session.model import Trigger
from speechcal_core.sources import open_recording
from speechcal_core.sync.model import SyncModel
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.session import generate_session
from speechcal_core.target import TargetSpec

TRIGGERS = 50
CAMERAS = 5
FISHEYE = 1
TARGET_S = 15.0


def make_data(out: Path, seed: int) -> dict:
    """Write the synthetic session; the shortest duration that holds all triggers."""
    for duration in range(170, 400, 20):
        options = SynthOptions(cameras=CAMERAS, fisheye=FISHEYE, triggers=TRIGGERS,
                               duration=float(duration), width=1280, height=720,
                               encoding="jpeg", seed=seed)
        try:
            t0 = time.perf_counter()
            truth = generate_session(out, options, force=True)
            print(f"generated {duration} s session in {time.perf_counter() - t0:.0f} s",
                  file=sys.stderr)
            return truth
        except UsageError:
            continue
    raise SystemExit("could not fit the triggers into a session")


def score(analysis: FrameAnalysis, truth: dict) -> tuple[int, int]:
    """Chosen frames outside their hold (camera clock offset removed), and all frames."""
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    holds = [t["hold"] for t in sorted(truth["triggers"],
                                       key=lambda t: t["start_s"] + t["end_s"])]
    outside = total = 0
    for fs, hold in zip(analysis.sets, holds, strict=True):
        for f in fs.frames:
            if f.index < 0:
                continue
            t = f.stamp_ns - offsets[f.stream]
            total += 1
            outside += not hold[0] <= t <= hold[1]
    return outside, total


def main() -> int:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--data", help="use (or create) this session folder instead of a temp one")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    args = parser.parse_args()

    with session_folder(args.data, args.keep,
                        lambda out: make_data(out, args.seed)) as (folder, truth):
        sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "truth")
        triggers = [Trigger(t["word"], t["start_s"], t["end_s"], source="truth")
                    for t in truth["triggers"]]
        tg = truth["target"]
        target = TargetSpec(tg["kind"], tg["rows"], tg["cols"], tg["size"], tg["spacing"])
        recording = [str(folder / truth["recording"])]
        figures = {}
        for name, opts in (("nearest", FrameSetOptions(search=False)),
                           ("search", FrameSetOptions(search=True))):
            times, cpu = [], []
            for _ in range(args.runs):
                with open_recording(recording) as source:
                    t0, c0 = time.perf_counter(), time.process_time()
                    analysis = analyse_frames(source, sync, triggers, target, options=opts)
                    times.append(time.perf_counter() - t0)
                    cpu.append(time.process_time() - c0)
            figures[name] = (statistics.median(times), times, analysis, statistics.median(cpu))
        print(f"frame processing, {len(triggers)} triggers x {CAMERAS} cameras, 1280x720 JPEG "
              f"(median of {args.runs} runs)")
        base = figures["nearest"][0]
        for name, (median, times, analysis, cpu) in figures.items():
            outside, total = score(analysis, truth)
            runs = ", ".join(f"{t:.2f}" for t in times)
            print(f"  {name:8s} {median:6.2f} s wall, {cpu:6.2f} s CPU  (runs {runs}; "
                  f"x{median / base:.2f} of nearest)  frames outside their hold: "
                  f"{outside}/{total}")
        search = figures["search"][0]
        verdict = "meets" if search <= TARGET_S else "MISSES"
        print(f"  target <= {TARGET_S:.0f} s with window search: {verdict} ({search:.2f} s)")
        cams = {c["name"]: c for c in truth["cameras"]}
        print("target corners in the chosen frames (window search), share of the board:")
        board = len(target.object_points())
        for stream in cams:
            counts = [f.corners or 0 for fs in figures["search"][2].sets for f in fs.frames
                      if f.stream == stream]
            whole = sum(c == board for c in counts)
            print(f"  {stream} ({cams[stream]['model']}): {np.mean(counts) / board:.2f}, "
                  f"whole board in {whole} of {len(counts)} frames")
        print("calibration check (window search):")
        print(f"  (load average during the run: {os.getloadavg()[0]:.1f} on "
              f"{os.cpu_count()} CPUs)")
        for stream, entry in figures["search"][2].calibration.items():
            cam = cams[stream]
            truth_k = np.asarray(cam["intrinsics"], float)
            line = f"  {stream} ({cam['model']}): best {entry['model']}"
            for model, fit in entry["models"].items():
                if model == "double-sphere":
                    fx, _fy, _cx, _cy, xi, alpha = fit["intrinsics"]
                    line += (f"; {model} rms {fit['rms_px']:.3f} px f/(1+xi) "
                             f"{fx / (1 + xi):.1f} xi {xi:.3f} alpha {alpha:.3f}")
                else:
                    err = np.abs(np.asarray(fit["intrinsics"][:4]) - truth_k) / truth_k
                    line += (f"; {model} rms {fit['rms_px']:.3f} px, "
                             f"max intrinsics error {err.max() * 100:.3f}%")
            print(line)
    return 0


if __name__ == "__main__":
    sys.exit(main())
