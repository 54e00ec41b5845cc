"""The window's "find trigger words" (Ctrl+F): the dialog, the detection on a worker
thread, and the sets found added on the UI thread.

What the words mean and how they become sets is the core's business
(:mod:`speechcal_core.review.detect_again` and
:meth:`~speechcal_core.review.model.ReviewModel.apply_detected`); this asks, reports on the
status line (job ``"detect"``) and cancels.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from app.background_action import BackgroundAction
from app.detect_dialog import DetectDialog
from app.similar_action import found_message
from speechcal_core.review.detect_again import (
    DetectRequest,
    DetectResult,
    detect_request,
    detection_settings,
    result_message,
)

if TYPE_CHECKING:
    from app.main_window import ReviewWindow


class DetectAction(BackgroundAction):
    """Runs one detection at a time, started from the dialog."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window, 0)
        self.dialog: DetectDialog | None = None
        #: the last detection's outcome (for tests and the screenshot): result, sets added
        self.last: tuple[DetectResult, list[int]] | None = None

    def choose(self) -> None:
        """Open the dialog (non-blocking) with the session's last words and sensitivity;
        accepting it starts the detection."""
        model = self.window.model
        if model is None or self.task is not None:  # the status line shows the one running
            return
        text, sensitivity = detection_settings(model.session)
        session = model.session
        self._close_dialog()
        self.dialog = DetectDialog(self.window, text, sensitivity,
                                   lambda t, s: detect_request(session, t, s))
        self.dialog.accepted.connect(self._dialog_accepted)
        self.dialog.open()

    def _dialog_accepted(self) -> None:
        assert self.dialog is not None and self.dialog.request is not None
        self.start(self.dialog.request)

    def start(self, request: DetectRequest) -> None:
        """Detect as ``request`` says, on a worker thread (not for another session's
        audio: a request made before another session opened is dropped)."""
        model = self.window.model
        if model is None or self.task is not None or request.audio != model.session.audio:
            return
        self.last_error = ""
        self.window.status.begin("detect", request.text)
        self.launch(model, request.run,
                    lambda text, f: self.window.status.report("detect", text, f))

    def start_if_needed(self) -> None:
        """Detections start from the dialog only (:meth:`start`)."""

    def cancel(self) -> None:
        """The operator's cancel: stop the detection under way."""
        if self.task is not None:
            self.task.cancel()

    def reset(self) -> None:
        """Another session opens: the dialog and the detection under way are for the
        previous one."""
        self._close_dialog()
        self.cancel()

    def _close_dialog(self) -> None:
        if self.dialog is not None:
            self.dialog.reject()
            self.dialog.deleteLater()
            self.dialog = None

    def _finished(self, result: DetectResult) -> None:
        model = self.take_model()
        if model is None:
            self.window.status.end("detect")
            return
        added = model.apply_detected(result)
        self.last = (result, added)
        self.window.status.end("detect", found_message(result, added, result_message))

    def _failed(self, message: str) -> None:
        if self.take_model() is None:  # another session is shown: nothing to say of it
            self.window.status.end("detect")
        elif message == "cancelled":
            self.window.status.end("detect", "finding trigger words cancelled")
        else:
            self.last_error = message
            self.window.status.end("detect", f"finding trigger words failed: {message}")
