"""Worker processes for CPU-bound work: how many cores there are, and whether spawned
workers can start at all.

Workers are spawned, never forked: a forked child inherits the parent's threads' locks
(OpenCV's thread pool, a Qt worker thread) mid-use and can deadlock in its first call.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
from multiprocessing.connection import wait


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the system has one)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def spawn_can_start() -> bool:
    """Whether spawned workers can re-import ``__main__`` (not so for ``python -`` input)."""
    main_file = getattr(sys.modules.get("__main__"), "__file__", None)
    return main_file is None or os.path.exists(main_file)


def exit_with_parent() -> None:
    """Make this worker process exit when the process that started it ends, however it
    ends: a pool's idle workers wait on a queue whose writing end they hold themselves,
    so a parent that was killed would leave them waiting, and holding their memory, for
    good. A worker initializer."""
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch() -> None:
        wait([parent.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()
