"""``speechcal sync``: clap times in both clocks, offset and drift."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("sync", help="find the clap and the audio-to-camera offset")
    p.add_argument("recording", metavar="RECORDING", nargs="+")
    p.add_argument("--audio", required=True, metavar="AUDIO")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("sync is not yet available")
