"""Regenerate the bundled voice clips and index.json with flite (and espeak-ng) voices.

Run from anywhere: ``python resources/voices/make_voices.py``. Needs Debian's ``flite``
(voices slt, rms, awb, kal16: built from human recordings) and optionally ``espeak-ng``,
plus numpy, scipy and soundfile. Every take is deterministic (a fixed table of pitch and
rate settings), so re-running reproduces the same files. Each clip is trimmed to the spoken
part (a few ms margin), so a clip's bounds are the word's start and end, and stored as
16 kHz mono 16-bit FLAC.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import soundfile as sf
from scipy.signal import resample_poly

HERE = Path(__file__).resolve().parent
SAMPLE_RATE = 16_000
FRAME_S = 0.002  # trimming resolution
TRIM_DB = 35.0  # this far below the loudest 2 ms frame counts as silence
SPAN_SLACK_S = (0.005, 0.025)  # flite segment times may end a vowel's decay early
MARGIN_S = 0.004  # kept either side of the spoken part
FADE_S = 0.002

TRIGGERS = ["capture", "snapshot", "record", "mark"]

#: distractor text -> the trigger word it resembles (None: ordinary chatter)
DISTRACTORS: dict[str, str | None] = {
    "picture": "capture",
    "rapture": "capture",
    "captain": "capture",
    "captured it?": "capture",
    "capsule": "capture",
    "snap shut": "snapshot",
    "recorder": "record",
    "market": "mark",
    "park it": "mark",
    "okay": None,
    "move it left": None,
    "a bit closer": None,
    "hold on": None,
    "ready": None,
    "tilt it up": None,
    "nice": None,
    "one more": None,
    "turn it right": None,
    "a bit further": None,
    "good": None,
    "wait": None,
    "almost there": None,
    "higher": None,
    "that's blurry": None,
}

#: flite voice -> natural mean F0 (Hz); takes scale it
FLITE_VOICES = {"slt": 180.0, "rms": 105.0, "awb": 140.0, "kal16": 105.0}
#: espeak-ng voice -> base pitch (0-99); formant voices, a minority for variety
ESPEAK_VOICES = {"en-us+f3": 55, "en-gb-x-rp": 45}

#: (F0 factor, duration stretch) per take; trigger words get all, distractors the first 2
TAKES = [(1.0, 1.0), (1.12, 0.88), (0.9, 1.18), (1.05, 1.3), (0.95, 0.8)]
ESPEAK_TAKES = [(1.0, 1.0), (1.15, 0.88), (0.88, 1.15)]


def slug(text: str) -> str:
    """File-name form of a text: ``"captured it?"`` -> ``captured_it``."""
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")


def flite(voice: str, text: str, f0: float, stretch: float, out: Path) -> tuple[float, float]:
    """Synthesize one take with flite; return the spoken span (s) from its segment timing."""
    run = subprocess.run(
        ["flite", "-voice", voice, "-psdur", "--setf", f"duration_stretch={stretch:.3f}",
         "--setf", f"int_f0_target_mean={f0:.1f}", "-t", text, "-o", str(out)],
        check=True, capture_output=True, text=True,
    )
    segs = [(name, float(end)) for name, end in re.findall(r"(\S+):([0-9.]+)", run.stdout)]
    start = segs[0][1] if segs[0][0] == "pau" else 0.0
    speech = [end for name, end in segs if name != "pau"]
    return start, speech[-1]


def espeak(voice: str, text: str, pitch: int, stretch: float, out: Path) -> None:
    """Synthesize one take with espeak-ng (its pauses are digital silence)."""
    speed = round(165 / stretch)
    subprocess.run(
        ["espeak-ng", "-v", voice, "-p", str(pitch), "-s", str(speed), "-w", str(out), text],
        check=True, capture_output=True,
    )


def load_16k(path: Path) -> np.ndarray:
    """Read a wav as float64 mono at 16 kHz."""
    x, sr = sf.read(str(path), dtype="float64", always_2d=True)
    x = x[:, 0]
    if sr != SAMPLE_RATE:
        g = np.gcd(sr, SAMPLE_RATE)
        x = resample_poly(x, SAMPLE_RATE // g, sr // g)
    return x


def trim(x: np.ndarray, span: tuple[float, float] | None = None) -> np.ndarray:
    """Cut leading and trailing silence, keep MARGIN_S, fade the ends, peak-normalize.

    ``span`` (seconds) limits the search to the synthesizer's own word segments, so the
    breathy noise some voices render in pauses is never taken for speech.
    """
    fr = int(FRAME_S * SAMPLE_RATE)
    n = len(x) // fr
    rms = np.sqrt(np.mean(x[: n * fr].reshape(n, fr) ** 2, axis=1))
    if span is not None:
        first = max(0, int((span[0] - SPAN_SLACK_S[0]) * SAMPLE_RATE) // fr)
        last = min(n, -(-int((span[1] + SPAN_SLACK_S[1]) * SAMPLE_RATE) // fr))
        rms[:first] = 0.0
        rms[last:] = 0.0
    thresh = max(rms.max() * 10 ** (-TRIM_DB / 20), 1e-4)
    active = np.flatnonzero(rms > thresh)
    margin = int(MARGIN_S * SAMPLE_RATE)
    a = max(0, active[0] * fr - margin)
    b = min(len(x), (active[-1] + 1) * fr + margin)
    y = x[a:b].copy()
    fade = int(FADE_S * SAMPLE_RATE)
    ramp = np.linspace(0.0, 1.0, fade, endpoint=False)
    y[:fade] *= ramp
    y[-fade:] *= ramp[::-1]
    return y * (0.9 / np.abs(y).max())


def main() -> int:
    """Write every clip and index.json; remove clips of an earlier run first."""
    if shutil.which("flite") is None:
        print("flite not found: apt-get install flite", file=sys.stderr)
        return 1
    have_espeak = shutil.which("espeak-ng") is not None
    for old in HERE.iterdir():
        if old.is_dir():
            shutil.rmtree(old)
    items = [(w, "trigger", w) for w in TRIGGERS]
    items += [(t, "distractor", near) for t, near in DISTRACTORS.items()]
    clips = []
    with tempfile.TemporaryDirectory() as tmp:
        wav = Path(tmp) / "take.wav"
        jobs = []
        for voice, f0 in FLITE_VOICES.items():
            for text, kind, near in items:
                takes = TAKES if kind == "trigger" else TAKES[:2]
                for k, (f0_factor, stretch) in enumerate(takes):
                    jobs.append(("flite", voice, text, kind, near, k, f0 * f0_factor, stretch))
        if have_espeak:
            for voice, pitch in ESPEAK_VOICES.items():
                for text, kind, near in items:
                    takes = ESPEAK_TAKES if kind == "trigger" else ESPEAK_TAKES[:1]
                    for k, (f0_factor, stretch) in enumerate(takes):
                        p = int(min(99, pitch * f0_factor))
                        jobs.append(("espeak-ng", voice, text, kind, near, k, p, stretch))
        for engine, voice, text, kind, near, k, f0, stretch in jobs:
            span = None
            if engine == "flite":
                span = flite(voice, text, f0, stretch, wav)
            else:
                espeak(voice, text, int(f0), stretch, wav)
            y = trim(load_16k(wav), span)
            folder = voice if engine == "flite" else "espeak-" + voice.replace("+", "-")
            rel = f"{folder}/{slug(text)}_{k + 1}.flac"
            (HERE / folder).mkdir(exist_ok=True)
            sf.write(str(HERE / rel), y, SAMPLE_RATE, subtype="PCM_16")
            clips.append({
                "file": rel, "text": text, "kind": kind, "near": near,
                "voice": voice, "engine": engine, "take": k + 1,
                "frames": len(y), "duration_s": round(len(y) / SAMPLE_RATE, 7),
                "pitch": round(float(f0), 1), "duration_stretch": stretch,
            })
    index = {
        "schema": 1,
        "sample_rate": SAMPLE_RATE,
        "note": "clip bounds are the spoken part (4 ms margin); made by make_voices.py",
        "triggers": TRIGGERS,
        "clips": clips,
    }
    (HERE / "index.json").write_text(json.dumps(index, indent=1) + "\n", encoding="utf-8")
    total = sum(p.stat().st_size for p in HERE.rglob("*.flac"))
    print(f"{len(clips)} clips, {total / 1e6:.2f} MB", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
