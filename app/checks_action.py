"""The window's coverage and calibration check: recomputed on a worker thread whenever
re-scoring, a decision, an added or a removed set changed what they are computed over.

When they are due and how results are taken is
:class:`~speechcal_core.review.model.ReviewModel`'s business; this only schedules. It is
quiet: a few tens of milliseconds of work, shown by the check line under the frame-set
list ("updating…"), not on the status line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QTimer

from app.tasks import BackgroundTask, start

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.checks import ChecksResult
    from speechcal_core.review.model import ReviewModel

#: wait this long after the last change (decisions come in quick succession)
DELAY_MS = 300


class ChecksAction(QObject):
    """Runs one recomputation at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window)
        self.window = window
        self.task: BackgroundTask | None = None
        self._model: ReviewModel | None = None
        self.last_error = ""
        self.timer = QTimer(self)
        self.timer.setSingleShot(True)
        self.timer.setInterval(DELAY_MS)
        self.timer.timeout.connect(self.start_if_needed)

    def busy(self) -> bool:
        """True while the checks are computed or about to be."""
        return self.task is not None or self.timer.isActive()

    def schedule(self, *_args: object) -> None:
        """Something they depend on may have changed: (re)start the countdown."""
        if self.window.model is not None:
            self.timer.start()

    def start_if_needed(self) -> None:
        model = self.window.model
        if model is None or self.task is not None:
            return  # a running one is followed by another if still due
        request = model.checks_request()
        if request is None:
            return
        self._model = model
        self.task = BackgroundTask(lambda report: request.run(report))
        self.task.signals.finished.connect(self._finished)
        self.task.signals.failed.connect(self._failed)
        start(self.task)

    def reset(self) -> None:
        """Another session opens: a running computation's result will be ignored."""
        self.timer.stop()
        self.last_error = ""

    def shutdown(self, wait_s: float = 5.0) -> None:
        """Stop for good (the window closes)."""
        self.timer.stop()
        task = self.task
        if task is not None:
            task.cancel()
            task.done.wait(wait_s)

    def _finished(self, result: ChecksResult) -> None:
        model, self._model, self.task = self._model, None, None
        if model is self.window.model and model is not None:
            model.apply_checks(result)  # refused if frames or decisions changed meanwhile
        self.start_if_needed()

    def _failed(self, message: str) -> None:
        self._model, self.task = None, None
        if message != "cancelled":
            self.last_error = message
            self.window.status.say(f"calibration check failed: {message}")
