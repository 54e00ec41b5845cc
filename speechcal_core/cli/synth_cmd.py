"""``speechcal synth``: write a synthetic session (recording, audio.ogg, truth.json)."""

from __future__ import annotations

import argparse
import time

from speechcal_core.cli._output import emit_json, progress
from speechcal_core.cli._paths import path_arg
from speechcal_core.text import counted


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("synth", help="write a synthetic session for tests and demos")
    p.add_argument("out", metavar="OUT", type=path_arg("the output folder"),
                   help="output folder")
    p.add_argument("--cameras", type=int, default=3, help="number of cameras (1-12; default 3)")
    p.add_argument("--fisheye", type=int, default=0, help="how many of them are fisheye")
    p.add_argument("--duration", type=float, default=60.0,
                   help="session length in seconds (5-3600; default 60)")
    p.add_argument("--triggers", type=int, default=None,
                   help="number of trigger words (default: as many as the duration holds)")
    p.add_argument("--trigger-word", default="capture",
                   help="bundled trigger word (default capture)")
    p.add_argument("--snr", type=float, default=20.0,
                   help="speech-to-noise ratio in dB (-10 to 60; default 20)")
    p.add_argument("--claps", type=int, choices=(1, 2), default=1,
                   help="claps seen by the cameras and heard (2: one more near the end)")
    p.add_argument("--drift-ppm", type=float, default=5.0,
                   help="microphone clock rate error in ppm (within +-200)")
    p.add_argument("--format", default="ros1", help="ros1 (default) | ros2-sqlite3 | ros2-mcap")
    p.add_argument("--encoding", default="jpeg",
                   help="mono8 | bgr8 | rgb8 | mono16 | bayer_rggb8 | jpeg (default) | png")
    p.add_argument("--compression", default="none", choices=("none", "bz2", "lz4"),
                   help="ROS1 chunk compression")
    p.add_argument("--target", default="aprilgrid", choices=("aprilgrid", "checkerboard"),
                   help="the board in the frames (its target.yaml is written beside them)")
    p.add_argument("--size", default="640x480",
                   help="image size WxH (at least 64x64; default 640x480)")
    p.add_argument("--rolling-shutter", action="store_true",
                   help="skew moving boards row by row, as rolling-shutter cameras do")
    p.add_argument("--seed", type=int, default=0,
                   help="random seed (default 0): the same seed and options give the same session")
    p.add_argument("--force", action="store_true",
                   help="replace an earlier synthetic session at OUT (never other files)")
    p.add_argument("--json", action="store_true", help="print truth.json on stdout")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from speechcal_core.errors import UsageError
    from speechcal_core.synth.options import SynthOptions

    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        raise UsageError(f"--size must look like 640x480, got {args.size!r}") from None
    options = SynthOptions(
        cameras=args.cameras, fisheye=args.fisheye, duration=args.duration,
        triggers=args.triggers, trigger_word=args.trigger_word, snr_db=args.snr,
        claps=args.claps, drift_ppm=args.drift_ppm, format=args.format,
        encoding=args.encoding, seed=args.seed, width=width, height=height,
        target_kind=args.target, ros1_compression=args.compression,
        rolling_shutter=args.rolling_shutter,
    )
    # the renderer (numpy, OpenCV, the recording writers) only once the options are good:
    # a usage error is told at once
    from speechcal_core.synth.session import generate_session

    started = time.monotonic()
    last = {"stage": "", "shown": -1}

    def report(stage: str, fraction: float) -> None:
        pct = int(fraction * 10) * 10
        if stage != last["stage"] or pct != last["shown"]:
            last.update(stage=stage, shown=pct)
            progress(f"{stage}: {pct}%")

    truth = generate_session(args.out, options, force=args.force, progress=report)
    progress(
        f"wrote {args.out}: {truth['recording']}, {counted(len(truth['cameras']), 'camera')}, "
        f"{counted(len(truth['triggers']), 'trigger')} (made in {time.monotonic() - started:.1f} s)"
    )
    if not truth["triggers"] and args.triggers != 0:  # none asked for: nothing to say
        progress(f"note: --duration {args.duration:g} s leaves no time for a trigger after "
                 "the clap and the first move; give a longer --duration")
    if args.json:
        emit_json(truth)
    return 0
