"""``speechcal review``: the review window."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("review", help="open the review window")
    p.add_argument("inputs", nargs="*", metavar="SESSION.json | RECORDING")
    p.add_argument("--audio", metavar="AUDIO")
    p.add_argument("--screenshot", metavar="PNG", help="render the window to PNG and exit")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("review is not yet available")
