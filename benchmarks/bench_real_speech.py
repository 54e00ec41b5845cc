"""Trigger detection on real recorded speech: ours versus naive keyphrase spotting.

The recordings of ``../shared/speech-real`` (real people, CMU PocketSphinx's test data:
"ten of clubs", "four queen of clubs", "seven of clubs", "five five", "eight of spades
four of clubs seven of hearts", "go forward ten meters") are laid one after another in a
random order, each at a random gain (+-3 dB), with pauses of 1-2.5 s, in the synthetic
sessions' room noise at 20, 10 and 5 dB SNR (speech level inside the recordings). The
trigger word is "clubs": four instances a scene, one of them followed at once by more
speech ("... clubs seven of hearts"). Each is timed against its bounds marked by hand
on the spectrogram, from the burst of its /k/ to the end of its /z/ (the same marks as
``tests/speech/test_pocketsphinx.py``).

    python benchmarks/bench_real_speech.py              # 10 scenes per SNR
    python benchmarks/bench_real_speech.py --scenes 3 --snr 20 --sensitivity 0.8

Each recording appears once a scene, so the similarity search never meets a copy of the
same waveform. Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import soundfile as sf

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
for p in (REPO, HERE):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))

from bench_triggers import NaiveKeyphrase, label, measure, row  # noqa: E402

from speechcal_core.audio import load_audio  # noqa: E402
from speechcal_core.speech import TriggerSpec  # noqa: E402
from speechcal_core.speech.matching import DEFAULT_SENSITIVITY  # noqa: E402
from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend  # noqa: E402
from speechcal_core.synth.audio import _RoomNoise  # noqa: E402  (the synth's room tone)

RATE = 16000
REAL_SPEECH = REPO.parent / "shared" / "speech-real"
#: "clubs" in each recording, marked by hand on its spectrogram (seconds in the file)
CLUBS_MARKED: dict[str, list[tuple[float, float]]] = {
    "cards_001.wav": [(0.49, 0.93)], "cards_002.wav": [(1.23, 1.71)],
    "cards_003.wav": [(0.76, 1.21)], "cards_004.wav": [],
    "cards_005.wav": [(1.69, 2.13)], "goforward.wav": [],
}
GAIN_DB = 3.0
PAUSE_S = (1.0, 2.5)


def scene(out: Path, snr_db: float, seed: int) -> tuple[Path, list[dict]]:
    """One scene of all recordings in noise, and the marked triggers in scene seconds."""
    rng = np.random.default_rng(seed)
    parts, truth, spoken = [np.zeros(int(PAUSE_S[1] * RATE), np.float32)], [], []
    t = PAUSE_S[1]
    for name in rng.permutation(sorted(CLUBS_MARKED)):
        x = load_audio(REAL_SPEECH / name, rate=RATE).samples
        x = x / (np.sqrt(np.mean(x**2)) + 1e-9) * 0.1 * 10 ** (rng.uniform(-1, 1) * GAIN_DB / 20)
        truth += [{"start_s": t + a, "end_s": t + b} for a, b in CLUBS_MARKED[name]]
        spoken.append(x)
        pause = np.zeros(int(rng.uniform(*PAUSE_S) * RATE), np.float32)
        parts += [x.astype(np.float32), pause]
        t += (x.size + pause.size) / RATE
    speech = np.concatenate(parts)
    speech_rms = float(np.sqrt(np.mean(np.concatenate(spoken) ** 2)))
    noise = _RoomNoise(np.random.default_rng(1000 + seed)).take(speech.size)
    mix = speech + noise * speech_rms / 10 ** (snr_db / 20)
    mix *= 0.5 / np.max(np.abs(mix))
    path = out / f"real_{snr_db:g}_{seed}.wav"
    sf.write(str(path), mix.astype(np.float32), RATE)
    return path, truth


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--snr", type=float, nargs="+", default=[20.0, 10.0, 5.0],
                        help="noise levels, dB of speech above the room noise")
    parser.add_argument("--scenes", type=int, default=10, help="scenes (seeds) per SNR")
    parser.add_argument("--sensitivity", type=float, default=DEFAULT_SENSITIVITY,
                        help="of our detector (0..1)")
    args = parser.parse_args()
    missing = [n for n in CLUBS_MARKED if not (REAL_SPEECH / n).is_file()]
    if missing:
        sys.exit(f"{REAL_SPEECH}: {', '.join(missing)} not found; the real recordings "
                 f"sit beside the checkout (../shared/speech-real)")
    print(f"{args.scenes} scenes per SNR, trigger 'clubs' at sensitivity "
          f"{args.sensitivity:g}; load average "
          f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    spec = TriggerSpec(("clubs",), sensitivity=args.sensitivity)
    detectors = [PocketsphinxBackend(), NaiveKeyphrase()]
    with tempfile.TemporaryDirectory(prefix="bench_real_speech_") as tmp:
        for snr in args.snr:
            totals = {d.name: [0, 0, 0, [], 0.0, 0.0] for d in detectors}
            audio_s = 0.0
            for seed in range(1, args.scenes + 1):
                path, truth = scene(Path(tmp), snr, seed)
                audio = load_audio(path, rate=RATE)
                audio_s += audio.duration_s
                for d in detectors:
                    measure(d, audio, spec, truth, totals[d.name])
            for d in detectors:
                print(row(label(d), snr, *totals[d.name], audio_s), flush=True)


if __name__ == "__main__":
    main()
