"""Shared helpers for subcommands: JSON on stdout, progress on stderr."""

from __future__ import annotations

import contextlib
import json
import os
import sys
from typing import Any, TextIO


def emit_json(document: Any) -> None:
    """Print exactly one JSON document on stdout (UTF-8: a file name that is not, held
    as lone surrogates, is written as their escapes, which read back as the same name)."""
    text = json.dumps(document, indent=2, ensure_ascii=False)
    sys.stdout.write(text.encode("utf-8", "backslashreplace").decode("utf-8") + "\n")
    sys.stdout.flush()


def progress(message: str) -> None:
    """One progress line on stderr (never stdout, which may carry JSON).

    A reader that went away (``speechcal export ... 2>&1 | head -1``) does not stop the
    command: its files are written whole all the same. stderr goes to the null device
    from then on (what is said there is for a reader, and there is none)."""
    try:
        print(message, file=sys.stderr, flush=True)
    except BrokenPipeError:
        to_null(sys.stderr)


def to_null(stream: TextIO) -> None:
    """Send ``stream`` (stdout or stderr) to the null device after its pipe broke, so that
    later writes, and Python's own flush of it at exit, do not fail again (Python's advice
    on SIGPIPE). A stream without a file descriptor (a test's capture) is left as it is."""
    with contextlib.suppress(OSError, ValueError):
        null = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(null, stream.fileno())
        finally:
            os.close(null)


class StageProgress:
    """A ``(text, fraction)`` progress callback that writes ``[ NN%] text`` lines on
    stderr: one when the text changes and then one per ``step`` percent, never the same
    line twice. Texts starting with one of ``item_prefixes`` ("writing ", one per file)
    count as one stage, so a line per item is not printed."""

    def __init__(self, step: int = 10, item_prefixes: tuple[str, ...] = ()) -> None:
        self.step, self.item_prefixes = step, item_prefixes
        self._stage: str | None = None
        self._shown = -1

    def __call__(self, text: str, fraction: float) -> None:
        pct = int(fraction * 100)
        stage = next((p for p in self.item_prefixes if text.startswith(p)), text)
        if stage != self._stage or pct // self.step > self._shown // self.step:
            self._stage, self._shown = stage, pct
            progress(f"[{pct:3d}%] {text}")
