"""``speechcal process``: sync, detect, frame sets and quality into a session file."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("process", help="build a session file from recording and audio")
    p.add_argument("recording", metavar="RECORDING", nargs="+")
    p.add_argument("--audio", required=True, metavar="AUDIO")
    p.add_argument("--target", metavar="TARGET.yaml", help="Kalibr target yaml")
    p.add_argument("--trigger", action="append", metavar="W")
    p.add_argument("--transcript", metavar="F")
    p.add_argument("--offset-ns", type=int, metavar="N")
    p.add_argument("-o", "--output", required=True, metavar="SESSION.json")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("process is not yet available")
