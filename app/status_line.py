"""The window's status line, shared by everything that runs in the background.

Opening, exporting and re-scoring each report as a *job*: while jobs run the line lists
each one's text (with its percentage when more than one runs), the progress bar follows
the job started first, and Cancel stops them all. A job that ends leaves a message, kept
beside the other jobs' (newest first) until that job runs again, so an export's result
is not lost when re-scoring finishes after it.
"""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtWidgets import QLabel, QProgressBar, QPushButton

SEPARATOR = "  ·  "


@dataclass
class _Job:
    text: str
    fraction: float | None = None


class StatusLine:
    """Drives the status text, progress bar and Cancel button from the running jobs."""

    def __init__(self, text: QLabel, progress: QProgressBar, cancel: QPushButton) -> None:
        self.text, self.progress, self.cancel = text, progress, cancel
        self._jobs: dict[str, _Job] = {}  # in the order they began
        self._notes: dict[str, str] = {}  # job -> message it ended with, newest last

    def running(self, job: str | None = None) -> bool:
        """Whether ``job`` (or any job) is running."""
        return bool(self._jobs) if job is None else job in self._jobs

    def begin(self, job: str, text: str) -> None:
        """``job`` starts (or says something new while waiting); its old message goes."""
        self._notes.pop(job, None)
        self._notes.pop("", None)  # a plain message is outdated by any new work
        old = self._jobs.get(job)
        self._jobs[job] = _Job(text, old.fraction if old else None)
        self._show()

    def report(self, job: str, text: str, fraction: float) -> None:
        """Progress of a running job (ignored once it has ended)."""
        if job in self._jobs:
            self._jobs[job] = _Job(text, fraction)
            self._show()

    def end(self, job: str, message: str = "") -> None:
        """``job`` stopped; ``message`` says how it went."""
        self._jobs.pop(job, None)
        self._notes.pop(job, None)
        if message:
            self._notes[job] = message
        self._show()

    def say(self, message: str) -> None:
        """A plain message (not from a job): replaces every job's message."""
        self._notes = {"": message} if message else {}
        self._show()

    def _show(self) -> None:
        jobs = list(self._jobs.values())
        several = len(jobs) > 1
        parts = [f"{j.text} {round(100 * j.fraction)}%" if several and j.fraction is not None
                 else j.text for j in jobs]
        parts += reversed(self._notes.values())
        self.text.setText(SEPARATOR.join(parts))
        self.text.setToolTip("\n".join(parts))
        measured = [j.fraction for j in jobs if j.fraction is not None]
        if jobs:
            self.progress.setValue(int(1000 * measured[0]) if measured else 0)
        self.progress.setVisible(bool(jobs))
        self.cancel.setVisible(bool(jobs))
        self.cancel.setToolTip("stop " + " and ".join(j.text.rstrip("…") for j in jobs)
                               if jobs else "")
