"""``speechcal export``: write the accepted frame sets for a calibration tool."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("export", help="export accepted frame sets")
    p.add_argument("session", metavar="SESSION.json")
    p.add_argument("--format", required=True, choices=("kalibr", "folders", "rosbag1", "rosbag2"))
    p.add_argument("--out", required=True, metavar="DIR")
    p.add_argument("--force", action="store_true")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("export is not yet available")
