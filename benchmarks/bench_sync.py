"""Sync accuracy on synthetic sessions: audio clap, camera clap, offset and drift errors.

Run: ``.venv/bin/python benchmarks/bench_sync.py [--seeds 0-5] [--claps 2] [--duration 60]
[--snr 0,10,30]``. Sessions are made by ``speechcal synth`` in a temporary folder and
scored against their truth.json; one line per session, then the worst figures.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _run(args: argparse.Namespace, seed: int, snr: float, work: Path) -> dict:
    out = work / f"s{seed}_{snr:g}"
    cmd = [sys.executable, "-m", "speechcal_core.cli", "synth", str(out), "--cameras",
           str(args.cameras), "--duration", str(args.duration), "--size", args.size,
           "--claps", str(args.claps), "--seed", str(seed), "--snr", str(snr),
           "--drift-ppm", str(args.drift_ppm)]
    subprocess.run(cmd, check=True, capture_output=True)
    truth = json.loads((out / "truth.json").read_text())
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "speechcal_core.cli", "sync",
                        str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                        "--json"], capture_output=True, text=True)
    elapsed = time.perf_counter() - t0
    if p.returncode:
        return {"seed": seed, "snr": snr, "error": p.stderr.strip()}
    doc = json.loads(p.stdout)
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    cam_ms = [(k["clap_ns"] - t["session_ns"] - offsets[k["name"]]) / 1e6
              for c, t in zip(doc["claps"], truth["claps"], strict=False) for k in c["cameras"]]
    t_a = truth["claps"][0]["audio_s"]
    true_at = truth["sync"]["offset_ns"] + round(t_a * truth["sync"]["drift"] * 1e9)
    got_at = doc["offset_ns"] + round(t_a * doc["drift"] * 1e9)
    return {
        "seed": seed, "snr": snr, "claps_found": len(doc["claps"]),
        "claps_true": len(truth["claps"]),
        "audio_ms": [round((c["audio_s"] - t["audio_s"]) * 1e3, 3)
                     for c, t in zip(doc["claps"], truth["claps"], strict=False)],
        "camera_ms": [round(v, 2) for v in cam_ms],
        "offset_at_clap_ms": round((got_at - true_at) / 1e6, 3),
        "drift_error_ppm": round((doc["drift"] - truth["sync"]["drift"]) * 1e6, 2),
        "sync_s": round(elapsed, 2), "warnings": doc["warnings"],
    }


def main() -> int:
    """Run the benchmark and print one JSON line per session plus a summary."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", default="0-4")
    ap.add_argument("--snr", default="20")
    ap.add_argument("--claps", type=int, default=2)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--cameras", type=int, default=2)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--drift-ppm", type=float, default=40.0)
    args = ap.parse_args()
    lo, _, hi = args.seeds.partition("-")
    seeds = range(int(lo), int(hi or lo) + 1)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            for snr in (float(s) for s in args.snr.split(",")):
                row = _run(args, seed, snr, Path(tmp))
                rows.append(row)
                print(json.dumps(row), flush=True)
    ok = [r for r in rows if "error" not in r]
    audio = [abs(v) for r in ok for v in r["audio_ms"]]
    summary = {
        "sessions": len(rows), "failed": len(rows) - len(ok),
        "all_claps_found": sum(r["claps_found"] == r["claps_true"] for r in ok),
        "max_audio_ms": max(audio, default=None),
        "max_camera_ms": max((abs(v) for r in ok for v in r["camera_ms"]), default=None),
        "max_offset_ms": max((abs(r["offset_at_clap_ms"]) for r in ok), default=None),
    }
    if args.claps == 2:
        summary["max_drift_error_ppm"] = max((abs(r["drift_error_ppm"]) for r in ok),
                                             default=None)
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
