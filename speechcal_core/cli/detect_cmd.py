"""``speechcal detect``: trigger words with start, end, t and score in audio seconds."""

from __future__ import annotations

import argparse

from speechcal_core.errors import NotYetAvailableError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("detect", help="find trigger words in an audio file")
    p.add_argument("audio", metavar="AUDIO")
    p.add_argument("--trigger", action="append", metavar="W", help="trigger word (repeatable)")
    p.add_argument("--backend", default="pocketsphinx")
    p.add_argument("--transcript", metavar="F", help="take words from a transcript file")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    raise NotYetAvailableError("detect is not yet available")
