"""Sync accuracy on synthetic sessions: audio clap, camera clap, offset and drift errors,
and the clap V fit's time against its baseline.

Run: ``.venv/bin/python benchmarks/bench_sync.py [--seeds 0-5] [--claps 2] [--duration 60]
[--snr 0,10,30] [--work DIR]``. Sessions are made by ``speechcal synth`` in a temporary
folder (or kept in ``--work DIR``: made there once, then reused) and scored against their
truth.json; one line per session, then the worst figures (with two claps also the median
and worst drift error, the seed of the worst, and how many sessions have a note on the
drift).

How the cameras' clap times are combined into the clap's session time (which sets the
offset) is compared in the same run: the code's weighting (inverse frame period squared,
for two cameras within a frame of each other) against ``session_ns_inverse_variance``
below, each camera counted by the inverse variance of its V fit's timing (its standard
error, at least ``estimate.MIN_TIMING_SD_NS``), as the drift counts them. For each, the
offset's error at the first clap and the clap's timing error (the synthetic cameras'
clock offsets, a few ms, taken out: that part of the offset error no weighting can mend).

The V fit (``clap_video._fit_v``) is timed in the same run against the baseline
``fit_v_baseline`` below, the fit as it was (one ``np.linalg.lstsq`` per grid vertex): each
session is synced in this process once with each (the baseline first), giving both sync
times and any difference of offset, drift or camera clap; then the V fits that sync made
are timed alone, the median of ``--repeats`` runs of all of them.
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
from dataclasses import replace
from pathlib import Path

import numpy as np
from timing import median_ms

from speechcal_core.audio import load_audio
from speechcal_core.sources import open_recording
from speechcal_core.sync import clap_video
from speechcal_core.sync.estimate import Clap, SyncResult, timing_sd_ns
from speechcal_core.sync.pipeline import sync_recording


def fit_v_baseline(x: np.ndarray, y: np.ndarray, t_min: float,
                   period: float) -> tuple[float | None, float]:
    """The V fit before it was batched (frozen here as the baseline): a least-squares
    solve per vertex of the grid."""
    grid = np.arange(t_min - 0.25 - period, t_min + 0.25 + period, 2.5e-4)
    best, best_err = None, np.inf
    for tc in grid:
        b = np.stack([np.ones_like(x), np.minimum(x - tc, 0.0), np.maximum(x - tc, 0.0)],
                     axis=1)
        if (x < tc).sum() < 2 or (x > tc).sum() < 1:
            continue
        coef, *_ = np.linalg.lstsq(b, y, rcond=None)
        if coef[1] >= 0 or coef[2] <= 0:
            continue
        err = float(np.sum((b @ coef - y) ** 2))
        if err < best_err:
            best, best_err = float(tc), err
    return best, best_err


def session_ns_inverse_variance(clap: Clap) -> int:
    """The clap's session time with each camera counted by the inverse variance of its
    timing (:func:`estimate.timing_sd_ns`), where the code counts it by its frame rate
    (the same median of three cameras or more, the same clearer of two a frame apart)."""
    if clap.session_override_ns is not None or len(clap.cameras) != 2 \
            or clap._clearer_of_two() is not None:
        return clap.session_ns
    stamps = np.array([c.clap_ns for c in clap.cameras], dtype=np.int64)
    base = int(stamps.min())
    w = np.array([1.0 / timing_sd_ns(c) ** 2 for c in clap.cameras])
    return base + round(float(np.sum(w * (stamps - base)) / np.sum(w)))


def _offset_weights(result, truth: dict, offset_at_clap_ms: float) -> dict:
    """The first clap's offset error (ms) and timing error (cameras' clock offsets taken
    out) with frame-rate weights (the code's) and with inverse-variance weights."""
    clap, true = result.claps[0], truth["claps"][0]
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    exact = replace(clap, cameras=tuple(replace(c, clap_ns=true["session_ns"] + offsets[c.name])
                                        for c in clap.cameras))
    rate = clap.session_ns
    ivar = session_ns_inverse_variance(clap)
    return {
        "offset_rate_ms": offset_at_clap_ms,
        "offset_ivar_ms": round(offset_at_clap_ms + (ivar - rate) / 1e6, 3),
        "timing_rate_ms": round((rate - exact.session_ns) / 1e6, 3),
        "timing_ivar_ms": round((ivar - session_ns_inverse_variance(exact)) / 1e6, 3),
    }


def _sync_with(fit, recording: Path, audio: Path, calls: list | None = None):
    """Sync in this process with ``fit`` as the V fit: (result, seconds); ``calls``
    collects the fits' arguments."""
    def recorded(*args):
        if calls is not None:
            calls.append(args)
        return fit(*args)

    kept = clap_video._fit_v
    clap_video._fit_v = recorded
    try:
        with open_recording([str(recording)]) as src:
            sound = load_audio(str(audio))
            t0 = time.perf_counter()
            result = sync_recording(src, sound)
            return result, time.perf_counter() - t0
    finally:
        clap_video._fit_v = kept


def _compare_fit(out: Path, truth: dict, repeats: int) -> tuple[dict, SyncResult]:
    """The V fit against its baseline on one session: sync times, fit times, differences;
    and the sync made with the current fit."""
    recording, audio = out / truth["recording"], out / "audio.ogg"
    old, old_s = _sync_with(fit_v_baseline, recording, audio)
    calls: list = []
    new, new_s = _sync_with(clap_video._fit_v, recording, audio, calls)
    old_clap = [c.clap_ns for clap in old.claps for c in clap.cameras]
    new_clap = [c.clap_ns for clap in new.claps for c in clap.cameras]
    fit_old = median_ms(lambda: [fit_v_baseline(*a) for a in calls], repeats)
    fit_new = median_ms(lambda: [clap_video._fit_v(*a) for a in calls], repeats)
    return {
        "v_fits": len(calls),
        "fits_baseline_ms": round(fit_old, 1), "fits_ms": round(fit_new, 2),
        "fits_ratio": round(fit_old / fit_new, 1),
        "sync_baseline_s": round(old_s, 2), "sync_new_s": round(new_s, 2),
        "same_claps": len(old_clap) == len(new_clap),
        "offset_diff_ns": new.model.offset_ns - old.model.offset_ns,
        "drift_diff_ppm": (new.model.drift - old.model.drift) * 1e6,
        "max_clap_diff_ns": max((abs(a - b) for a, b in zip(old_clap, new_clap,
                                                            strict=False)), default=0),
    }, new


def _run(args: argparse.Namespace, seed: int, snr: float, work: Path) -> dict:
    out = work / (f"d{args.duration:g}_c{args.claps}_n{args.cameras}_{args.size}"
                  f"_p{args.drift_ppm:g}_s{seed}_{snr:g}")
    cmd = [sys.executable, "-m", "speechcal_core.cli", "synth", str(out), "--cameras",
           str(args.cameras), "--duration", str(args.duration), "--size", args.size,
           "--claps", str(args.claps), "--seed", str(seed), "--snr", str(snr),
           "--drift-ppm", str(args.drift_ppm), "--force"]
    if not (out / "truth.json").exists():
        subprocess.run(cmd, check=True, capture_output=True)
    truth = json.loads((out / "truth.json").read_text())
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "speechcal_core.cli", "sync",
                        str(out / truth["recording"]), "--audio", str(out / "audio.ogg"),
                        "--json"], capture_output=True, text=True)
    elapsed = time.perf_counter() - t0
    if p.returncode:
        return {"seed": seed, "snr": snr, "error": p.stderr.strip()}
    fit, result = _compare_fit(out, truth, args.repeats)  # after the index the sync kept
    doc = json.loads(p.stdout)
    offsets = {c["name"]: c["clock_offset_ns"] for c in truth["cameras"]}
    cam_ms = [(k["clap_ns"] - t["session_ns"] - offsets[k["name"]]) / 1e6
              for c, t in zip(doc["claps"], truth["claps"], strict=False) for k in c["cameras"]]
    t_a = truth["claps"][0]["audio_s"]
    true_at = truth["sync"]["offset_ns"] + round(t_a * truth["sync"]["drift"] * 1e9)
    got_at = doc["offset_ns"] + round(t_a * doc["drift"] * 1e9)
    offset_ms = round((got_at - true_at) / 1e6, 3)
    return {
        "seed": seed, "snr": snr, "claps_found": len(doc["claps"]),
        "claps_true": len(truth["claps"]),
        "audio_ms": [round((c["audio_s"] - t["audio_s"]) * 1e3, 3)
                     for c, t in zip(doc["claps"], truth["claps"], strict=False)],
        "camera_ms": [round(v, 2) for v in cam_ms],
        "offset_at_clap_ms": offset_ms, **_offset_weights(result, truth, offset_ms),
        "drift_error_ppm": round((doc["drift"] - truth["sync"]["drift"]) * 1e6, 2),
        "sync_s": round(elapsed, 2), "warnings": doc["warnings"], **fit,
    }


