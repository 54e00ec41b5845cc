"""Sync time with the clap search's frames read at the size each pass needs, against the
full-colour decoding it replaced, and whether the claps, offset and drift stay the same.

Run: ``.venv/bin/python benchmarks/bench_clap_decode.py [--seeds 0-4] [--size 320x240]
[--duration 60] [--claps 2] [--encoding jpeg] [--repeats 3] [--work DIR]``. Sessions are
bench_sync's (``speechcal synth``, two cameras, JPEG by default), made in a temporary
folder or kept in ``--work DIR`` (made there once, then reused).

Each session is synced in this process (its index built first, by a sync not timed), then
``--repeats`` times with each reading, alternately: the baseline ``read_baseline`` (every
frame decoded in full colour, then made gray and small, as before) and the current
:mod:`speechcal_core.sync.clap_frames` (a JPEG's luma decoded alone, area-resized for the
coarse pass, as it is for the fine pass). One JSON line per session: the median sync
times (wall clock, and this process's CPU time, steadier on a busy machine), their
ratios, and the differences of offset, drift and every camera clap between
the two readings; then a summary with the medians and the largest differences.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from pathlib import Path

from speechcal_core.audio import load_audio
from speechcal_core.sources import open_recording
from speechcal_core.sync import pipeline
from speechcal_core.sync.clap_video import gray_full, to_gray_small


def small_baseline(source, info, i, depth):
    """The coarse pass's frame as it was read (frozen here): decoded in full colour."""
    return to_gray_small(source.frame(info.name, i), depth=depth)


def full_baseline(source, info, i, depth):
    """The fine pass's frame as it was read (frozen here): decoded in full colour."""
    return gray_full(source.frame(info.name, i), depth)


READERS = {"read_baseline": (small_baseline, full_baseline),
           "clap_frames": (pipeline.small_gray, pipeline.full_gray)}


def make_session(args: argparse.Namespace, seed: int, work: Path) -> tuple[Path, dict]:
    """The session of ``seed`` (made when ``work`` does not hold it yet) and its truth."""
    enc = "" if args.encoding == "jpeg" else f"_{args.encoding}"
    out = work / (f"d{args.duration:g}_c{args.claps}_n{args.cameras}_{args.size}"
                  f"_p{args.drift_ppm:g}_s{seed}_{args.snr:g}{enc}")
    if not (out / "truth.json").exists():
        subprocess.run([sys.executable, "-m", "speechcal_core.cli", "synth", str(out),
                        "--cameras", str(args.cameras), "--duration", str(args.duration),
                        "--size", args.size, "--claps", str(args.claps), "--seed", str(seed),
                        "--snr", str(args.snr), "--drift-ppm", str(args.drift_ppm),
                        "--encoding", args.encoding, "--force"],
                       check=True, capture_output=True)
    return out, json.loads((out / "truth.json").read_text())


def _sync(reader: str, source, audio):
    """Sync with the frames read by ``reader``: (result, wall seconds, CPU seconds)."""
    kept = pipeline.small_gray, pipeline.full_gray
    pipeline.small_gray, pipeline.full_gray = READERS[reader]
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        result = pipeline.sync_recording(source, audio)
        return result, time.perf_counter() - t0, time.process_time() - c0
    finally:
        pipeline.small_gray, pipeline.full_gray = kept


def _claps(result) -> list[tuple[str, int]]:
    return [(c.name, c.clap_ns) for clap in result.claps for c in clap.cameras]


def run(args: argparse.Namespace, seed: int, work: Path) -> dict:
    """Both readings on one session: median sync times, ratio and differences."""
    out, truth = make_session(args, seed, work)
    with open_recording([str(out / truth["recording"])]) as source:
        audio = load_audio(str(out / "audio.ogg"))
        pipeline.sync_recording(source, audio)  # the index, and the files in the page cache
        times: dict[str, list[float]] = {name: [] for name in READERS}
        cpu: dict[str, list[float]] = {name: [] for name in READERS}
        results = {}
        for _ in range(args.repeats):
            for name in READERS:
                results[name], s, c = _sync(name, source, audio)
                times[name].append(s)
                cpu[name].append(c)
    old, new = results["read_baseline"], results["clap_frames"]
    old_claps, new_claps = _claps(old), _claps(new)
    same_cams = [a[0] for a in old_claps] == [b[0] for b in new_claps]
    base_s = statistics.median(times["read_baseline"])
    new_s = statistics.median(times["clap_frames"])
    base_cpu = statistics.median(cpu["read_baseline"])
    new_cpu = statistics.median(cpu["clap_frames"])
    return {
        "seed": seed, "sync_baseline_s": round(base_s, 3), "sync_s": round(new_s, 3),
        "ratio": round(base_s / new_s, 2), "cpu_baseline_s": round(base_cpu, 3),
        "cpu_s": round(new_cpu, 3), "cpu_ratio": round(base_cpu / new_cpu, 2),
        "same_cameras": same_cams,
        "claps": len(new.claps), "claps_baseline": len(old.claps),
        "offset_diff_ns": new.model.offset_ns - old.model.offset_ns,
        "drift_diff_ppm": round((new.model.drift - old.model.drift) * 1e6, 4),
        "max_clap_diff_ns": max((abs(a[1] - b[1]) for a, b in zip(old_claps, new_claps,
                                                                   strict=False)), default=0),
    }


def main() -> int:
    """Run the benchmark and print one JSON line per session plus a summary."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", default="0-4")
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--cameras", type=int, default=2)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--claps", type=int, default=2)
    ap.add_argument("--snr", type=float, default=20.0)
    ap.add_argument("--drift-ppm", type=float, default=40.0)
    ap.add_argument("--encoding", default="jpeg")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--work", help="keep the sessions here (made once, then reused)")
    args = ap.parse_args()
    lo, _, hi = args.seeds.partition("-")
    rows = []
    with ExitStack() as stack:
        work = Path(args.work) if args.work else Path(stack.enter_context(
            tempfile.TemporaryDirectory()))
        for seed in range(int(lo), int(hi or lo) + 1):
            rows.append(run(args, seed, work))
            print(json.dumps(rows[-1]), flush=True)
    print(json.dumps({
        "sessions": len(rows), "size": args.size, "encoding": args.encoding,
        "baseline": "read_baseline (every frame decoded in full colour, then made gray)",
        "median_sync_baseline_s": round(statistics.median(r["sync_baseline_s"] for r in rows), 3),
        "median_sync_s": round(statistics.median(r["sync_s"] for r in rows), 3),
        "median_ratio": round(statistics.median(r["ratio"] for r in rows), 2),
        "median_cpu_baseline_s": round(statistics.median(r["cpu_baseline_s"] for r in rows), 3),
        "median_cpu_s": round(statistics.median(r["cpu_s"] for r in rows), 3),
        "median_cpu_ratio": round(statistics.median(r["cpu_ratio"] for r in rows), 2),
        "all_same_claps": all(r["same_cameras"] and r["claps"] == r["claps_baseline"]
                              for r in rows),
        "max_offset_diff_ns": max(abs(r["offset_diff_ns"]) for r in rows),
        "max_drift_diff_ppm": max(abs(r["drift_diff_ppm"]) for r in rows),
        "max_clap_diff_ns": max(r["max_clap_diff_ns"] for r in rows),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
