"""The window's coverage and calibration check: recomputed on a worker thread whenever
re-scoring, a decision, an added or a removed set changed what they are computed over.

When they are due and how results are taken is
:class:`~speechcal_core.review.model.ReviewModel`'s business; this only schedules. It is
quiet: a few tens of milliseconds of work, shown by the check line under the frame-set
list ("updating…"), not on the status line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.background_action import BackgroundAction

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.checks import ChecksResult

#: wait this long after the last change (decisions come in quick succession)
DELAY_MS = 300


class ChecksAction(BackgroundAction):
    """Runs one recomputation at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window, DELAY_MS)

    def start_if_needed(self) -> None:
        model = self.window.model
        if model is None or self.task is not None:
            return  # a running one is followed by another if still due
        request = model.checks_request()
        if request is None:
            return
        self.launch(model, lambda report: request.run(report))

    def reset(self) -> None:
        """Another session opens: a running computation's result will be ignored."""
        self.timer.stop()
        self.last_error = ""

    def _finished(self, result: ChecksResult) -> None:
        model = self.take_model()
        if model is not None:
            model.apply_checks(result)  # refused if frames or decisions changed meanwhile
        self.start_if_needed()

    def _failed(self, message: str) -> None:
        self.take_model()
        if message != "cancelled":
            self.last_error = message
            self.window.status.say(f"calibration check failed: {message}")
