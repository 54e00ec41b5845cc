"""Find more like this on a long recording: memory held for the session and search time.

Writes a long 48 kHz mono WAV (room noise with word-length tone bursts, no speech needed)
into a temporary folder, then runs each measurement in a fresh process so peak RSS
belongs to it alone:

- baseline ``array``: the index built over the loaded 16 kHz samples and kept with them
  (as the review window did before: the whole audio held for the session);
- ``whole``: the index as :class:`SessionAudio` built it before decoding block by block
  (the whole file decoded at its own rate, then resampled; features kept, samples read
  back from the file): the baseline for the index load's peak;
- ``file``: :class:`SessionAudio` as the window uses it now (decoded and resampled block
  by block, features kept, the stretches around each hit read back from the file).

All run the same searches, whose results must be equal.

    python benchmarks/bench_find_similar.py              # a 2-hour file
    python benchmarks/bench_find_similar.py --minutes 20 --repeats 3

Prints figures and ratios; asserts nothing beyond equal results.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

from long_audio import peak_rss_mb, rss_mb, run_child, write_tone_bursts

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

SEARCHES = 5
MODES = ("array", "whole", "file")


def _measure(path: str, mode: str) -> dict:
    """One fresh process: build, then time the searches; memory in MB."""
    from speechcal_core.review.similar import SessionAudio
    from speechcal_core.speech.more_like import RATE as RATE16
    from speechcal_core.speech.more_like import find_more_like, word_near
    from speechcal_core.speech.speech_index import SpeechIndex

    rss0 = rss_mb()
    t0 = time.perf_counter()
    if mode == "array":
        from speechcal_core.audio import load_audio

        audio = load_audio(path, rate=RATE16)
        index = SpeechIndex.build(audio.samples, RATE16)
        del audio
    elif mode == "whole":
        from speechcal_core.audio import load_audio
        from speechcal_core.audio.file_samples import FileSamples

        native = load_audio(path)
        reader = FileSamples(path, RATE16, rate_in=native.rate, size_in=native.samples.size)
        samples = native.resampled(RATE16).samples
        del native
        index = SpeechIndex.build(samples, RATE16).with_samples(reader)
        del samples
    else:
        index = SessionAudio(path).index()
    build_s = time.perf_counter() - t0
    held = rss_mb() - rss0
    arrays = sum(a.nbytes for a in (index.seq, index.frames,
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
    peak = peak_rss_mb()
    return {"build_s": build_s, "held_mb": held, "arrays_mb": arrays / 1e6,
            "peak_mb": peak, "search_s": times, "found": found}


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
        write_tone_bursts(path, args.minutes)
        print(f"{args.minutes:g} min of 48 kHz audio ({path.stat().st_size / 1e6:.0f} MB "
              f"WAV) written in {time.perf_counter() - t0:.1f} s", file=sys.stderr)
        runs = {mode: [run_child(__file__, mode, path) for _ in range(args.repeats)]
                for mode in MODES}
    same = all(runs[m][0]["found"] == runs["file"][0]["found"] for m in MODES)
    hits = sum(len(f) for f in runs["file"][0]["found"])
    print(f"find more like this, {args.minutes:g} min recording, "
          f"{len(runs['file'][0]['found'])} searches ({hits} hits), "
          f"medians of {args.repeats} process(es) per mode; results equal: {same}")
    print(f"{'mode':<22}{'held MB':>9}{'arrays MB':>11}{'peak MB':>9}{'build s':>9}"
          f"{'search ms':>11}")
    base = None
    for mode, label in (("array", "array (baseline)"), ("whole", "whole-file decode"),
                        ("file", "file (SessionAudio)")):
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
            print("  ratio vs baseline   " + "".join(
                f"{row[k] / base[k]:>{w}.2f}" for k, w in
                (("held_mb", 9), ("arrays_mb", 11), ("peak_mb", 9), ("build_s", 9),
                 ("search_ms", 11))))
    if not same:
        print("WARNING: the modes found different words", file=sys.stderr)


if __name__ == "__main__":
    main()
