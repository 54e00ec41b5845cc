"""``speechcal demo``: make a synthetic session and open it in the review window."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("demo", help="open a synthetic demo session")
    p.add_argument("--workdir", metavar="DIR", help="where to write the demo session")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("demo is not yet available")
