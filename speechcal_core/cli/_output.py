"""Shared helpers for subcommands: JSON on stdout, progress on stderr."""

from __future__ import annotations

import json
import sys
from typing import Any


def emit_json(document: Any) -> None:
    """Print exactly one JSON document on stdout."""
    json.dump(document, sys.stdout, indent=2, ensure_ascii=False)
    sys.stdout.write("\n")
    sys.stdout.flush()


def progress(message: str) -> None:
    """One progress line on stderr (never stdout, which may carry JSON)."""
    print(message, file=sys.stderr, flush=True)
