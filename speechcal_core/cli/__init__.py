"""The ``speechcal`` console script: one subcommand per module (DESIGN.md §2).

Exit codes: 0 success, 1 bad input (one-line reason on stderr), 2 bad usage; 130 after
Ctrl+C, 128 + the signal's number after SIGTERM or SIGHUP (a closed terminal), which stop
a command as cleanly as Ctrl+C: its partial output is removed.
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import importlib
import signal
import sys
import threading
from collections.abc import Iterator, Sequence

from speechcal_core import __version__
from speechcal_core.cli._output import progress, to_null
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

#: commands that keep the default handling of SIGTERM and SIGHUP: the window ends at
#: once (a Python handler would wait for Qt's event loop to hand back control)
WINDOW_COMMANDS = ("review", "demo")
#: errors writing the command's output (stdout) that end it with a one-line reason
UNWRITABLE_OUTPUT = (errno.ENOSPC, errno.EIO, errno.EDQUOT)
STOP_SIGNALS = ("SIGTERM", "SIGHUP")


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where the command is, so that it cleans up as on Ctrl+C."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _raise_stopped(signum: int, _frame: object) -> None:
    raise Stopped(signum)


@contextlib.contextmanager
def _stopping_on_signals() -> Iterator[None]:
    """SIGTERM and SIGHUP raise :class:`Stopped` inside the block (main thread only);
    the earlier handlers come back afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    earlier = {}
    for name in STOP_SIGNALS:
        number = getattr(signal, name, None)  # no SIGHUP on Windows
        if number is not None:
            earlier[number] = signal.signal(number, _raise_stopped)
    try:
        yield
    finally:
        for number, handler in earlier.items():
            signal.signal(number, handler)


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
    _file_names_as_given()
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # the subcommand's usage says which options it does take
        args._parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    stopping = contextlib.nullcontext() if args._name in WINDOW_COMMANDS \
        else _stopping_on_signals()
    try:
        with stopping:
            return int(args._run(args) or 0)
    except Stopped as exc:
        name = signal.Signals(exc.signum).name
        progress(f"speechcal {args._name}: stopped by {name}")
        return 128 + exc.signum
    except UsageError as exc:
        progress(f"speechcal {args._name}: error: {exc}")
        return 2
    except SpeechCalError as exc:
        progress(f"speechcal {args._name}: error: {exc}")
        return 1
    except KeyboardInterrupt:
        progress(f"speechcal {args._name}: interrupted")
        return 130
    except BrokenPipeError:
        # the reader of stdout went away (``speechcal index --json | head``): nothing to
        # say to it, and Python's own flush of stdout at exit must not fail again. Commands
        # print there once their work is done (a closed stderr never stops them:
        # ``progress``), so what they wrote is complete.
        to_null(sys.stdout)
        return 141  # as a shell reports a process ended by SIGPIPE
    except OSError as exc:
        if exc.errno not in UNWRITABLE_OUTPUT:
            raise
        # stdout on a full disk (``> /dev/full``); files the command writes say so
        # themselves, naming the file
        progress(f"speechcal {args._name}: error: could not write the output: "
                 f"{exc.strerror}")
        to_null(sys.stdout)  # Python's own flush at exit must not fail
        return 1


def _file_names_as_given() -> None:
    """Print file names that are not UTF-8 (a Latin-1 name from a FAT card) byte for
    byte, as ``ls`` does, instead of failing on them."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is not None:
            with contextlib.suppress(ValueError, OSError):
                reconfigure(errors="surrogateescape")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
