"""A review model over a session file that saves back to it, noting each save."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from speechcal_core.review.model import ReviewModel
from speechcal_core.session.model import Session
from speechcal_core.session.store import load_session, save_session
from speechcal_core.sources import open_recording


def open_model(path: Path, saves: list | None = None,
               note: Callable[[Session], object] = Session.counts) -> ReviewModel:
    """The model of ``path``; every autosave writes the file and appends ``note(session)``
    to ``saves`` (when given)."""
    session = load_session(path)

    def autosave(s: Session) -> None:
        save_session(s, path)
        if saves is not None:
            saves.append(note(s))

    return ReviewModel(session, open_recording(session.recording), autosave=autosave)
