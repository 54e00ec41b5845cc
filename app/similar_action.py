"""The window's "find more like this" (S): the session's audio searched on a worker thread
for words like the current set's, the sets found added on the UI thread.

What to search for and how the words become sets is
:class:`~speechcal_core.review.model.ReviewModel`'s business; this reads the audio file
once per opened session (on the first search, off the UI thread), reports on the status
line (job ``"similar"``) and cancels.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from app.background_action import BackgroundAction
from speechcal_core.review.similar import SessionAudio, result_message

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.review.loading import ReviewInputs
    from speechcal_core.review.similar import SimilarRequest, SimilarResult

#: a second S within this time runs one search
DELAY_MS = 50
#: the status line names at most this many of the sets a search added
NAMED_SETS = 8


def found_message(result: Any, added: list[int],
                  message: Callable[[Any, int], str] = result_message) -> str:
    """The status line's report of a finished search (``message(result, count)``, by
    default a "find more like this" one), naming the sets it added (by the ids the list
    shows), so one search's result reads apart from the next one's."""
    text = message(result, len(added))
    if not added:
        return text
    names = ", ".join(f"#{set_id}" for set_id in added[:NAMED_SETS])
    more = f" and {len(added) - NAMED_SETS} more" if len(added) > NAMED_SETS else ""
    return f"{text} (added {names}{more})"


class SimilarAction(BackgroundAction):
    """Runs one search at a time; a search asked for meanwhile runs after it."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window, DELAY_MS)
        self.wanted: SimilarRequest | None = None  # the next search to run
        self.audio: SessionAudio | None = None
        self._audio_of: ReviewInputs | None = None  # the session ``audio`` belongs to
        #: the last search's outcome (for tests and the screenshot): result, sets added
        self.last: tuple[SimilarResult, list[int]] | None = None

    def ask(self, request: SimilarRequest | None) -> None:
        """The model's ``"similar"`` event: search for ``request`` (None: say why not)."""
        model = self.window.model
        if request is None:
            if model is not None and model.similar_refused:
                self.window.status.end("similar", model.similar_refused)
            return
        self.wanted = request
        self.window.status.begin("similar", request.text)
        self.schedule()

    def start_if_needed(self) -> None:
        model, inputs = self.window.model, self.window.inputs
        if model is None or inputs is None or self.task is not None or self.wanted is None:
            return
        request, self.wanted = self.wanted, None
        if self._audio_of is not inputs or self.audio is None:
            self.audio = SessionAudio(inputs.session.audio, inputs.session.audio_channel)
            self._audio_of = inputs
        audio = self.audio
        self.last_error = ""
        self.window.status.begin("similar", request.text)
        self.launch(model, lambda report: request.run(audio, report),
                    lambda text, f: self.window.status.report("similar", text, f))

    def reset(self) -> None:
        """Another session opens: forget its audio and what was asked for."""
        self.timer.stop()
        self.wanted = None
        self.audio, self._audio_of = None, None
        if self.task is not None:
            self.task.cancel()

    def cancel(self) -> None:
        """The operator's cancel: stop the search under way and forget the next one."""
        self.timer.stop()
        self.wanted = None
        if self.task is not None:
            self.task.cancel()

    def _finished(self, result: SimilarResult) -> None:
        model = self.take_model()
        if model is None:
            self.window.status.end("similar")
            return
        searched = result.request.set_id
        if all(s.id != searched for s in model.session.sets):  # removed meanwhile (Del)
            self.last = (result, [])
            self.window.status.end("similar", f"set #{searched} was removed while its "
                                   "search ran: nothing added from it")
            self.start_if_needed()
            return
        added = model.apply_similar(result)
        self.last = (result, added)
        self.window.status.end("similar", found_message(result, added))
        self.start_if_needed()

    def _failed(self, message: str) -> None:
        self.take_model()
        if message == "cancelled":
            self.window.status.end("similar", "search for more like this cancelled")
        else:
            self.last_error = message
            self.window.status.end("similar", f"search for more like this failed: {message}")
        self.start_if_needed()
