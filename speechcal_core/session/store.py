"""Reading and writing SESSION.json (DESIGN.md §3): atomic, with .bak, schema-checked."""

from __future__ import annotations

import errno
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from speechcal_core.errors import SpeechCalError
from speechcal_core.fsutil import (
    atomic_write_text,
    copy_atomically,
    folder_write_problem,
    plain_absolute,
    shell_quoted,
)
from speechcal_core.session.backups import free_name
from speechcal_core.session.model import STREAMS_KEY, FrameSet, Session
from speechcal_core.sync.model import SyncModel

SCHEMA = 1


class SessionFileError(SpeechCalError):
    """A session file that cannot be read, or comes from a newer SpeechCal."""


class SessionChangedError(SessionFileError):
    """A session file that someone else changed since it was read: not overwritten."""


def session_file(path: str | Path) -> Path:
    """The file a session path names: ``path`` itself, or where it leads when it is a
    symbolic link (resolved once, when the session is opened or first saved).

    A session reached through a link is the link's target: it is read and saved there
    (the atomic replace and the ``.bak`` happen beside the target, so the link stays a
    link and the target holds the review work), and the paths it stores are relative to
    the TARGET's folder, not the link's: the session opens alike through any link to it.
    A path that is no link comes back as it was given.
    """
    path = Path(path)
    return path.resolve() if path.is_symlink() else path


def session_to_dict(session: Session, session_path: Path) -> dict[str, Any]:
    """The JSON document, ``schema`` first, paths relative to the session file's folder
    (the link's target's folder for a link: :func:`session_file`)."""
    return _document(session, session_path, [s.to_dict() for s in session.sets])


def _document(session: Session, session_path: Path, sets: list[Any]) -> dict[str, Any]:
    """:func:`session_to_dict` with ``sets`` for its sets."""
    base = session_file(session_path).absolute().parent
    return {
        "schema": SCHEMA,
        "recording": [_relative(p, base) for p in session.recording],
        "audio": _relative(session.audio, base) if session.audio else None,
        **({"audio_channel": session.audio_channel}
           if session.audio_channel is not None else {}),
        "trigger_words": session.triggers_word,
        "sync": {**_with_audio_path(session.sync_evidence, lambda a: _relative(a, base)),
                 **session.sync.to_dict()},
        "sets": sets,
        "last_set_id": session.highest_set_id(),
        "calibration": session.calibration,
        **session.extra,
    }


def session_snapshot(session: Session, session_path: Path) -> dict[str, Any]:
    """What :func:`session_to_dict` gives, taken cheaply to be written later, maybe on
    another thread, while the session goes on changing: the sets as their (immutable)
    :class:`FrameSet` objects, and every top-level list or object copied, so that sets
    and details replaced or added afterwards do not reach it. Like :class:`SessionWriter`
    it relies on the review model replacing the items of those (a set's details, a
    camera's fit), never changing one in place. :class:`SessionWriter` encodes it."""
    document = _document(session, session_path, list(session.sets))
    return {k: dict(v) if isinstance(v, dict) else list(v) if isinstance(v, list) else v
            for k, v in document.items()}


def save_session(session: Session, path: str | Path,
                 writer: SessionWriter | None = None,
                 expect: tuple[int, int, int] | None = None, *, backup: bool = True,
                 keep_aside: bool = False) -> Path | None:
    """Write atomically; the previous version stays as ``<path>.bak`` (unless ``backup``
    is False: the ``.bak`` there is left as it is). A ``writer`` kept from save to save
    re-uses the text of what did not change (autosave). With ``expect`` (the
    :func:`file_stamp` the file had when it was read or last saved), a file that another
    window or program changed since is not overwritten: SessionFileError. A ``path``
    that is a symbolic link stays one: its target is written (:func:`session_file`).

    ``keep_aside`` is the first save of a kept previous version restored as ``path``
    (``backups`` says the rule): the file it replaces is kept as a free ``.bak.N``, the
    ``.bak`` left as it is; returns that ``.bak.N`` (None when nothing was replaced)."""
    path = session_file(path)
    return save_document(session_to_dict(session, path), path, writer, expect,
                         backup=backup, keep_aside=keep_aside)


