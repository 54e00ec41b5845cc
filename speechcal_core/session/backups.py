"""Earlier versions of a session file kept beside it: ``SESSION.json.bak`` (the version
before the last save) and ``SESSION.json.bak.1``, ``.bak.2``, … (review work set aside).

Opening a kept previous version is restoring it (:func:`restored_name`): the review's
session file is ``SESSION.json``, not the version opened. Nothing is written until
review work is saved (opened to be looked at, no file changes); the first save writes
``SESSION.json`` and keeps the ``SESSION.json`` it replaces as a free ``.bak.N`` (never
as ``.bak``: that may be the very version opened, or an older one), and says where
(:func:`restored_note`). The version opened is left as it is; later saves go on as
usual. (Saved beside itself, it became ``SESSION.json.bak.bak`` while ``SESSION.json``
kept the other version.)
"""

from __future__ import annotations

import os
import re
from pathlib import Path

#: a session file's name: SESSION.json (any case), or a previous version of one that
#: saving kept (SESSION.json.bak, SESSION.json.bak.1), which a damaged file's error names
_SESSION_NAME = re.compile(r"\.json(\.bak(\.\d+)?)?$", re.IGNORECASE)


#: a kept previous version's name; group 1 is the session file's
_KEPT_NAME = re.compile(r"^(.+\.json)\.bak(\.\d+)?$", re.IGNORECASE)


def restored_name(path: Path) -> Path | None:
    """The session file that ``path``, a kept previous version of it (SESSION.json.bak,
    SESSION.json.bak.N), is restored as: SESSION.json beside it; None for any other name."""
    found = _KEPT_NAME.match(path.name)
    return path.with_name(found.group(1)) if found else None


def restoring_note(kept: Path, path: Path) -> str:
    """What opening ``kept``, a previous version of the session file ``path``, says."""
    aside = free_name(path.with_name(path.name + ".bak"))
    then = f"; the {path.name} there now is then kept as {aside.name}" if path.exists() else ""
    return (f"{kept.name} is a kept previous version: review work saved restores it as "
            f"{path.name}{then}")


def restored_note(kept: Path, path: Path, aside: Path | None) -> str:
    """What the first save of ``kept`` restored as ``path`` says: where the file it
    replaced went (``aside``; None when there was none)."""
    return (f"{kept.name} restored as {path.name}"
            + (f"; the {path.name} it replaced is kept as {aside.name}" if aside else ""))


def named_as_session(path: str) -> bool:
    """Whether ``path`` is named as a session file (or a kept previous version of one)."""
    return _SESSION_NAME.search(path) is not None


def review_work_in(path: Path) -> str:
    """What an operator did in the session file at ``path`` (``summary.review_work``);
    "" for nothing, or a file that does not read as a session."""
    from speechcal_core.review.summary import review_work
    from speechcal_core.session.store import SessionFileError, load_session

    try:
        return review_work(load_session(path))
    except SessionFileError:
        return ""


def free_name(bak: Path) -> Path:
    """``SESSION.json.bak.1`` (or .2, …): the first such name no file has."""
    n = 1
    while bak.with_name(f"{bak.name}.{n}").exists():
        n += 1
    return bak.with_name(f"{bak.name}.{n}")


def set_aside_backup_work(path: Path, work: str) -> str:
    """Move ``path``'s ``.bak`` to a free ``.bak.N`` when it holds review work and the
    session at ``path`` (whose review ``work`` is given) holds none, as ``process --force``
    leaves a reviewed file: the next save keeps the file it replaces as ``.bak``, which
    would give that work up. Says what was done ("" for nothing)."""
    bak = path.with_name(path.name + ".bak")
    if work or not bak.is_file():
        return ""
    kept = review_work_in(bak)
    if not kept:
        return ""
    older = free_name(bak)
    try:
        os.replace(bak, older)
    except OSError:  # a folder nothing can be saved in: the .bak is not replaced either
        return ""
    return (f"{bak.name} holds review work ({kept}) and {path.name} none: it is kept as "
            f"{older.name}, as saving keeps the file it replaces as {bak.name}")
