"""The window's re-scoring: the best-still search for sets an offset edit or an add left
with nearest frames, on a worker thread, applied on the UI thread.

What needs it and how results are taken is :class:`~speechcal_core.review.model.ReviewModel`'s
business; this only schedules, reports (job ``"rescore"`` of the status line) and cancels,
and tells the window's export, which waits for it, when it stops.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.background_action import BackgroundAction

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.rescore import RescoreRequest, RescoreResult
    from speechcal_core.sources.base import FrameSource

#: wait this long after the last edit before starting (held-down offset keys repeat)
DELAY_MS = 250
CANCELLED = "re-scoring cancelled: the sets keep their nearest frames until the next offset edit"


class RescoreAction(BackgroundAction):
    """Runs one re-scoring at a time for a :class:`ReviewWindow`; a newer offset cancels it."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window, DELAY_MS)
        self.request: RescoreRequest | None = None
        self.source: FrameSource | None = None  # the recording the running task reads
        #: the operator cancelled (or it failed): nothing starts until the next edit
        self.held = False

    def schedule(self, *_args: object) -> None:
        """An edit happened: (re)start the countdown to re-scoring what needs it."""
        self.held = False
        super().schedule()

    def start_now(self) -> None:
        """Re-score what needs it without waiting for more edits, even after a cancel
        (an export waits for it)."""
        self.held = False
        self.timer.stop()
        self.start_if_needed()

    def start_if_needed(self) -> None:
        """Start re-scoring now if the model has sets that need it; a running task for an
        older offset is cancelled (the next one starts when it has stopped)."""
        model, inputs = self.window.model, self.window.inputs
        if model is None or inputs is None or self.held:
            return
        if self.task is not None:
            if self._model is not model or \
                    (self.request is not None and self.request.sync != model.session.sync):
                self.task.cancel()
            return
        request = model.rescore_request()
        if request is None:
            return
        source = inputs.source
        self.request, self.source = request, source
        self.last_error = ""
        self.launch(model, lambda report: request.run(source, report),
                    lambda text, f: self.window.status.report("rescore", text, f))
        self.window.refresh_rescore_marks()
        self.window.status.begin("rescore", request.text)

    def reset(self) -> None:
        """Another session opens: whatever runs belongs to the previous one."""
        self.timer.stop()
        self.held = False
        if self.task is not None:
            self.task.cancel()

    def cancel(self) -> None:
        """The operator's cancel: stop, and keep the nearest frames until the next edit
        (also when it was only about to start)."""
        pending = self.timer.isActive()
        self.timer.stop()
        if self.task is not None:
            self.held = True
            self.task.cancel()
        elif pending:
            self.held = True
            self.window.status.end("rescore", CANCELLED)
            self.window.refresh_rescore_marks()
            self.window._refresh_playhead()  # tile captions: no longer re-scoring

    def _stopping(self) -> None:
        self.held = True

    # -- results ------------------------------------------------------------------------
    def _ended(self, message: str = "", *, warning: bool = False) -> None:
        """Forget the task; ``message`` says on the status line how it went."""
        self.take_model()
        self.request, self.source = None, None
        self.window.status.end("rescore", message, warning=warning)
        self.window.release_retired()

    def _finished(self, result: RescoreResult) -> None:
        model = self.take_model()
        taken = model.apply_rescored(result) if model is not None else []
        n = len(taken)
        changed = model.accepted_with_new_frames if model is not None and taken else []
        message = f"re-scored {n} frame set{'' if n == 1 else 's'}: best still frames chosen"
        self._ended(message + new_frames_note(changed) if taken else "",
                    warning=bool(changed))
        self.window.refresh_rescore_marks()
        self.start_if_needed()  # anything that needs it since (an added set, a new offset)
        self.window.exporter.rescoring_stopped()

    def _failed(self, message: str) -> None:
        if message != "cancelled":
            self.last_error = message
            self.held = True  # not again until the next edit
            self._ended(f"re-scoring failed: {message}; the sets keep their nearest frames")
        elif self.held:
            self._ended(CANCELLED)
        else:
            self._ended()
        self.window.refresh_rescore_marks()
        self.window._refresh_playhead()  # tile captions: re-scoring or not
        if not self.held:
            self.start_if_needed()  # cancelled for a newer offset
        self.window.exporter.rescoring_stopped()


def new_frames_note(set_ids: list[int], most: int = 5) -> str:
    """"; accepted set #3 now shows other frames: look again" for the accepted sets
    re-scoring gave other frames than they showed when decided ("" for none)."""
    if not set_ids:
        return ""
    named = ", ".join(f"#{i}" for i in set_ids[:most]) + (" …" if len(set_ids) > most else "")
    if len(set_ids) == 1:
        return f"; accepted set {named} now shows other frames: look again"
    return f"; accepted sets {named} now show other frames: look again"
