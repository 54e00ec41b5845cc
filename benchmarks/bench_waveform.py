"""The review window's waveform on a long recording: memory held, peak, build and draw time.

Writes a long 48 kHz mono WAV (noise with tone bursts) into a temporary folder, then runs
each measurement in a fresh process so peak RSS belongs to it alone:

- baseline ``samples``: the pyramid as it was, every level from 16 samples per bucket
  over the whole audio loaded at the file's rate, kept with those samples;
- ``file``: :meth:`EnvelopePyramid.from_file` as the window uses it now (levels from 256
  samples per bucket, built block by block; finer views read back from the file).

Both draw the same views (zoomed out, seconds, milliseconds), whose results must be equal.

    python benchmarks/bench_waveform.py              # a 2-hour file
    python benchmarks/bench_waveform.py --minutes 20 --repeats 3

Prints figures and ratios; asserts nothing beyond equal results.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from long_audio import RATE, peak_rss_mb, rss_mb, run_child, write_tone_bursts

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

WIDTH = 1920
#: (view span in seconds, label): zoomed out, one bucket level of each kind, raw samples
SPANS = ((None, "whole"), (600.0, "10 min"), (15.0, "15 s"), (2.0, "2 s"), (0.03, "30 ms"))
VIEWS = 7  # positions per span


class SamplesPyramid:
    """The baseline: the pyramid before, all levels from 16 samples, samples kept."""

    def __init__(self, samples: np.ndarray, rate: float) -> None:
        self.samples = np.asarray(samples, dtype=np.float32)
        self.rate = float(rate)
        self.levels: list[tuple[int, np.ndarray, np.ndarray]] = []
        x = self.samples
        n = x.size - x.size % 16
        mn = x[:n].reshape(-1, 16).min(axis=1)
        mx = x[:n].reshape(-1, 16).max(axis=1)
        if n < x.size:
            mn, mx = np.append(mn, x[n:].min()), np.append(mx, x[n:].max())
        size = 16
        self.levels.append((size, mn, mx))
        while mn.size > 1:
            pad = (-mn.size) % 4
            if pad:
                mn = np.concatenate([mn, np.full(pad, mn[-1], np.float32)])
                mx = np.concatenate([mx, np.full(pad, mx[-1], np.float32)])
            mn, mx = mn.reshape(-1, 4).min(axis=1), mx.reshape(-1, 4).max(axis=1)
            size *= 4
            self.levels.append((size, mn, mx))

    @property
    def nbytes(self) -> int:
        return self.samples.nbytes + sum(a.nbytes + b.nbytes for _, a, b in self.levels)

    def envelope(self, t0: float, t1: float, width: int):
        n = self.samples.size
        i0 = int(np.clip(np.floor(t0 * self.rate), 0, n))
        i1 = int(np.clip(np.ceil(t1 * self.rate), 0, n))
        per_px = (i1 - i0) / width
        if per_px < 32:
            s = self.samples[i0:i1]
            return np.arange(i0, i1) / self.rate, s, s
        size, mn, mx = self.levels[0]
        for lv in self.levels:
            if lv[0] * 2 > per_px:
                break
            size, mn, mx = lv
        b0, b1 = i0 // size, min(-(-i1 // size), mn.size)
        edges = np.unique(np.linspace(b0, b1, width + 1).astype(np.int64))
        starts = edges[:-1]
        t = (starts * size + (edges[1:] - starts) * size / 2) / self.rate
        return (t, np.minimum.reduceat(mn[b0:b1], starts - b0),
                np.maximum.reduceat(mx[b0:b1], starts - b0))


def _measure(path: str, mode: str) -> dict:
    """One fresh process: build, then draw every view; memory in MB, times in s."""
    from speechcal_core.audio import EnvelopePyramid, load_audio

    rss0 = rss_mb()
    t0 = time.perf_counter()
    if mode == "samples":
        audio = load_audio(path)
        pyramid = SamplesPyramid(audio.samples, audio.rate)
        del audio
    else:
        pyramid = EnvelopePyramid.from_file(path)
    build_s = time.perf_counter() - t0
    held = rss_mb() - rss0
    arrays = pyramid.nbytes
    import soundfile as sf

    duration = sf.info(path).frames / RATE
    draw: dict[str, list[float]] = {}
    digest = hashlib.sha1()
    rng = np.random.default_rng(5)
    for span, label in SPANS:
        if span is not None and span >= duration:
            span = None  # a short file: the whole of it
        for _ in range(VIEWS):
            if span is None:
                a, b = 0.0, duration
            else:
                a = float(rng.uniform(0, duration - span))
                b = a + span
            t1 = time.perf_counter()
            out = pyramid.envelope(a, b, WIDTH)
            draw.setdefault(label, []).append(time.perf_counter() - t1)
            for arr in out:
                digest.update(np.ascontiguousarray(arr).tobytes())
    peak = peak_rss_mb()
    return {"build_s": build_s, "held_mb": held, "arrays_mb": arrays / 1e6,
            "peak_mb": peak, "draw_s": draw, "digest": digest.hexdigest()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=120.0)
    ap.add_argument("--repeats", type=int, default=1, help="processes per mode")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(_measure(args.child[1], args.child[0])))
        return
    with tempfile.TemporaryDirectory(prefix="bench_waveform_") as tmp:
        path = Path(tmp) / "long.wav"
        t0 = time.perf_counter()
        write_tone_bursts(path, args.minutes, (440.0,))
        print(f"{args.minutes:g} min of 48 kHz audio ({path.stat().st_size / 1e6:.0f} MB "
              f"WAV) written in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        runs = {mode: [run_child(__file__, mode, path) for _ in range(args.repeats)]
                for mode in ("samples", "file")}
    same = runs["samples"][0]["digest"] == runs["file"][0]["digest"]
    print(f"waveform envelope, {args.minutes:g} min recording at 48 kHz, {WIDTH} px, "
          f"medians of {args.repeats} process(es) per mode; views drawn equal: {same}")
    labels = [label for _, label in SPANS]
    print(f"{'mode':<20}{'held MB':>9}{'arrays MB':>11}{'peak MB':>9}{'build s':>9}"
          + "".join(f"{'ms ' + lb:>11}" for lb in labels))
    base = None
    for mode, name in (("samples", "samples (baseline)"), ("file", "file (from_file)")):
        r = runs[mode]
        row = {k: statistics.median(x[k] for x in r)
               for k in ("held_mb", "arrays_mb", "peak_mb", "build_s")}
        for lb in labels:
            row[lb] = 1e3 * statistics.median(t for x in r for t in x["draw_s"][lb])
        print(f"{name:<20}{row['held_mb']:>9.0f}{row['arrays_mb']:>11.1f}"
              f"{row['peak_mb']:>9.0f}{row['build_s']:>9.2f}"
              + "".join(f"{row[lb]:>11.2f}" for lb in labels))
        if base is None:
            base = row
        else:
            keys = ["held_mb", "arrays_mb", "peak_mb", "build_s", *labels]
            widths = [9, 11, 9, 9] + [11] * len(labels)
            print(f"{'ratio vs baseline':<20}" + "".join(
                f"{row[k] / base[k]:>{w}.2f}" for k, w in zip(keys, widths, strict=True)))
    if not same:
        print("WARNING: the two modes drew different envelopes", file=sys.stderr)


if __name__ == "__main__":
    main()