def save_document(document: dict[str, Any], path: str | Path,
                  writer: SessionWriter | None = None,
                  expect: tuple[int, int, int] | None = None, *, backup: bool = True,
                  keep_aside: bool = False) -> Path | None:
    """:func:`save_session` for a document already taken (:func:`session_to_dict` or
    :func:`session_snapshot`); safe on a worker thread. A link is written through: its
    target is replaced (:func:`session_file`)."""
    path = session_file(path)
    now = file_stamp(path)
    if expect is not None and now is not None and now != expect:
        raise SessionChangedError(
            f"{path.name} changed since it was read here (another window or program saved "
            f"it) and is left as it is; open it again to see that version ({path})")
    text = writer.text(document) if writer is not None else session_text(document)
    aside = None
    try:
        if keep_aside and path.exists():  # copied first: the file is never missing
            aside = free_name(path.with_name(path.name + ".bak"))
            copy_atomically(path, aside)
        atomic_write_text(path, text, keep_backup=backup and not keep_aside)
    except OSError as exc:
        if aside is not None and file_stamp(path) == now:  # not replaced: no copy kept
            aside.unlink(missing_ok=True)
        raise _save_error(path, exc.strerror or str(exc)) from exc
    return aside


def file_stamp(path: str | Path) -> tuple[int, int, int] | None:
    """A file's inode, modification time (ns) and size, to tell later whether it changed
    (an atomic save makes a new file; an edit in place moves the time); None when it is
    not there."""
    try:
        info = Path(path).stat()
    except OSError:
        return None
    return info.st_ino, info.st_mtime_ns, info.st_size


def session_text(document: dict[str, Any]) -> str:
    """``document`` as the session file's text: a line per top-level key, and per item of
    a top-level list or object (a frame set, a set's details, a camera's fit), each line
    compact. A decision changes one line; and json's fast encoder does the work (indented
    output goes through its slow one: 300 ms instead of 40 for a 66-set session, on every
    autosave)."""
    return SessionWriter().text(document)


class SessionWriter:
    """Encodes a session document again and again, as :func:`session_text` does, re-using
    the line of an item that is the very object it encoded last time.

    The bulk of a session file is the sets' frame details (found corners: megabytes with
    many cameras), and a decision or an added set leaves all but one of them as they
    were. This relies on what the review model does: a set's details are replaced by a
    new object, never changed in place.

    Lines of items that left the document are kept a while (:data:`KEEP_SAVES` saves, at
    most :data:`KEEP_CHARS` characters): undoing an offset edit brings back every set's
    details as they were before it, the very objects, whose 4 MB of text (12 cameras,
    100 sets) need not be encoded again.
    """

    #: saves an item's line is kept after it left the document
    KEEP_SAVES = 16
    #: characters of such lines kept at most (the oldest go first)
    KEEP_CHARS = 64_000_000

    def __init__(self) -> None:
        self._lines: dict[int, tuple[object, str]] = {}
        # lines of items not in the last document: id -> (item, line, save it left at)
        self._spare: dict[int, tuple[object, str, int]] = {}
        self._spare_chars = 0
        self._saves = 0

    def text(self, document: dict[str, Any]) -> str:
        """The session file's text for ``document``."""
        before, self._lines = self._lines, {}
        try:
            return self._text(document, before)
        finally:
            self._keep_spare(before)

    def _keep_spare(self, before: dict[int, tuple[object, str]]) -> None:
        """Keep the lines of the items of the last save that this one no longer has."""
        self._saves += 1
        for key, (value, line) in before.items():
            if key not in self._lines and key not in self._spare:
                self._spare[key] = (value, line, self._saves)
                self._spare_chars += len(line)
        # oldest first (insertion order): drop what is too old, then what is too much
        for key, (_value, line, left) in list(self._spare.items()):
            if self._saves - left < self.KEEP_SAVES and self._spare_chars <= self.KEEP_CHARS:
                break
            del self._spare[key]
            self._spare_chars -= len(line)

    def _text(self, document: dict[str, Any], before: dict[int, tuple[object, str]]) -> str:
        lines = []
        for key, value in document.items():
            if isinstance(value, list) and value:
                body = "[\n" + ",\n".join(
                    f"  {self._item(v, before)}" for v in value) + "\n ]"
            elif isinstance(value, dict) and value:
                body = "{\n" + ",\n".join(f"  {_dumps(k)}: {self._item(v, before)}"
                                          for k, v in value.items()) + "\n }"
            else:
                body = _dumps(value)
            lines.append(f" {_dumps(key)}: {body}")
        return "{\n" + ",\n".join(lines) + "\n}\n"

    def _item(self, value: object, before: dict[int, tuple[object, str]]) -> str:
        """One item's compact JSON, from the last call if it is the same object; only
        containers and frame sets (of a :func:`session_snapshot`) are remembered (the
        object is kept, so its id is not re-used)."""
        if not isinstance(value, dict | list | FrameSet):
            return _dumps(value)
        known = before.get(id(value))
        spare = self._spare.get(id(value)) if known is None else None
        if known is not None and known[0] is value:
            line = known[1]
        elif spare is not None and spare[0] is value:  # back (an undo)
            line = spare[1]
            del self._spare[id(value)]
            self._spare_chars -= len(line)
        else:
            line = _dumps(value.to_dict() if isinstance(value, FrameSet) else value)
        self._lines[id(value)] = (value, line)
        return line


