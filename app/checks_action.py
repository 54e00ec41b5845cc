"""The window's coverage and calibration check: recomputed on a worker thread whenever
re-scoring, a decision, an added or a removed set changed what they are computed over.

When they are due and how results are taken is
:class:`~speechcal_core.review.model.ReviewModel`'s business; this schedules, and cancels
a computation whose frames or decisions changed meanwhile (its result would be refused).
It is quiet: a fraction of a second for a few cameras (seconds for a dozen with wide
lenses), shown by the check line under the frame-set list ("updating…"), not on the
status line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.background_action import BackgroundAction

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.checks import ChecksRequest, ChecksResult

#: wait this long after the last change (decisions come in quick succession)
DELAY_MS = 300


class ChecksAction(BackgroundAction):
    """Runs one recomputation at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window, DELAY_MS)
        self.request: ChecksRequest | None = None  # what the running computation is for

    def schedule(self, *_args: object) -> None:
        """Something changed: a running computation over other frames or decisions than
        the session has now is cancelled (it stops before its next camera); the next
        starts after a quiet spell."""
        model = self.window.model
        if (self.task is not None and self.request is not None and model is not None
                and not model.checks_wanted(self.request)):
            self.task.cancel()
        super().schedule()

    def start_if_needed(self) -> None:
        model = self.window.model
        if model is None or self.task is not None:
            return  # a running one is followed by another if still due
        request = model.checks_request()
        if request is None:
            return
        self.request = request
        self.launch(model, lambda report: request.run(report))

    def reset(self) -> None:
        """Another session opens: a running computation's result will be ignored."""
        self.timer.stop()
        self.last_error = ""

    def _finished(self, result: ChecksResult) -> None:
        model = self.take_model()
        self.request = None
        if model is not None:
            model.apply_checks(result)  # refused if frames or decisions changed meanwhile
        self.start_if_needed()

    def _failed(self, message: str) -> None:
        self.take_model()
        self.request = None
        if message == "cancelled":
            self.schedule()  # for newer frames or decisions: after a quiet spell
        else:
            self.last_error = message
            self.window.status.say(f"calibration check failed: {message}")
