"""Run a core function on a worker thread with progress, cancel, and a result signal."""

from __future__ import annotations

import threading
import time
import traceback
from collections.abc import Callable
from typing import Any

import shiboken6
from PySide6.QtCore import QObject, QRunnable, QThreadPool, Signal


class Cancelled(Exception):
    """Raised inside a task when the operator pressed cancel."""


#: tasks started and not yet ended: kept alive here until their worker lets go (the
#: window that started one may be deleted meanwhile), and waited for at exit
_running: set[BackgroundTask] = set()
_running_lock = threading.Lock()
#: tasks started whose last word (result or failure) has not yet been relayed on the UI
#: thread: kept alive here past the end of their worker, so that word is relayed (or its
#: result discarded) even once nothing else holds the task, e.g. an opening superseded
#: by another (UI thread only)
_unreleased: set[BackgroundTask] = set()
#: one-thread pools by name (see :func:`lane`): made on first use and kept for the life
#: of the process, so that closing a window never waits for a pool's thread
_lanes: dict[str, QThreadPool] = {}


class TaskSignals(QObject):
    progress = Signal(str, float)
    finished = Signal(object)
    failed = Signal(str)


class BackgroundTask(QRunnable):
    """Calls ``fn(report)`` off the UI thread; ``report(text, fraction)`` raises if cancelled.

    Receivers connect to :attr:`signals`, emitted on the UI thread. With an ``owner`` (the
    window or action the result is for), nothing is delivered once the owner is gone and
    the task is cancelled when it is destroyed: a window closed and deleted while its work
    runs gets no late progress or result (its widgets no longer exist). :meth:`abandon`
    does the same for a window that closes but still exists. A result nobody hears of is
    handed to ``discard`` instead (e.g. to close the recording it opened).
    """

    def __init__(self, fn: Callable[[Callable[[str, float], None]], Any],
                 owner: QObject | None = None,
                 discard: Callable[[Any], None] | None = None) -> None:
        super().__init__()
        self.fn = fn
        #: called (UI thread) with a result that comes when nobody may hear of it; it must
        #: not reach the owner, which may be gone by then
        self._discard = discard
        self.signals = TaskSignals()  # delivered on the UI thread, while the owner lives
        # what the worker emits: Python-owned, so it outlives any window, and relayed to
        # ``signals`` on the thread ``signals`` lives in
        self._worker = TaskSignals()
        self._worker.progress.connect(self._relay_progress)
        self._worker.finished.connect(self._relay_finished)
        self._worker.failed.connect(self._relay_failed)
        self._cancel = threading.Event()
        self._abandoned = False  # UI thread only
        self.done = threading.Event()
        #: the exception the work raised (set before ``failed`` is sent), else None
        self.error: Exception | None = None
        self._owner = owner
        if owner is not None:
            owner.destroyed.connect(self.cancel)

    def cancel(self, *_args: object) -> None:
        """Ask the work to stop at its next progress report (it fails with "cancelled")."""
        self._cancel.set()

    def abandon(self) -> None:
        """Cancel, and tell the receivers nothing more, not even a result that comes anyway
        (UI thread; the window closes)."""
        self._abandoned = True
        self.cancel()

    def _deliver(self) -> bool:
        """Whether the receivers may still hear of this task (UI thread)."""
        return not self._abandoned and (self._owner is None or shiboken6.isValid(self._owner))

    def _relay_progress(self, text: str, fraction: float) -> None:
        if self._deliver() and not self._cancel.is_set():
            self.signals.progress.emit(text, fraction)

    def _relay_finished(self, result: object) -> None:
        deliver = self._deliver()
        discard = self._discard
        self._release()
        if deliver:
            self.signals.finished.emit(result)
        elif discard is not None:
            discard(result)

    def _relay_failed(self, message: str) -> None:
        deliver = self._deliver()
        self._release()
        if deliver:
            self.signals.failed.emit(message)

    def _release(self) -> None:
        """The last word is in: drop the connections that keep this task (and what its
        function holds, e.g. a recording) referenced."""
        _unreleased.discard(self)  # freed once this relay returns (the caller holds it)
        self.fn = None  # type: ignore[assignment]
        self._discard = None
        for signal, slot in ((self._worker.progress, self._relay_progress),
                             (self._worker.finished, self._relay_finished),
                             (self._worker.failed, self._relay_failed)):
            signal.disconnect(slot)
        if self._owner is not None:
            if shiboken6.isValid(self._owner):
                self._owner.destroyed.disconnect(self.cancel)
            self._owner = None

    def _report(self, text: str, fraction: float) -> None:
        if self._cancel.is_set():
            raise Cancelled()
        self._worker.progress.emit(text, float(fraction))

    def run(self) -> None:
        try:
            if self._cancel.is_set():
                raise Cancelled()  # cancelled while it waited for a thread
            result = self.fn(self._report)
        except Cancelled:
            self._worker.failed.emit("cancelled")
        except Exception as exc:  # shown to the operator, never swallowed
            self.error = exc  # read by the owner once ``failed`` reaches it
            message = str(exc) or type(exc).__name__
            if not getattr(exc, "__module__", "").startswith("speechcal_core"):
                traceback.print_exc()
            self._worker.failed.emit(message)
        else:
            self._worker.finished.emit(result)
        finally:
            with _running_lock:
                _running.discard(self)
            self.done.set()


def start(task: BackgroundTask, pool: QThreadPool | None = None) -> BackgroundTask:
    """Queue ``task`` on ``pool`` (default: the global pool) and return it."""
    _unreleased.add(task)
    with _running_lock:
        _running.add(task)
    (pool or QThreadPool.globalInstance()).start(task)
    return task


def lane(name: str) -> QThreadPool:
    """The pool of one thread called ``name``: tasks started on it run one after another,
    never queued behind other kinds of work on the shared pool."""
    pool = _lanes.get(name)
    if pool is None:
        pool = _lanes[name] = QThreadPool()
        pool.setMaxThreadCount(1)
    return pool


def running() -> list[BackgroundTask]:
    """The tasks started and not yet ended."""
    with _running_lock:
        return list(_running)


def wait_for_all(timeout_s: float) -> bool:
    """Wait until no started task runs or waits for a thread; False on timeout.

    Before Python exits: work still running then would fail half-way ("cannot schedule
    new futures after shutdown") and report to Qt objects already deleted.
    """
    deadline = time.monotonic() + timeout_s
    while True:
        tasks = running()
        if not tasks:
            return True
        left = deadline - time.monotonic()
        if left <= 0:
            return False
        tasks[0].done.wait(left)