def _dumps(value: object) -> str:
    return json.dumps(value, ensure_ascii=False)


def check_session_target(path: str | Path) -> None:
    """Raise SessionFileError now if a session cannot be saved at ``path`` (its folder is
    missing or not writable), before any long work that would end in saving it."""
    path = session_file(path)
    problem = folder_write_problem(path.absolute().parent)
    if problem:
        raise _save_error(path, problem)


def _save_error(path: Path, reason: str) -> SessionFileError:
    """The operator's message for a session that cannot be written, for ``reason``."""
    folder = path.absolute().parent
    if not folder.is_dir():  # missing, or a file: say which
        return SessionFileError(f"{path}: cannot save the session: "
                                f"{folder_write_problem(folder)}; choose another path")
    if reason in (os.strerror(errno.EACCES), os.strerror(errno.EPERM),
                  os.strerror(errno.EROFS)):
        todo = "choose a folder you can write to (or make this one writable)"
    elif reason in (os.strerror(errno.ENOSPC), os.strerror(errno.EDQUOT)):
        todo = "free disk space or choose a folder on another disk"
    else:
        todo = "free disk space or choose a writable folder"
    return SessionFileError(f"{path}: cannot save the session ({reason}); {todo}")


def check_recording_present(session: Session, session_path: str | Path) -> None:
    """SessionFileError when a file of the session's recording is missing, saying how to
    point the session at where it went without losing the review decisions."""
    for p in session.recording:
        if not Path(p).exists():
            raise SessionFileError(
                f"{session_path}: its recording {os.path.normpath(p)} is missing; put it "
                f"back there, or open "
                f"it where it is now with this session to keep the review decisions "
                f"(speechcal review RECORDING --audio AUDIO --session "
                f"{shell_quoted(session_path)})")


