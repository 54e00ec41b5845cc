"""Run a core function on a worker thread with progress, cancel, and a result signal."""

from __future__ import annotations

import threading
import traceback
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, QRunnable, QThreadPool, Signal


class Cancelled(Exception):
    """Raised inside a task when the operator pressed cancel."""


class TaskSignals(QObject):
    progress = Signal(str, float)
    finished = Signal(object)
    failed = Signal(str)


class BackgroundTask(QRunnable):
    """Calls ``fn(report)`` off the UI thread; ``report(text, fraction)`` raises if cancelled."""

    def __init__(self, fn: Callable[[Callable[[str, float], None]], Any]) -> None:
        super().__init__()
        self.fn = fn
        self.signals = TaskSignals()
        self._cancel = threading.Event()
        self.done = threading.Event()

    def cancel(self) -> None:
        self._cancel.set()

    def _report(self, text: str, fraction: float) -> None:
        if self._cancel.is_set():
            raise Cancelled()
        self.signals.progress.emit(text, float(fraction))

    def run(self) -> None:
        try:
            result = self.fn(self._report)
        except Cancelled:
            self.signals.failed.emit("cancelled")
        except Exception as exc:  # shown to the operator, never swallowed
            message = str(exc) or type(exc).__name__
            if not getattr(exc, "__module__", "").startswith("speechcal_core"):
                traceback.print_exc()
            self.signals.failed.emit(message)
        else:
            self.signals.finished.emit(result)
        finally:
            self.done.set()


def start(task: BackgroundTask, pool: QThreadPool | None = None) -> BackgroundTask:
    """Queue ``task`` on ``pool`` (default: the global pool) and return it."""
    (pool or QThreadPool.globalInstance()).start(task)
    return task
