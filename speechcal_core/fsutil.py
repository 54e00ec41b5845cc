"""File-system helpers: atomic file writes and folders that appear complete or not at all."""

from __future__ import annotations

import contextlib
import glob
import os
import shlex
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path

from speechcal_core.errors import SpeechCalError

try:
    import fcntl
except ImportError:  # Windows: no folder locks, so abandoned staging folders are kept
    fcntl = None  # type: ignore[assignment]


class OutputExistsError(SpeechCalError):
    """The output exists and replacing it was not asked for."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def shell_quoted(path: str | Path) -> str:
    """``path`` as a shell command line takes it (quoted where it holds spaces and the
    like), for commands an error message tells the user to run."""
    return shlex.quote(str(path))


def atomic_write_text(path: str | Path, text: str, *, keep_backup: bool = False) -> None:
    """Write ``text`` to ``path`` atomically (temp file in the same folder, fsync, replace).

    With ``keep_backup`` the previous version, if any, is kept as ``<path>.bak``. A file
    name in ``text`` that is not UTF-8 (Python holds its bytes as lone surrogates) is
    written as the escape ``\udce9``: in a JSON string that reads back as the same name.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        mode = path.stat().st_mode & 0o777 if path.exists() else 0o666 & ~_umask()
        os.chmod(tmp, mode)  # mkstemp makes 0600; give the file its usual permissions
        with os.fdopen(fd, "w", encoding="utf-8", errors="backslashreplace") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        if keep_backup and path.exists():
            copy_atomically(path, path.with_name(path.name + ".bak"))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def copy_atomically(source: Path, target: Path) -> None:
    """Copy ``source`` to ``target`` through a temp file beside it: a copy failing midway
    (a full disk) leaves ``target`` as it was, not cut off."""
    with written_atomically(target, sync=False) as tmp:
        shutil.copy2(source, tmp)


@contextlib.contextmanager
def written_atomically(target: Path, *, sync: bool = True) -> Iterator[Path]:
    """A temp file beside ``target`` (with a new file's usual permissions) to write; it
    replaces ``target`` when the block ends (after an fsync, with ``sync``), and is
    removed if the block raises: ``target`` is whole or as it was."""
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    try:
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600
        yield Path(tmp)
        if sync:
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _remove(path: Path) -> None:
    """Remove a file, a link (not what it points to) or a folder tree; errors propagate."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink()


def same_file(a: str | Path, b: str | Path) -> bool:
    """Whether two paths name the same file (both resolved; a missing one compares by
    path)."""
    return Path(a).resolve() == Path(b).resolve()


def folder_write_problem(folder: str | Path) -> str | None:
    """Why no file can be written in ``folder`` (None when one can): it or a folder above
    it is a file, it is missing, or the system's reason (read-only, no permission)."""
    folder = Path(folder)
    in_the_way = file_in_the_way(folder)
    if in_the_way:
        return in_the_way
    if not folder.is_dir():
        return f"the folder {folder} does not exist"
    try:
        with tempfile.TemporaryFile(dir=folder, prefix=".speechcal-write-check-"):
            pass
    except OSError as exc:
        return exc.strerror or str(exc)
    return None


def file_in_the_way(folder: Path) -> str | None:
    """"X is a file, not a folder" when ``folder``, or the closest of its ancestors that
    exists, is not a folder (None otherwise)."""
    for candidate in (folder, *folder.parents):
        if os.path.lexists(candidate):
            return None if candidate.is_dir() else f"{candidate} is a file, not a folder"
    return None


def _aside(target: Path) -> Path:
    """A free hidden sibling name to move ``target`` to while its replacement goes in."""
    base = target.parent / f".{_sibling_stem(target)}.old-{os.getpid()}"
    candidate, n = base, 0
    while os.path.lexists(candidate):
        n += 1
        candidate = base.with_name(f"{base.name}-{n}")
    return candidate