def load_session(path: str | Path) -> Session:
    """Read a session file; older schemas are migrated, newer ones refused. A symbolic
    link is read as its target, relative paths from the target's folder
    (:func:`session_file`)."""
    path = session_file(path)
    text = ""
    try:
        text = path.read_text(encoding="utf-8-sig")  # an editor's BOM is fine
        data = json.loads(text)
    except FileNotFoundError:
        bak = _backup(path)
        raise SessionFileError(
            f"{path}: no such session file; "
            + (f"its previous version is in {bak.name}: rename it to {path.name} to open it"
               if bak else "check the path")) from None
    except UnicodeDecodeError:
        raise SessionFileError(
            f"{path}: not a session file (not JSON text); a session file is what 'speechcal "
            f"process' writes, a recording opens with its audio (speechcal review RECORDING "
            f"--audio AUDIO)") from None
    except IsADirectoryError:
        raise SessionFileError(f"{path}: a folder, not a session file; give the session's "
                               f".json file") from None
    except OSError as exc:
        raise SessionFileError(f"{path}: cannot read the session file ({exc})") from exc
    except json.JSONDecodeError as exc:
        if not text.lstrip().startswith("{"):  # another kind of file (a YAML, a CSV)
            raise SessionFileError(
                f"{path}: not a session file (not JSON); a session file is what 'speechcal "
                f"process' writes") from None
        raise SessionFileError(f"{path}: not valid JSON (line {exc.lineno}), the file is "
                               f"damaged{_way_back(path)}") from exc
    except RecursionError:
        raise SessionFileError(f"{path}: not a session file (its JSON nests too deeply)"
                               ) from None
    if not isinstance(data, dict) or "schema" not in data:
        raise SessionFileError(f"{path}: not a SpeechCal session file (no 'schema' key)")
    schema = data["schema"]
    if not isinstance(schema, int) or isinstance(schema, bool) or schema < 1:
        raise SessionFileError(f"{path}: damaged session file ('schema' is {schema!r}, not "
                               f"a schema number from 1 to {SCHEMA}){_way_back(path)}")
    if schema > SCHEMA:
        raise SessionFileError(
            f"{path}: written by a newer SpeechCal (schema {schema}, this version reads up to "
            f"{SCHEMA}); update SpeechCal to open it"
        )
    data = _migrate(data)
    _check_session_shape(path, data)
    base = path.absolute().parent
    try:
        _check_set_ids(data["sets"])
        _check_streams(data.get(STREAMS_KEY))
        _check_coverage(data.get("coverage"))
        _check_calibration(data.get("calibration"))
        known = {"schema", "recording", "audio", "audio_channel", "trigger_words", "sync",
                 "sets", "last_set_id", "calibration"}
        sets = [_frame_set(path, k, s) for k, s in enumerate(data["sets"])]
        _check_frames_in_streams(data.get(STREAMS_KEY), sets)
        return Session(
            recording=[_absolute(p, base) for p in data["recording"]],
            audio=_absolute(data["audio"], base) if data.get("audio") else None,
            audio_channel=_channel(data.get("audio_channel")),
            sync=SyncModel.from_dict(data["sync"]),
            sync_evidence=_with_audio_path(
                {k: v for k, v in data["sync"].items()
                 if k not in ("offset_ns", "drift", "source")},
                lambda a: _absolute(a, base)),
            sets=sets,
            triggers_word=_trigger_words(data.get("trigger_words", ["capture"])),
            calibration=dict(data.get("calibration", {})),
            extra={k: v for k, v in data.items() if k not in known},
            last_set_id=_last_set_id(data.get("last_set_id"), sets),
        )
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise SessionFileError(f"{path}: damaged session file ({_reason(exc)})"
                               f"{_way_back(path)}") from exc


def _way_back(path: Path) -> str:
    """How to get a usable session back: its previous version, or processing anew."""
    bak = _backup(path)
    if bak:
        return f"; the previous version is in {bak.name}"
    return "; restore it from a copy, or process the recording again (speechcal process)"


def _check_set_ids(sets: list[Any]) -> None:
    """ValueError naming a set id found twice (every set is found by its id)."""
    seen: set[Any] = set()
    for s in sets:
        set_id = s.get("id") if isinstance(s, dict) else None
        if set_id is not None and set_id in seen:
            raise ValueError(f"set id {set_id} appears twice")
        seen.add(set_id)


def _last_set_id(value: Any, sets: list[FrameSet]) -> int:
    """The highest set number the session gave (``last_set_id``; a file written before
    the key: its highest set's); ValueError when it is no set number."""
    if value is not None and not (isinstance(value, int) and not isinstance(value, bool)
                                  and value >= 0):
        raise ValueError(f"'last_set_id' is {value!r:.40}, not a set number; deleting the "
                         "key is a fix too (new sets are then numbered after the highest)")
    return max(value or 0, max((s.id for s in sets), default=0))


def _check_streams(value: Any) -> None:
    """ValueError unless ``value`` (the session's streams) is absent or stream names."""
    if value is not None and not (isinstance(value, list) and value
                                  and all(isinstance(v, str) and v for v in value)):
        raise ValueError(f"'{STREAMS_KEY}' is {value!r}, not a list of stream names")


