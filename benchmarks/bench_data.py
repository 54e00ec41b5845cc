"""Where a benchmark's synthetic session lives: the folder given with ``--data`` (made
there when it holds none yet, and kept), or one in a temporary folder that is removed
afterwards unless ``--keep``."""

from __future__ import annotations

import contextlib
import json
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path


@contextlib.contextmanager
def session_folder(data: str | None, keep: bool,
                   make: Callable[[Path], dict]) -> Iterator[tuple[Path, dict]]:
    """(folder, truth) of the session to measure; ``make(folder)`` writes one and
    returns its truth."""
    tmp = None if data else Path(tempfile.mkdtemp(prefix="speechcal-bench-"))
    folder = Path(data) if data else tmp / "session"
    try:
        truth_file = folder / "truth.json"
        truth = json.loads(truth_file.read_text()) if truth_file.exists() else make(folder)
        yield folder, truth
    finally:
        if tmp is not None and not keep:
            shutil.rmtree(tmp, ignore_errors=True)
        elif tmp is not None:
            print(f"data kept in {folder}", file=sys.stderr)