def _median(values) -> float | None:
    values = list(values)
    return round(statistics.median(values), 2) if values else None


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
    ap.add_argument("--repeats", type=int, default=5, help="runs of the V fits timed alone")
    ap.add_argument("--work", help="keep the sessions here (made once, then reused)")
    args = ap.parse_args()
    lo, _, hi = args.seeds.partition("-")
    seeds = range(int(lo), int(hi or lo) + 1)
    rows = []
    with ExitStack() as stack:
        tmp = args.work or stack.enter_context(tempfile.TemporaryDirectory())
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
        "v_fit": {
            "baseline": "fit_v_baseline (one np.linalg.lstsq per vertex)",
            "median_fits_baseline_ms": _median(r["fits_baseline_ms"] for r in ok),
            "median_fits_ms": _median(r["fits_ms"] for r in ok),
            "median_fits_ratio": _median(r["fits_ratio"] for r in ok),
            "median_sync_baseline_s": _median(r["sync_baseline_s"] for r in ok),
            "median_sync_new_s": _median(r["sync_new_s"] for r in ok),
            "max_offset_diff_ns": max((abs(r["offset_diff_ns"]) for r in ok), default=None),
            "max_drift_diff_ppm": max((abs(r["drift_diff_ppm"]) for r in ok), default=None),
            "max_clap_diff_ns": max((r["max_clap_diff_ns"] for r in ok), default=None),
            "all_same_claps": all(r["same_claps"] for r in ok),
        },
    }
    summary["median_offset_ms"] = _median(abs(r["offset_at_clap_ms"]) for r in ok)
    summary["offset_weights"] = {
        "baseline": "frame-rate weights (the code's); candidate: session_ns_inverse_variance",
    }
    for key in ("offset_rate", "offset_ivar", "timing_rate", "timing_ivar"):
        errors = [abs(r[f"{key}_ms"]) for r in ok]
        summary["offset_weights"][f"median_{key}_ms"] = _median(errors)
        summary["offset_weights"][f"max_{key}_ms"] = max(errors, default=None)
    if args.claps == 2:
        drift = [abs(r["drift_error_ppm"]) for r in ok]
        worst = max(ok, key=lambda r: abs(r["drift_error_ppm"]), default=None)
        summary["median_drift_error_ppm"] = _median(drift)
        summary["max_drift_error_ppm"] = max(drift, default=None)
        summary["worst_drift_seed"] = worst["seed"] if worst else None
        summary["drift_noted"] = sum(any("drift" in w for w in r["warnings"]) for r in ok)
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