def _check_frames_in_streams(streams: list[str] | None, sets: list[FrameSet]) -> None:
    """ValueError naming a set that shows a stream the session's ``streams`` leave out (a
    hand edit): its camera was said to be missing from the recording."""
    if streams is None:
        return
    for frame_set in sets:
        for frame in frame_set.frames:
            if frame.stream not in streams:
                raise ValueError(
                    f"set {frame_set.id} shows {frame.stream}, which '{STREAMS_KEY}' leaves "
                    "out; put it back in the list, and leave a camera out with speechcal "
                    f"review SESSION.json --skip-stream {frame.stream} (its frames go too)")


def _trigger_words(value: Any) -> list[str]:
    """The session's trigger words; one word written by hand is a list of one (taken
    as a list, "snapshot" was the words "s", "n", ...); ValueError unless words."""
    if isinstance(value, str) and value.strip():
        return [value.strip()]
    if not (isinstance(value, list) and all(isinstance(v, str) and v.strip() for v in value)):
        raise ValueError(f"'trigger_words' is {value!r:.40}, not a list of words, e.g. "
                         '["capture"]')
    return [v.strip() for v in value]


def _derived_fix(key: str) -> str:
    """What to tell of a damaged derived key: deleting it is a fix too."""
    return f"; deleting the '{key}' key is a fix too: the next calibration check writes it"


def _camera_entries(value: Any, key: str, whole: str, each: str
                    ) -> list[tuple[str, dict[str, Any]]]:
    """The cameras' entries of a derived per-camera key (``coverage``, ``calibration``):
    ValueError unless ``value`` is absent or a dict whose entries are dicts or null
    (``whole`` and ``each`` say what they should be)."""
    if value is None:
        return []
    if not isinstance(value, dict):
        raise ValueError(f"'{key}' is {value!r}, not {whole}{_derived_fix(key)}")
    entries = []
    for stream, entry in value.items():
        if entry is not None and not isinstance(entry, dict):
            raise ValueError(f"the {key} of {stream} is {entry!r}, not {each}"
                             f"{_derived_fix(key)}")
        if entry is not None:
            entries.append((stream, entry))
    return entries


