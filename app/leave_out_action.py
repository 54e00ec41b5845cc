"""Edit ▸ Leave a camera out…: a stream taken out of the session opened (one camera
recorded twice, a depth topic), its review work kept.

The session is opened again with the stream left out: the core
(:func:`speechcal_core.review.loading.load_for_review` with ``streams``) takes its frames,
calibration and coverage out, saves the file and says so on the status line.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtGui import QAction
from PySide6.QtWidgets import QInputDialog

from speechcal_core.sources import StreamChoice

if TYPE_CHECKING:
    from app.main_window import ReviewWindow

LEAVE_OUT = "Leave a camera out"


class LeaveOutAction(QAction):
    """The menu entry; on while a session with more than one camera is open."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(f"{LEAVE_OUT}…", window)
        self.window = window
        self.setToolTip("Take one camera's stream out of this session (one camera recorded "
                        "twice, a depth topic); the review decisions are kept")
        #: asks which stream to leave out, None to leave none (a dialog; tests put a
        #: function here)
        self.ask: Callable[[list[str]], str | None] = self._ask
        self.triggered.connect(self.choose)
        self.setEnabled(False)

    def update(self) -> None:
        """On only while the session opened has more than one camera."""
        model = self.window.model
        self.setEnabled(model is not None and len(model.streams) > 1)

    def choose(self) -> None:
        """Ask which camera, then open the session again without it."""
        model, inputs = self.window.model, self.window.inputs
        if model is None or inputs is None or len(model.streams) < 2:
            return
        name = self.ask(list(model.streams))
        if name:
            self.window.open(session_path=str(inputs.session_path),
                             streams=StreamChoice(skip=(name,)))

    def _ask(self, streams: list[str]) -> str | None:
        """The dialog behind :attr:`ask`."""
        name, ok = QInputDialog.getItem(
            self.window, LEAVE_OUT,
            "Leave this camera out of the session (its frames, calibration and coverage "
            "go; the review decisions stay):", streams, 0, False)
        return name if ok else None
