"""What the window's background actions share: one task at a time, started after a quiet
spell (edits come in quick succession), for the model the window had when it started.

Each kind of action has a thread of its own (:func:`app.tasks.lane`): the operator's
"find more like this" starts at once even while a re-scoring and a calibration check
run, instead of queueing behind them on Qt's shared pool (one thread per core).

Subclasses say what to run (:meth:`BackgroundAction.start_if_needed`, which calls
:meth:`BackgroundAction.launch`) and take the result (``_finished``, ``_failed``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QObject, QTimer

from app.tasks import BackgroundTask, lane, start

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.model import ReviewModel


class BackgroundAction(QObject):
    """Runs one background task at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow, delay_ms: int) -> None:
        super().__init__(window)
        self.window = window
        self.task: BackgroundTask | None = None
        self._model: ReviewModel | None = None  # the model the running task works for
        self.last_error = ""
        self.timer = QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(delay_ms)
        self.timer.timeout.connect(self.start_if_needed)

    def busy(self) -> bool:
        """True while the task runs or is about to start."""
        return self.task is not None or self.timer.isActive()

    def schedule(self, *_args: object) -> None:
        """Something changed: (re)start the countdown to :meth:`start_if_needed`."""
        if self.window.model is not None:
            self.timer.start()

    def start_if_needed(self) -> None:
        """Start the task now if there is work (and none runs)."""
        raise NotImplementedError

    def launch(self, model: ReviewModel, work: Callable[[Callable[[str, float], None]], Any],
               progress: Callable[[str, float], None] | None = None) -> BackgroundTask:
        """Run ``work(report)`` on a worker thread for ``model``; its result goes to
        ``_finished``, a failure or cancel to ``_failed``."""
        self._model = model
        self.task = BackgroundTask(work, owner=self)
        if progress is not None:
            self.task.signals.progress.connect(progress)
        self.task.signals.finished.connect(self._finished)
        self.task.signals.failed.connect(self._failed)
        start(self.task, lane(type(self).__name__))
        return self.task

    def take_model(self) -> ReviewModel | None:
        """Forget the task; returns the model it worked for if the window still shows it."""
        model = self._model if self._model is self.window.model else None
        self.task, self._model = None, None
        return model

    def shutdown(self, wait_s: float = 5.0) -> None:
        """Stop for good (the window closes): cancel, and wait for the worker to let go;
        nothing it still reports or returns is taken (the window no longer shows it)."""
        self.timer.stop()
        self._stopping()
        task = self.task
        if task is not None:
            task.abandon()
            task.done.wait(wait_s)

    def _stopping(self) -> None:
        """Called by :meth:`shutdown` before the task is cancelled."""

    def _finished(self, result: Any) -> None:
        raise NotImplementedError

    def _failed(self, message: str) -> None:
        raise NotImplementedError
