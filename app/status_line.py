"""The window's status line, shared by everything that runs in the background.

Opening, exporting, re-scoring and searching each report as a *job*: while jobs run the
line lists each one's text (with its percentage when more than one runs), the progress bar
follows the job started first, and Cancel stops them all. A job that ends leaves a
message, which replaces that job's earlier one. The messages of one spell of work stay
side by side (newest first), so an export's result is not lost when re-scoring finishes
after it; once the line has been quiet for :data:`QUIET_S`, whatever comes next replaces
them, so a result from long ago does not linger beside newer ones. A warning (a save that
failed) stays until its own job reports again. The same message from a job twice in a
row is counted ("(×2)"), also when other jobs ended in between, and so is a plain
message (what a key did) said again while it shows, so a repeated action visibly did
something.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

from PySide6.QtWidgets import QLabel, QProgressBar, QPushButton

from app.style import WARNING_SYMBOL

SEPARATOR = "  ·  "
#: no job ran and nothing was said for this long: the next job or message starts afresh
QUIET_S = 3.0


@dataclass
class _Job:
    text: str
    fraction: float | None = None


@dataclass
class _Note:
    """The message a job ended with."""

    text: str
    warning: bool = False  # stays until its job reports again
    #: a plain message that tells of an edit and the work it starts (re-scoring): it
    #: stays beside that work instead of giving way to it
    outlasts_work: bool = False
    repeats: int = 1  # said this many times in a row

    @property
    def shown(self) -> str:
        text = f"{WARNING_SYMBOL} {self.text}" if self.warning else self.text
        return f"{text} (×{self.repeats})" if self.repeats > 1 else text


class StatusLine:
    """Drives the status text, progress bar and Cancel button from the running jobs."""

    def __init__(self, text: QLabel, progress: QProgressBar, cancel: QPushButton,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.text, self.progress, self.cancel = text, progress, cancel
        self.clock = clock
        self._jobs: dict[str, _Job] = {}  # in the order they began
        self._notes: dict[str, _Note] = {}  # job -> message it ended with, newest last
        self._last: dict[str, _Note] = {}  # job -> the last message it ended with
        self._touched = clock()  # when a job last began, reported or ended

    def running(self, job: str | None = None) -> bool:
        """Whether ``job`` (or any job) is running."""
        return bool(self._jobs) if job is None else job in self._jobs

    def begin(self, job: str, text: str) -> None:
        """``job`` starts (or says something new while waiting); its old message goes."""
        self._start_afresh_if_quiet()
        self._notes.pop(job, None)
        said = self._notes.get("")
        if said is not None and not said.outlasts_work:
            del self._notes[""]  # a plain message is outdated by any new work
        old = self._jobs.get(job)
        self._jobs[job] = _Job(text, old.fraction if old else None)
        self._show()

    def report(self, job: str, text: str, fraction: float) -> None:
        """Progress of a running job (ignored once it has ended)."""
        if job in self._jobs:
            self._jobs[job] = _Job(text, fraction)
            self._show()

    def end(self, job: str, message: str = "", *, warning: bool = False) -> None:
        """``job`` stopped; ``message`` says how it went (a ``warning`` stays beside newer
        messages until ``job`` reports again)."""
        if message:
            self._start_afresh_if_quiet()
        self._jobs.pop(job, None)
        self._notes.pop(job, None)
        if message:
            note = _Note(message, warning)
            last = self._last.get(job)
            if not warning and last is not None and last.text == message and not last.warning:
                note.repeats = last.repeats + 1
            self._notes[job] = note
            self._last[job] = note
        self._show()

    def say(self, message: str, *, outlasts_work: bool = False) -> None:
        """A plain message (not from a job): replaces every job's message but warnings.
        One that ``outlasts_work`` (what C or T did, "Ctrl+Z takes it back") stays when
        the work it starts begins, as a job's message does; others give way to it. The
        message shown said again is counted ("(×2)"), as a job's is."""
        shown = self._notes.get("")
        self._notes = {job: n for job, n in self._notes.items() if n.warning}
        if message:
            note = _Note(message, outlasts_work=outlasts_work)
            if shown is not None and shown.text == message:
                note.repeats = shown.repeats + 1
            self._notes[""] = note
        self._show()

    def revise(self, message: str, revised: str) -> None:
        """Put ``revised`` in place of the plain ``message`` if that is still shown (a
        count it gave has changed); other messages stay as they are."""
        note = self._notes.get("")
        if note is not None and note.text == message and revised != message:
            self._notes[""] = _Note(revised)
            self._show()

    def withdraw(self, message: str, job: str = "") -> None:
        """Take back the plain ``message`` (or ``job``'s) if it is still shown (it no
        longer holds: "no set listed after set #4" once J went to another set)."""
        note = self._notes.get(job)
        if message and note is not None and note.text == message:
            del self._notes[job]
            self._show()

    def _start_afresh_if_quiet(self) -> None:
        """New work or news on a line quiet for :data:`QUIET_S`: the messages of the
        spell before are outdated (warnings stay)."""
        if not self._jobs and self.clock() - self._touched >= QUIET_S:
            self._notes = {job: n for job, n in self._notes.items() if n.warning}

    def _show(self) -> None:
        self._touched = self.clock()
        jobs = list(self._jobs.values())
        several = len(jobs) > 1
        parts = [f"{j.text} {round(100 * j.fraction)}%" if several and j.fraction is not None
                 else j.text for j in jobs]
        parts += [n.shown for n in reversed(self._notes.values())]
        self.text.setText(SEPARATOR.join(parts))
        self.text.setToolTip("\n".join(parts))
        measured = [j.fraction for j in jobs if j.fraction is not None]
        if jobs:
            self.progress.setValue(int(1000 * measured[0]) if measured else 0)
        self.progress.setVisible(bool(jobs))
        self.cancel.setVisible(bool(jobs))
        self.cancel.setToolTip("stop " + " and ".join(j.text.rstrip("…") for j in jobs)
                               if jobs else "")
