"""``speechcal index``: image streams of a recording with counts and stamp ranges."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("index", help="list image streams with header-stamp ranges")
    p.add_argument("recording", metavar="RECORDING", nargs="+")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--no-cache", action="store_true", help="build the index afresh")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("index is not yet available")
