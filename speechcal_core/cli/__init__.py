"""The ``speechcal`` console script: one subcommand per module (DESIGN.md §2).

Exit codes: 0 success, 1 bad input (one-line reason on stderr), 2 bad usage.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from speechcal_core import __version__
from speechcal_core.errors import SpeechCalError, UsageError

#: subcommand name -> module under speechcal_core.cli providing register() and run()
COMMANDS: dict[str, str] = {
    "synth": "synth_cmd",
    "index": "index_cmd",
    "sync": "sync_cmd",
    "detect": "detect_cmd",
    "process": "process_cmd",
    "export": "export_cmd",
    "review": "review_cmd",
    "demo": "demo_cmd",
}


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser with every subcommand registered."""
    parser = argparse.ArgumentParser(
        prog="speechcal",
        description="Spoken-trigger frame selection for multi-camera calibration.",
    )
    parser.add_argument("--version", action="version", version=f"speechcal {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, module_name in COMMANDS.items():
        module = importlib.import_module(f"speechcal_core.cli.{module_name}")
        sub = module.register(subparsers)
        sub.set_defaults(_run=module.run, _name=name, _parser=sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point; returns the process exit code."""
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # the subcommand's usage says which options it does take
        args._parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    try:
        return int(args._run(args) or 0)
    except UsageError as exc:
        print(f"speechcal {args._name}: error: {exc}", file=sys.stderr)
        return 2
    except SpeechCalError as exc:
        print(f"speechcal {args._name}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"speechcal {args._name}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