@contextlib.contextmanager
def staged_directory(target: str | Path, *, force: bool = False,
                     may_replace: Callable[[Path], str] | None = None) -> Iterator[Path]:
    """Yield a temporary sibling folder that replaces ``target`` only when the block succeeds.

    An existing ``target`` (folder, file or link) is an :class:`OutputExistsError` unless
    ``force``; on failure the partial folder is removed and ``target`` is left untouched.
    A replaced ``target`` that cannot be removed afterwards is a :class:`SpeechCalError`
    naming where it was left.

    What is at ``target`` is looked at again once the block is done: a ``target`` that
    appeared meanwhile (another program, a second export to the same place), or one that
    ``may_replace`` now objects to (its reason, "" when it may go), is left alone; the
    finished output is kept at a free sibling name and a :class:`SpeechCalError` says where.

    The staging folder stays locked while it is written. One that no process holds any
    more is what a killed write (SIGKILL, power loss) left behind: the next write of the
    same ``target`` removes it (``_sweep_abandoned``).
    """
    target = Path(target).absolute()
    _refuse_working_folder(target)
    existed = os.path.lexists(target)
    if existed and not force:
        raise OutputExistsError(f"{target} already exists; choose another folder or pass --force")
    parent = target.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        _sweep_abandoned(target)
        staging, lock = _locked_staging(target)
    except OSError as exc:
        reason = file_in_the_way(parent) or exc.strerror
        raise SpeechCalError(
            f"{target}: cannot write there ({reason}); choose a writable folder"
        ) from exc
    try:
        try:
            yield staging
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)  # the block's own error is the one
            raise
        _check_still_replaceable(staging, target, existed, may_replace)
        old = _swap_in(staging, target)
    finally:
        if lock is not None:
            os.close(lock)
    if old is not None:
        try:
            _remove(old)
        except OSError as exc:
            raise SpeechCalError(
                f"{target} is written, but what it replaced could not be removed "
                f"({exc.strerror}) and is left at {old}; remove it by hand"
            ) from exc


def _staging_prefix(target: Path, state: str) -> str:
    """The name a staging folder of ``target`` starts with: ``state`` is "starting" until
    it is locked, then "partial"."""
    return f".{_sibling_stem(target)}.{state}-"


#: the longest name a file system takes (bytes), and what the names of the siblings
#: written beside an output add to its name (".NAME.starting-XXXXXXXX", ".NAME.old-PID-N")
_NAME_MAX = 255
_SIBLING_EXTRA = 24


def staging_name_bytes(target: str | Path) -> int:
    """How long (bytes) the name of the hidden folder that :func:`staged_directory` writes
    ``target`` in is: a file inside it has a path this much longer than inside ``target``,
    less ``target``'s own name."""
    prefix = _staging_prefix(Path(target).absolute(), "partial")
    return len(os.fsencode(prefix)) + _STAGING_RANDOM


#: characters ``tempfile.mkdtemp`` adds to a staging folder's prefix
_STAGING_RANDOM = 8


def _sibling_stem(target: Path) -> str:
    """``target``'s name, shortened where a sibling named after it would pass the file
    system's limit on a name's length (an output named with 240 bytes is fine itself)."""
    name = target.name
    while len(os.fsencode(name)) > _NAME_MAX - _SIBLING_EXTRA:
        name = name[:-1]
    return name


def _locked_staging(target: Path) -> tuple[Path, int | None]:
    """A new staging folder beside ``target`` and the descriptor holding its lock (None
    where the system has no folder locks). It is locked before it takes its "partial"
    name, so a sweep never sees it unheld."""
    starting = Path(tempfile.mkdtemp(prefix=_staging_prefix(target, "starting"),
                                     dir=target.parent))
    try:
        os.chmod(starting, 0o777 & ~_umask())  # mkdtemp makes 0700
        lock = _lock(starting)
        staging = starting.with_name(_staging_prefix(target, "partial")
                                     + starting.name[len(_staging_prefix(target, "starting")):])
        os.rename(starting, staging)
    except BaseException:
        shutil.rmtree(starting, ignore_errors=True)
        raise
    return staging, lock


def _lock(folder: Path) -> int | None:
    """An open descriptor holding an exclusive lock on ``folder``, or None when another
    process holds it (or the system has no folder locks). The system ends the lock with
    the process however it ends, so an unheld staging folder is an abandoned one."""
    if fcntl is None:
        return None
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return None
    return fd


def _sweep_abandoned(target: Path) -> None:
    """Remove the staging folders that killed writes of ``target`` left behind (a killed
    export can leave gigabytes of frames in a hidden folder). Those a running write holds
    are left alone, and so is everything where folders cannot be locked."""
    pattern = glob.escape(_staging_prefix(target, "partial")) + "*"
    for folder in target.parent.glob(pattern):
        if folder.is_symlink() or not folder.is_dir():
            continue
        lock = _lock(folder)
        if lock is None:
            continue
        try:
            shutil.rmtree(folder, ignore_errors=True)
        finally:
            os.close(lock)


