"""File-system helpers: atomic file writes and folders that appear complete or not at all."""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from speechcal_core.errors import SpeechCalError


class OutputExistsError(SpeechCalError):
    """The output exists and replacing it was not asked for."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def atomic_write_text(path: str | Path, text: str, *, keep_backup: bool = False) -> None:
    """Write ``text`` to ``path`` atomically (temp file in the same folder, fsync, replace).

    With ``keep_backup`` the previous version, if any, is kept as ``<path>.bak``.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        mode = path.stat().st_mode & 0o777 if path.exists() else 0o666 & ~_umask()
        os.chmod(tmp, mode)  # mkstemp makes 0600; give the file its usual permissions
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        if keep_backup and path.exists():
            shutil.copy2(path, path.with_name(path.name + ".bak"))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def staged_directory(target: str | Path, *, force: bool = False) -> Iterator[Path]:
    """Yield a temporary sibling folder that replaces ``target`` only when the block succeeds.

    An existing ``target`` is an :class:`OutputExistsError` unless ``force``; on failure the
    partial folder is removed and ``target`` is left untouched.
    """
    target = Path(target).absolute()
    if target.exists() and not force:
        raise OutputExistsError(f"{target} already exists; choose another folder or pass --force")
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-", dir=parent))
        os.chmod(staging, 0o777 & ~_umask())  # mkdtemp makes 0700
    except OSError as exc:
        raise SpeechCalError(
            f"{target}: cannot write there ({exc.strerror}); choose a writable folder"
        ) from exc
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    old = None
    if target.exists():
        old = parent / f".{target.name}.old-{os.getpid()}"
        os.replace(target, old)
    os.replace(staging, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
