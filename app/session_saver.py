"""Where the window saves its session, when that last worked, and why it last failed.

A failed save is never raised into Qt: the decisions stay in memory, the window warns
until a later save (autosave or "Save session as…") succeeds. A file that another window
or program changed since this window opened or last saved it is not overwritten: that is
a failed save too.

An autosave is written off the UI thread: the UI thread only takes a snapshot of the
session (its sets and top-level entries, a few milliseconds); encoding it (megabytes of
frame details with a dozen cameras), the write, its fsync and the ``.bak`` copy run on
a thread of their own, one save after another, the latest snapshot replacing one that
waits. :meth:`SessionSaver.flush` waits for them: before anything reads the file or
asks whether the session is saved (another session opened, the window closing, Save
as…), and the app waits for them before it exits (:func:`app.tasks.wait_for_all`).
"""

from __future__ import annotations

import threading
import time
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, Signal

from app.tasks import BackgroundTask, lane, start
from speechcal_core.session.backups import restored_note
from speechcal_core.session.model import Session
from speechcal_core.session.store import (
    SessionFileError,
    SessionWriter,
    file_stamp,
    save_document,
    save_session,
    session_file,
    session_snapshot,
)

SAVE_AS_HINT = "File ▸ Save session as… (Ctrl+Shift+S) writes them to another file"


def saved_text(saved_at: float, now: float) -> str:
    """ "saved 42 s ago", "saved 10 min ago", "saved at 11:00" or with the date."""
    ago = int(now - saved_at)
    if ago < 2:
        return "saved just now"
    if ago < 60:
        return f"saved {ago} s ago"
    if ago < 3600:
        return f"saved {ago // 60} min ago"
    then, today = time.localtime(saved_at), time.localtime(now)
    if then[:3] == today[:3]:
        return time.strftime("saved at %H:%M", then)
    return time.strftime("saved %Y-%m-%d %H:%M", then)


class SessionSaver(QObject):
    """Saves the open session to its file; remembers the last success and failure."""

    #: a background save ended (UI thread): :attr:`error` and :attr:`saved_at` say how
    saved = Signal()

    def __init__(self, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.path: Path | None = None
        self.saved_at: float | None = None  # wall-clock time of the file's last save
        self.error: SessionFileError | None = None  # the last save's failure, if it failed
        self._writer = SessionWriter()  # re-uses the text of what a save left unchanged
        self._on_disk: tuple[int, int, int] | None = None  # the file as this window left it
        # the worker's state, under _lock: the snapshot waiting to be written (with its
        # path), and whether a worker runs (it writes until nothing waits)
        self._lock = threading.Condition()
        self._pending: tuple[Path, dict[str, Any]] | None = None
        self._writing = False
        self._unreported = False  # saves ended that :attr:`saved` has not told of
        # the kept previous version opened, which the first save restores at :attr:`path`
        self._restores: Path | None = None
        #: what the save that restored it said (where the file it replaced went), until
        #: the window has told it (and set it to "")
        self.restored = ""

    @property
    def unsaved(self) -> bool:
        """Whether the window holds changes its file does not have (as far as the saves
        ended say: :meth:`flush` first to know for sure)."""
        return self.error is not None

    def busy(self) -> bool:
        """Whether a save waits or is being written."""
        with self._lock:
            return self._writing

    def reset(self, path: Path | None,
              stamp: tuple[int, int, int] | None = None, restores: Path | None = None
              ) -> None:
        """A session was opened from (or processed into) ``path``, whose file was as
        ``stamp`` says when it was read (``file_stamp``; by default, as it is now); or
        ``restores``, a kept previous version of ``path``, was opened: the first save
        restores it there (``backups`` says the rule). The previous session's saves are
        written first."""
        self.flush()
        self.path, self.error = path, None
        self._restores, self.restored = restores, ""
        self._writer = SessionWriter()
        self._on_disk = stamp if stamp is not None or path is None else file_stamp(path)
        # the stamp's modification time (ns): when the file was last saved (not this
        # session, when a previous version it restores was opened)
        self.saved_at = self._on_disk[1] / 1e9 \
            if self._on_disk is not None and restores is None else None

    def save(self, session: Session) -> None:
        """Autosave to :attr:`path`, off the UI thread: :attr:`saved` is emitted when it
        is written or has failed (:attr:`error` set)."""
        if self.path is None:
            return
        document = session_snapshot(session, self.path)
        with self._lock:
            self._pending = (self.path, document)
            if self._writing:
                return  # the worker running takes it next
            self._writing = True
        task = BackgroundTask(self._write_pending)
        task.signals.finished.connect(self._written)
        start(task, lane("SessionSaver"))

    def flush(self) -> None:
        """Wait until every save asked for is written (or has failed); :attr:`error` and
        :attr:`saved_at` then say how the last one went (UI thread)."""
        with self._lock:
            while self._writing:
                self._lock.wait()
        self._report_saves()

    def _write_pending(self, _report: object) -> None:
        """The worker: write the snapshot waiting, until none waits."""
        while True:
            with self._lock:
                job, self._pending = self._pending, None
                if job is None:
                    self._writing, self._unreported = False, True
                    self._lock.notify_all()
                    return
                expect, restores = self._on_disk, self._restores
            path, document = job
            try:
                aside = save_document(document, path, self._writer, expect=expect,
                                      keep_aside=restores is not None)
            except SessionFileError as exc:
                with self._lock:
                    self.error = exc
            except Exception as exc:  # said like any failure; _writing must not stay on
                with self._lock:
                    self.error = SessionFileError(f"{path}: cannot save the session ({exc})")
            else:
                stamp = file_stamp(path)
                with self._lock:
                    self.saved_at, self.error, self._on_disk = time.time(), None, stamp
                    if restores is not None:
                        self._restores = None
                        self.restored = restored_note(restores, path, aside)

    def _written(self, _result: object) -> None:
        """A worker ended (UI thread): say how its saves went."""
        self._report_saves()

    def _report_saves(self) -> None:
        """Emit :attr:`saved` once for the saves ended since it was last emitted."""
        with self._lock:
            ended, self._unreported = self._unreported, False
        if ended:
            self.saved.emit()

    def save_as(self, session: Session, path: Path) -> None:
        """Save to ``path`` and autosave there from now on (a link: its target, as
        ``session_file`` says); raises SessionFileError."""
        self.flush()
        path = session_file(path)
        save_session(session, path, self._writer)
        self.path, self.saved_at, self.error = path, time.time(), None
        self._restores = None  # saved elsewhere: the version opened restores nothing
        self._on_disk = file_stamp(path)

    def label(self, now: float) -> tuple[str, str]:
        """The status line's text and tooltip: the last save, or a warning."""
        if self.error is not None:
            # the reason in full stands on the status line's left, this stays in view
            return ("not saved · Ctrl+Shift+S saves elsewhere",
                    f"{self.error}\nThe decisions are kept in this window; {SAVE_AS_HINT}.")
        if self.path is None or self.saved_at is None:
            return "", ""
        stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(self.saved_at))
        return saved_text(self.saved_at, now), f"{self.path}\nlast saved {stamp}"


def free_name_beside(path: Path) -> Path:
    """``<stem>-2<suffix>`` beside ``path`` (or -3, -4...): the first name not taken, to
    save a window's decisions next to a session file another window changed."""
    n = 2
    while (candidate := path.with_name(f"{path.stem}-{n}{path.suffix}")).exists():
        n += 1
    return candidate