def _refuse_working_folder(target: Path) -> None:
    """A ``target`` that is (or holds) the current folder is never replaced: the shell
    would be left in a deleted folder, showing nothing, as if nothing had been written."""
    try:
        here = Path.cwd().resolve()
    except OSError:
        return  # the current folder is gone already
    plain = Path(os.path.normpath(target))  # a link at the target itself is replaced, not
    real = plain.parent.resolve() / plain.name  # what it points to
    if real == here or real in here.parents:
        raise SpeechCalError(f"{target} is the current folder (or holds it); give the output "
                             "a new folder's name, such as ./export")


def _check_still_replaceable(staging: Path, target: Path, existed: bool,
                             may_replace: Callable[[Path], str] | None) -> None:
    """Raise (keeping the finished ``staging`` under a free sibling name) when ``target``
    appeared while it was written, or ``may_replace`` objects to what is there now."""
    if not os.path.lexists(target):
        return
    problem = "it appeared while this was being written" if not existed else (
        may_replace(target) if may_replace is not None else "")
    if not problem:
        return
    kept = _free_sibling(target)
    try:
        os.replace(staging, kept)
    except OSError as exc:
        shutil.rmtree(staging, ignore_errors=True)
        raise SpeechCalError(f"{target}: left as it is ({problem}), and the new output "
                             f"could not be kept ({exc.strerror})") from exc
    raise SpeechCalError(f"{target}: left as it is ({problem}); the new output is complete "
                         f"at {kept}")


def _free_sibling(target: Path) -> Path:
    """``<target>-new``, or ``-new-2``, ``-new-3``... : the first name not taken."""
    stem = _sibling_stem(target)
    candidate, n = target.with_name(f"{stem}-new"), 1
    while os.path.lexists(candidate):
        n += 1
        candidate = target.with_name(f"{stem}-new-{n}")
    return candidate


def _swap_in(staging: Path, target: Path) -> Path | None:
    """Rename ``staging`` to ``target``, moving an existing ``target`` aside first; returns
    where it went. On failure the old ``target`` is put back and ``staging`` removed."""
    old = _aside(target) if os.path.lexists(target) else None
    try:
        if old is not None:
            os.replace(target, old)
        os.replace(staging, target)
    except OSError as exc:
        kept = "nothing was replaced"
        if old is not None and os.path.lexists(old):
            try:
                os.replace(old, target)
            except OSError:
                kept = f"what it held is at {old}; move it back by hand"
        shutil.rmtree(staging, ignore_errors=True)  # the swap's error is the one to report
        raise SpeechCalError(
            f"{target}: cannot put the new output in place ({exc.strerror}); {kept}"
        ) from exc
    return old


def plain_absolute(path: str | Path) -> Path:
    """``path`` made absolute without "." or ".." steps, by its names alone (links are
    left as they are)."""
    return Path(os.path.normpath(Path(path).absolute()))


def _spellings(path: Path, *, follow_last: bool) -> set[Path]:
    """``path`` made absolute without ``..``, and with links resolved (all of them, or
    all but the last part): the ways one file may be named."""
    plain = plain_absolute(path)
    real = plain.resolve() if follow_last else plain.parent.resolve() / plain.name
    return {plain, real}


def overlap(out: Path, inputs: dict[str, list[Path]]) -> tuple[str, str, Path] | None:
    """Whether writing ``out`` would touch one of ``inputs`` (what it is -> its paths):
    ``("is" | "holds" | "inside", what, path)`` for the first that ``out`` is, holds (a
    folder around it) or lies inside (a folder input), else None. Links and ``..`` are
    followed, but not a link at ``out`` itself (replacing a link leaves what it points to).
    """
    outs = _spellings(out, follow_last=False)
    for what, paths in inputs.items():
        for p in paths:
            spellings = _spellings(p, follow_last=True) | _spellings(p, follow_last=False)
            for o, q in ((o, q) for o in outs for q in spellings):
                if o == q:
                    return "is", what, p
                if o in q.parents:
                    return "holds", what, p
                if q in o.parents:
                    return "inside", what, p
    return None
