"""Trigger detection against the synthetic sessions' truth: ours versus naive keyphrase spotting.

Renders microphone tracks with the synth's audio renderer (the audio of ``speechcal
synth``: trigger words in several recorded voices, distractors and near-homophones,
reverb, room noise, claps) at 20, 10 and 5 dB SNR, runs the default pocketsphinx detector
and plain pocketsphinx keyphrase spotting on the same audio, and prints recall,
precision, median and 95th-percentile |t - truth| and the real-time factor side by side.
Then times a 2-hour noise file (made in a temporary folder, deleted afterwards).

    python benchmarks/bench_triggers.py                 # 3 sessions x 200 s per SNR
    python benchmarks/bench_triggers.py --sessions 1 --duration 60 --no-long
    python benchmarks/bench_triggers.py --first-seed 101 --duration 120 --no-long  # tuning
    python benchmarks/bench_triggers.py --workers 1     # decoding in this process only

Seeds 1-3 (the default) give the reported figures; tune on others (101 and up).

Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from speechcal_core.audio import Audio, load_audio  # noqa: E402
from speechcal_core.speech import TriggerSpec, Word, match_triggers  # noqa: E402
from speechcal_core.speech.lexicon import model_dir  # noqa: E402
from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend  # noqa: E402

RATE = 16000
MATCH_SLACK_S = 0.1  # a detection counts when its t falls inside the word +- this


def render(out: Path, snr: float, seed: int, duration: float, word: str) -> tuple[Path, list]:
    """One synthetic microphone track and its trigger truth."""
    from speechcal_core.synth.audio import render_audio
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.timeline import plan_session

    timeline = plan_session(SynthOptions(duration=duration, seed=seed, snr_db=snr,
                                         trigger_word=word))
    path = out / f"{word}_{snr:g}_{seed}.ogg"
    truth = render_audio(timeline, path)
    return path, truth.triggers


class NaiveKeyphrase:
    """Plain pocketsphinx keyphrase spotting over the whole file (the baseline)."""

    name = "naive-kws"

    def __init__(self, threshold: float = 1e-20) -> None:
        self.threshold = threshold

    def words(self, audio: Audio, spec: TriggerSpec) -> list[Word]:
        import pocketsphinx

        mdir = model_dir()
        decoder = pocketsphinx.Decoder(hmm=str(mdir / "en-us"),
                                       dict=str(mdir / "cmudict-en-us.dict"),
                                       keyphrase=spec.words[0], kws_threshold=self.threshold,
                                       loglevel="ERROR")
        x = audio.samples
        pcm = (np.clip(x, -1, 1) * 32767).astype(np.int16)
        decoder.start_utt()
        for a in range(0, pcm.size, RATE * 10):
            decoder.process_raw(pcm[a:a + RATE * 10].tobytes(), full_utt=False)
        decoder.end_utt()
        return [Word(s.word.strip(), s.start_frame / 100, (s.end_frame + 1) / 100, 1.0,
                     self.name) for s in decoder.seg() or []]


def label(detector: PocketsphinxBackend | NaiveKeyphrase) -> str:
    """A detector's name in the printed rows: ours is "speechcal" (the naive spotter runs
    on pocketsphinx too)."""
    return "speechcal" if isinstance(detector, PocketsphinxBackend) else detector.name


def measure(detector: PocketsphinxBackend | NaiveKeyphrase, audio: Path | Audio,
            spec: TriggerSpec, truth: list[dict], totals: list) -> Audio:
    """Run ``detector`` on ``audio`` (a file's loading timed too) and add to ``totals`` its
    true positives, detections, truth count, errors, wall and CPU seconds; returns the
    audio."""
    t0, c0 = time.perf_counter(), time.process_time()
    if isinstance(audio, Path):
        audio = load_audio(audio, rate=RATE)
    found = match_triggers(detector.words(audio, spec), spec)
    dt, dc = time.perf_counter() - t0, time.process_time() - c0 + worker_cpu_s(detector)
    for k, value in enumerate((*score(found, truth), dt, dc)):
        totals[k] += value
    return audio


def worker_cpu_s(detector: object) -> float:
    """CPU seconds the detector's worker processes spent on its last call."""
    return float(getattr(detector, "last_worker_cpu_s", 0.0))


def score(found: list[Word], truth: list[dict]) -> tuple[int, int, int, list[float]]:
    """True positives, detections, truth count and |t - truth| of the true positives."""
    used: set[int] = set()
    errors = []
    for w in found:
        for i, tr in enumerate(truth):
            if i not in used and tr["start_s"] - MATCH_SLACK_S <= w.t <= tr["end_s"] + \
                    MATCH_SLACK_S:
                used.add(i)
                errors.append(abs(w.t - (tr["start_s"] + tr["end_s"]) / 2))
                break
    return len(used), len(found), len(truth), errors


def row(name: str, snr: float, tp: int, n_found: int, n_truth: int, errors: list[float],
        seconds: float, cpu_s: float, audio_s: float) -> str:
    rec = tp / n_truth if n_truth else float("nan")
    prec = tp / n_found if n_found else float("nan")
    med = np.median(errors) * 1000 if errors else float("nan")
    p95 = np.percentile(errors, 95) * 1000 if errors else float("nan")
    return (f"{snr:>5g} dB  {name:<13} recall {rec:5.3f}  precision {prec:5.3f}  "
            f"median {med:5.1f} ms  p95 {p95:5.1f} ms  RTF {seconds / audio_s:6.4f} "
            f"(CPU {cpu_s / audio_s:6.4f})  "
            f"({tp}/{n_truth} found, {n_found - tp} false)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--snr", type=float, nargs="+", default=[20.0, 10.0, 5.0],
                        help="noise levels, dB of speech above the room noise")
    parser.add_argument("--sessions", type=int, default=3, help="sessions (seeds) per SNR")
    parser.add_argument("--first-seed", type=int, default=1,
                        help="seeds first..first+sessions-1 (keep tuning seeds apart)")
    parser.add_argument("--duration", type=float, default=200.0)
    parser.add_argument("--word", default="capture")
    parser.add_argument("--no-long", action="store_true", help="skip the 2-hour file")
    parser.add_argument("--workers", type=int, default=None,
                        help="speechcal's decoding processes (default: one per core, up to "
                             "its limit; 1: this process only)")
    args = parser.parse_args()
    ours = PocketsphinxBackend(workers=args.workers)
    print(f"seeds {args.first_seed}..{args.first_seed + args.sessions - 1}, "
          f"{args.duration:g} s each; load average {os.getloadavg()[0]:.2f} on "
          f"{os.cpu_count()} cores; speechcal decodes in {ours.workers} process(es), "
          f"naive-kws in one (other work stretches wall time; CPU time includes the "
          f"decoding processes')")
    spec = TriggerSpec((args.word,))
    detectors = [ours, NaiveKeyphrase()]
    with tempfile.TemporaryDirectory(prefix="bench_triggers_") as tmp:
        for snr in args.snr:
            totals = {d.name: [0, 0, 0, [], 0.0, 0.0] for d in detectors}
            audio_s = 0.0
            for seed in range(args.first_seed, args.first_seed + args.sessions):
                path, truth = render(Path(tmp), snr, seed, args.duration, args.word)
                for d in detectors:
                    audio = measure(d, path, spec, truth, totals[d.name])
                audio_s += audio.duration_s
            for d in detectors:
                print(row(label(d), snr, *totals[d.name], audio_s), flush=True)
            ours_s, naive_s = totals[ours.name][4:], totals[detectors[1].name][4:]
            print(f"{snr:>5g} dB  time as a ratio to naive-kws: wall "
                  f"{ours_s[0] / naive_s[0]:.2f}, CPU {ours_s[1] / naive_s[1]:.2f}", flush=True)
        if not args.no_long:
            long_file(Path(tmp), spec, ours)


def long_file(tmp: Path, spec: TriggerSpec, detector: PocketsphinxBackend) -> None:
    """Two hours of quiet room noise with no speech: time and result."""
    import soundfile as sf

    path = tmp / "two_hours.wav"
    rng = np.random.default_rng(0)
    with sf.SoundFile(str(path), "w", RATE, 1, subtype="PCM_16") as f:
        for _ in range(120):
            f.write((0.003 * rng.standard_normal(RATE * 60)).astype(np.float32))
    t0, c0 = time.perf_counter(), time.process_time()
    audio = load_audio(path, rate=RATE)
    found = match_triggers(detector.words(audio, spec), spec)
    dt, dc = time.perf_counter() - t0, time.process_time() - c0 + worker_cpu_s(detector)
    print(f"2 h noise file: {len(found)} trigger(s), {dt:.1f} s wall, {dc:.1f} s CPU, "
          f"RTF {dt / audio.duration_s:.4f} (CPU {dc / audio.duration_s:.4f})")


if __name__ == "__main__":
    main()
