"""Benchmark the clap search on one big camera stream: peak memory and time.

Generates a one-camera 1280x720 JPEG session (``speechcal synth``'s generator) in a temporary
folder, or takes ``--data`` (any synthetic session) and ``--stream``, then runs on that camera's
first ``SEARCH_S`` seconds, each run in a fresh process so that every peak is its own:

- ``decode`` (the baseline): every frame of the window read, decoded and reduced to the work
  size once, nothing kept: what any clap search has to do at least;
- ``search``: ``video_clap_candidates`` (work-size stack, motion events, full-resolution timing).

Prints the median wall time and the median peak resident memory above what the process held
before the call (imports, the open recording), with the search's ratios to the baseline.

    .venv/bin/python benchmarks/bench_clap_memory.py [--runs 3] [--data DIR --stream NAME] [--keep]
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from bench_data import session_folder

from speechcal_core.sources import open_recording
from speechcal_core.sources.depth import stream_depth
from speechcal_core.sync.clap_video import to_gray_small
from speechcal_core.sync.pipeline import SEARCH_S, video_clap_candidates
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.session import generate_session

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource

MODES = ("decode", "search")


def make_data(out: Path, seed: int) -> dict:
    """A one-camera 1280x720 JPEG session a little longer than the search window."""
    options = SynthOptions(cameras=1, duration=SEARCH_S + 5, width=1280, height=720,
                           encoding="jpeg", seed=seed)
    t0 = time.perf_counter()
    truth = generate_session(out, options, force=True)
    print(f"generated the session in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    return truth


def _status_mb(key: str) -> float | None:
    """A ``/proc/self/status`` memory figure (VmRSS, VmHWM) in MB; None off Linux."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return None


def _reset_peak() -> bool:
    """Start VmHWM afresh from the current RSS (Linux 4.0+); False where that is not possible."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
        return True
    except OSError:
        return False


def _decode_once(source: FrameSource, stream: str, t0_ns: int, t1_ns: int) -> int:
    """The baseline: each frame of the window decoded and made work-size, nothing kept."""
    stamps = source.stamps(stream)
    i0, i1 = np.searchsorted(stamps, [t0_ns, t1_ns])
    depth = stream_depth(source, stream)
    for i in range(int(i0), int(i1)):
        to_gray_small(source.frame(stream, i), depth=depth)
    return int(i1 - i0)


def child(mode: str, recording: str, stream: str) -> dict:
    """One measured run in this (fresh) process."""
    with open_recording([recording]) as source:
        info = next(s for s in source.streams if s.name == stream)
        t0, t1 = info.first_ns, min(info.last_ns, info.first_ns + int(SEARCH_S * 1e9))
        stream_depth(source, stream)  # read before the measurement by both modes alike
        gc.collect()
        before = _status_mb("VmRSS")
        exact = _reset_peak()
        start = time.perf_counter()
        out: dict = {"mode": mode}
        if mode == "decode":
            _decode_once(source, stream, t0, t1)
        else:
            found = video_clap_candidates(source, stream, t0, t1)
            out["claps"] = [c.to_dict() for c in found]
        out["wall_s"] = time.perf_counter() - start
        peak = _status_mb("VmHWM")
        out.update(before_mb=before, peak_mb=peak, peak_is_call=exact,
                   frames=int(np.searchsorted(source.stamps(stream), t1)
                              - np.searchsorted(source.stamps(stream), t0)),
                   width=info.width, height=info.height, encoding=info.encoding)
    return out


def _run_child(mode: str, recording: str, stream: str) -> dict:
    cmd = [sys.executable, __file__, "--child", mode, "--recording", recording,
           "--stream", stream]
    p = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> int:
    """Run the benchmark and print its figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--data", help="use (or create) this session folder instead of a temp one")
    parser.add_argument("--stream", help="the camera to search (default: the first)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary folder")
    parser.add_argument("--child", choices=MODES, help=argparse.SUPPRESS)
    parser.add_argument("--recording", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(args.child, args.recording, args.stream)))
        return 0

    with session_folder(args.data, args.keep,
                        lambda out: make_data(out, args.seed)) as (folder, truth):
        recording = str(folder / truth["recording"])
        stream = args.stream or truth["cameras"][0]["name"]
        runs: dict[str, list[dict]] = {m: [] for m in MODES}
        for _ in range(args.runs):
            for mode in MODES:  # interleaved, so that a change of machine load hits both
                runs[mode].append(_run_child(mode, recording, stream))
        first = runs["search"][0]
        frames, w, h = first["frames"], first["width"], first["height"]
        print(f"clap search on {stream}: {w}x{h} {first['encoding']}, {frames} frames in the "
              f"first {SEARCH_S:g} s (median of {args.runs} runs, each in a fresh process)")
        figures = {}
        for mode in MODES:
            wall = statistics.median(r["wall_s"] for r in runs[mode])
            rise = statistics.median(r["peak_mb"] - r["before_mb"] for r in runs[mode]
                                     if r["peak_mb"] is not None)
            held = statistics.median(r["before_mb"] for r in runs[mode] if r["before_mb"])
            figures[mode] = (wall, rise, held)
        base_wall, base_rise, _ = figures["decode"]
        for mode in MODES:
            wall, rise, held = figures[mode]
            times = ", ".join(f"{r['wall_s']:.2f}" for r in runs[mode])
            ratio = "" if mode == "decode" else (
                f"; x{wall / base_wall:.2f} the time and +{rise - base_rise:.0f} MB "
                f"(x{rise / max(base_rise, 1.0):.1f}) the peak of decode")
            label = "decode (baseline)" if mode == "decode" else mode
            print(f"  {label:18s} {wall:6.2f} s wall (runs {times}), peak {rise:6.0f} MB above "
                  f"the {held:.0f} MB held before{ratio}")
        if not all(r["peak_is_call"] for m in MODES for r in runs[m]):
            print("  (the peak could not be reset: it includes opening the recording)")
        print(f"  for scale: the window's frames as full-resolution float32 would take "
              f"{frames * w * h * 4 / 2**30:.2f} GB, as the work-size stack "
              f"{frames * 4 * 160 * round(h * 160 / w) / 2**20:.0f} MB")
        claps = first.get("claps") or []
        if claps:
            c = claps[0]
            same = all(r.get("claps") == claps for r in runs["search"])
            print(f"  clap at {c['clap_ns']} ns ({c['method']}, score {c['score']}), "
                  f"{len(claps)} candidate(s); every run the same: {same}")
        else:
            print("  no clap found")
    return 0


if __name__ == "__main__":
    sys.exit(main())
