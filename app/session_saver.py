"""Where the window saves its session, when that last worked, and why it last failed.

A failed save is never raised into Qt: the decisions stay in memory, the window warns
until a later save (autosave or "Save session as…") succeeds. A file that another window
or program changed since this window opened or last saved it is not overwritten: that is
a failed save too.
"""

from __future__ import annotations

import time
from pathlib import Path

from speechcal_core.session.model import Session
from speechcal_core.session.store import (
    SessionFileError,
    SessionWriter,
    file_stamp,
    save_session,
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


class SessionSaver:
    """Saves the open session to its file; remembers the last success and failure."""

    def __init__(self) -> None:
        self.path: Path | None = None
        self.saved_at: float | None = None  # wall-clock time of the file's last save
        self.error: SessionFileError | None = None  # the last save's failure, if it failed
        self._writer = SessionWriter()  # re-uses the text of what a save left unchanged
        self._on_disk: tuple[int, int, int] | None = None  # the file as this window left it

    @property
    def unsaved(self) -> bool:
        """Whether the window holds changes its file does not have."""
        return self.error is not None

    def reset(self, path: Path | None,
              stamp: tuple[int, int, int] | None = None) -> None:
        """A session was opened from (or processed into) ``path``, whose file was as
        ``stamp`` says when it was read (``file_stamp``; by default, as it is now)."""
        self.path, self.error = path, None
        self._writer = SessionWriter()
        self._on_disk = stamp if stamp is not None or path is None else file_stamp(path)
        # the stamp's modification time (ns): when the file was last saved
        self.saved_at = self._on_disk[1] / 1e9 if self._on_disk is not None else None

    def save(self, session: Session) -> bool:
        """Autosave to :attr:`path`; False (and :attr:`error` set) when it failed."""
        if self.path is None:
            return True
        try:
            save_session(session, self.path, self._writer, expect=self._on_disk)
        except SessionFileError as exc:
            self.error = exc
            return False
        self.saved_at, self.error = time.time(), None
        self._on_disk = file_stamp(self.path)
        return True

    def save_as(self, session: Session, path: Path) -> None:
        """Save to ``path`` and autosave there from now on; raises SessionFileError."""
        save_session(session, path, self._writer)
        self.path, self.saved_at, self.error = path, time.time(), None
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
