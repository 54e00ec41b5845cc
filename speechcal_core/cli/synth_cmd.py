"""``speechcal synth``: write a synthetic session (recording, audio.ogg, truth.json)."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("synth", help="write a synthetic session for tests and demos")
    p.add_argument("out", metavar="OUT", help="output folder")
    p.add_argument("--cameras", type=int, default=3, help="number of cameras (1-12)")
    p.add_argument("--fisheye", type=int, default=0, help="how many of them are fisheye")
    p.add_argument("--duration", type=float, default=60.0, help="session length in seconds")
    p.add_argument("--triggers", type=int, default=None, help="number of trigger words")
    p.add_argument("--trigger-word", default="capture", help="bundled trigger word")
    p.add_argument("--snr", type=float, default=20.0, help="speech-to-noise ratio in dB")
    p.add_argument("--claps", type=int, choices=(1, 2), default=1)
    p.add_argument("--drift-ppm", type=float, default=5.0, help="microphone clock rate error")
    p.add_argument("--format", default="ros1", help="ros1 | ros2-sqlite3 | ros2-mcap")
    p.add_argument("--encoding", default="jpeg", help="mono8 bgr8 rgb8 mono16 bayer_rggb8 jpeg png")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--force", action="store_true", help="replace an existing OUT")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("synth is not yet available")
