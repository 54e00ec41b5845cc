"""Find more like this on a long recording: memory held for the session and search time.

Writes a long 48 kHz mono WAV (room noise with word-length tone bursts, no speech needed)
into a temporary folder, then runs each measurement in a fresh process so peak RSS
belongs to it alone:

- baseline ``array``: the index built over the loaded 16 kHz samples and kept with them
  (as the review window did before: the whole audio held for the session);
- ``file``: :class:`SessionAudio` as the window uses it now (features kept, the stretches
  around each hit read back from the file).

Both run the same searches, whose results must be equal.

    python benchmarks/bench_find_similar.py              # a 2-hour file
    python benchmarks/bench_find_similar.py --minutes 20 --repeats 3

Prints figures and ratios; asserts nothing beyond equal results.
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

RATE = 48000
SEARCHES = 5


def _write(path: Path, minutes: float) -> None:
    """Noise with 0.4 s tone bursts (three pitches) every ~3 s, written a minute at a time."""
    import soundfile as sf

    rng = np.random.default_rng(3)
    with sf.SoundFile(str(path), "w", samplerate=RATE, channels=1, subtype="PCM_16") as f:
        for _minute in range(int(np.ceil(minutes))):
            n = RATE * 60
            x = 0.01 * rng.standard_normal(n)
            for start in np.arange(0.5, 59.0, 3.0) + rng.uniform(0, 1.5, 20):
                a = int(start * RATE)
                t = np.arange(int(0.4 * RATE)) / RATE
                hz = (300.0, 450.0, 700.0)[int(rng.integers(0, 3))]
                x[a:a + t.size] += 0.2 * np.sin(2 * np.pi * hz * t) * np.hanning(t.size)
            f.write(x.astype(np.float32))


def _rss_mb() -> float:
    with open("/proc/self/statm") as f:
        pages = int(f.read().split()[1])
    return pages * resource.getpagesize() / 1e6


def _measure(path: str, mode: str) -> dict:
    """One fresh process: build, then time the searches; memory in MB."""
    from speechcal_core.review.similar import SessionAudio
    from speechcal_core.speech.more_like import RATE as RATE16
    from speechcal_core.speech.more_like import find_more_like, word_near
    from speechcal_core.speech.speech_index import SpeechIndex

    rss0 = _rss_mb()
    t0 = time.perf_counter()
    if mode == "array":
        from speechcal_core.audio import load_audio

        audio = load_audio(path, rate=RATE16)
        index = SpeechIndex.build(audio.samples, RATE16)
        del audio
    else:
        index = SessionAudio(path).index()
    build_s = time.perf_counter() - t0
    held = _rss_mb() - rss0
    arrays = sum(a.nbytes for a in (index.full, index.seq, index.frames,
                                    index.activity.floor_db, index.activity.energy_db)
                 if a is not None)
    arrays += getattr(index.samples, "nbytes", 0)
    times, found = [], []
    for k in range(SEARCHES):
        t_mid = (k + 0.5) * index.duration_s / SEARCHES
        seg = next((s for s in index.activity.segments if s[0] >= t_mid), None)
        bounds = word_near(index.activity, (seg[0] + seg[1]) / 2) if seg else None
        if bounds is None:
            continue
        t1 = time.perf_counter()
        words = find_more_like(index, *bounds, "word")
        times.append(time.perf_counter() - t1)
        found.append([(w.start_s, w.end_s, w.score) for w in words])
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3
    return {"build_s": build_s, "held_mb": held, "arrays_mb": arrays / 1e6,
            "peak_mb": peak, "search_s": times, "found": found}


def _run(path: Path, mode: str) -> dict:
    out = subprocess.run([sys.executable, __file__, "--child", mode, str(path)],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=120.0)
    ap.add_argument("--repeats", type=int, default=1, help="processes per mode")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        print(json.dumps(_measure(args.child[1], args.child[0])))
        return
    with tempfile.TemporaryDirectory(prefix="bench_find_similar_") as tmp:
        path = Path(tmp) / "long.wav"
        t0 = time.perf_counter()
        _write(path, args.minutes)
        print(f"{args.minutes:g} min of 48 kHz audio ({path.stat().st_size / 1e6:.0f} MB "
              f"WAV) written in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        runs = {mode: [_run(path, mode) for _ in range(args.repeats)]
                for mode in ("array", "file")}
    same = runs["array"][0]["found"] == runs["file"][0]["found"]
    hits = sum(len(f) for f in runs["file"][0]["found"])
    print(f"find more like this, {args.minutes:g} min recording, "
          f"{len(runs['file'][0]['found'])} searches ({hits} hits), "
          f"medians of {args.repeats} process(es) per mode; results equal: {same}")
    print(f"{'mode':<22}{'held MB':>9}{'arrays MB':>11}{'peak MB':>9}{'build s':>9}"
          f"{'search ms':>11}")
    base = None
    for mode, label in (("array", "array (baseline)"), ("file", "file (SessionAudio)")):
        r = runs[mode]
        row = {k: statistics.median(x[k] for x in r)
               for k in ("held_mb", "arrays_mb", "peak_mb", "build_s")}
        row["search_ms"] = 1e3 * statistics.median(t for x in r for t in x["search_s"]) \
            if r[0]["search_s"] else float("nan")
        print(f"{label:<22}{row['held_mb']:>9.0f}{row['arrays_mb']:>11.1f}"
              f"{row['peak_mb']:>9.0f}{row['build_s']:>9.2f}{row['search_ms']:>11.1f}")
        if base is None:
            base = row
        else:
            print("ratio vs baseline     " + "".join(
                f"{row[k] / base[k]:>{w}.2f}" for k, w in
                (("held_mb", 9), ("arrays_mb", 11), ("peak_mb", 9), ("build_s", 9),
                 ("search_ms", 11))))
    if not same:
        print("WARNING: the two modes found different words", file=sys.stderr)


if __name__ == "__main__":
    main()