def _is_number(value: Any) -> bool:
    """Whether ``value`` is a JSON number (not a bool, which Python counts as one)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check_coverage(value: Any) -> None:
    """ValueError naming a damaged ``coverage`` entry (a hand edit), as a set's damaged
    quality figure is named: the window's calibration line reads each camera's views and
    progress as numbers. The key is derived, so deleting it is a fix too: the next
    calibration check writes it again."""
    fix = _derived_fix("coverage")
    for stream, entry in _camera_entries(value, "coverage", "the cameras' coverage",
                                         "its views and progress"):
        views = entry.get("views")
        if views is not None and not (isinstance(views, int) and _is_number(views)
                                      and views >= 0):
            raise ValueError(f"the coverage of {stream}: its views is {views!r}, not a "
                             f"count{fix}")
        progress = entry.get("progress")
        if progress is not None and not isinstance(progress, dict):
            raise ValueError(f"the coverage of {stream}: its progress is {progress!r}, not "
                             f"x, y, size and skew{fix}")
        for name, figure in (progress or {}).items():
            if not _is_number(figure):
                raise ValueError(f"the coverage of {stream}: its progress {name} is "
                                 f"{figure!r}, not a number{fix}")


def _check_calibration(value: Any) -> None:
    """ValueError naming a damaged ``calibration`` entry (a hand edit), as a damaged
    ``coverage`` is named: the window's calibration line reads each camera's RMS as a number
    and counts its views. Derived too: deleting the key is a fix."""
    fix = _derived_fix("calibration")
    for stream, entry in _camera_entries(value, "calibration", "the cameras' fitted models",
                                         "its fitted model"):
        rms = entry.get("rms_px")
        if rms is not None and not _is_number(rms):
            raise ValueError(f"the calibration of {stream}: its rms_px is {rms!r}, not a "
                             f"number{fix}")
        views = entry.get("views")
        if views is not None and not isinstance(views, list):
            raise ValueError(f"the calibration of {stream}: its views is {views!r}, not a "
                             f"list{fix}")


def _channel(value: Any) -> int | None:
    """The stored audio channel (None: all channels mixed); ValueError when it is none."""
    if value is None:
        return None
    if not isinstance(value, int) or isinstance(value, bool) or value < 0:
        raise ValueError(f"'audio_channel' is {value!r}, not a channel number from 0")
    return value


def _frame_set(path: Path, k: int, data: Any) -> FrameSet:
    """Set ``k`` (0-based) of the file, or SessionFileError naming it and what is wrong."""
    try:
        return FrameSet.from_dict(data)
    except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
        name = f"set {data['id']}" if isinstance(data, dict) and "id" in data else \
            f"set number {k + 1} in the list"
        bak = _backup(path)
        back = f" or go back to {bak.name}" if bak else ""
        raise SessionFileError(f"{path}: damaged session file: {name}: {_reason(exc)}; fix "
                               f"it{back}") from exc


def _backup(path: Path) -> Path | None:
    """The previous version :func:`save_session` kept beside ``path``, if there is one."""
    bak = path.with_name(path.name + ".bak")
    return bak if bak.exists() else None


def _reason(exc: Exception) -> str:
    """What a parsing error says, in words: a missing key is named as such."""
    if isinstance(exc, KeyError):
        return f"the key {exc.args[0]!r} is missing"
    if isinstance(exc, (TypeError, AttributeError)):
        return f"a value of the wrong kind ({exc})"
    return str(exc)


def _check_session_shape(path: Path, data: dict[str, Any]) -> None:
    """Refuse JSON that is not a session although it has a schema (a synthetic session's
    ``truth.json``, another tool's file): opening it would autosave a session over it.
    A session (a recording list and a sync entry) whose ``sets`` is missing or no list
    is refused as damaged, naming the key."""
    if "sets" not in data and "options" in data and "triggers" in data:
        raise SessionFileError(
            f"{path}: the truth file of a synthetic session, not a review session; open its "
            f"recording with its audio instead (speechcal review RECORDING --audio AUDIO)")
    recording = data.get("recording")
    if not (isinstance(recording, list) and recording
            and all(isinstance(p, str) for p in recording)
            and isinstance(data.get("sync"), dict)):
        raise SessionFileError(
            f"{path}: not a SpeechCal session file (it lacks a recording list or a sync "
            f"entry); a session file is what 'speechcal process' writes")
    # a session's recording and sync without its list of sets is a damaged session, not
    # an empty one: opened as empty, the next autosave would write that over the file
    if "sets" not in data:
        reason = "the key 'sets' is missing"
    elif not isinstance(data["sets"], list):
        reason = f"'sets' is {data['sets']!r:.60}, not a list of frame sets"
    else:
        return
    raise SessionFileError(f"{path}: damaged session file ({reason}){_way_back(path)}")


def _migrate(data: dict[str, Any]) -> dict[str, Any]:
    """Bring an older schema up to :data:`SCHEMA` (schema 1 is the first)."""
    if isinstance(data.get("recording"), str):
        data["recording"] = [data["recording"]]
    return data


def _with_audio_path(evidence: dict[str, Any], convert: Callable[[str], str]
                     ) -> dict[str, Any]:
    """``evidence`` with the path of the sync's audio (``sync.audio.path``) converted."""
    audio = evidence.get("audio")
    if not isinstance(audio, dict) or not isinstance(audio.get("path"), str):
        return evidence
    return {**evidence, "audio": {**audio, "path": convert(audio["path"])}}


def _absolute(stored: str, base: Path) -> str:
    """A stored path (relative to the session file's folder ``base``) as a plain absolute
    one: "reviews/../rec" is "rec", as ``_relative`` made it from (both work on the
    names alone, not on where links lead)."""
    return str(plain_absolute(base / stored))


def _relative(path: str, base: Path) -> str:
    try:
        return Path(os.path.relpath(Path(path).absolute(), base)).as_posix()
    except ValueError:  # another drive on Windows
        return Path(path).absolute().as_posix()
