"""The review's undo and redo steps kept in the session file, so that Ctrl+Z still takes
back the last review's steps after the session is closed and opened again.

They are one top-level key of the session file, ``"undo_history"`` (DESIGN.md §3: keys
the loader does not know are kept as they are, so the schema stays 1 and older
SpeechCal versions still open the file), written by the review model with every
autosave, in the same atomic write as the sets they belong to::

    "undo_history": {"version": 1, "matches": "<sha256>", "undo": [step, ...],
                     "redo": [step, ...]}

``matches`` is a fingerprint of what the steps act on: the sync and, per set, its id,
time, decision, trigger and cameras (:func:`history_fingerprint`). A file whose sets or
offset changed since the steps were saved (edited by hand, processed again, cameras left
out by an older SpeechCal, or saved by a SpeechCal that kept the key without knowing it)
no longer matches: its steps are dropped with a note (:func:`read_history`), never
applied to other sets. Cameras left out here carry the steps along
(:func:`speechcal_core.session.streams.leave_out_streams`).
A set re-scored meanwhile (``speechcal export``) still matches: no step refers to a
set's frames, it only puts back frames it holds itself.

Bounded: the newest :data:`MAX_STEPS` steps of each stack within :data:`MAX_CHARS`
characters. An offset edit is kept as its sync and claps only (its undo re-scores the
sets), a removed set's frame details only while they fit (without them it comes back
to be re-scored).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from speechcal_core.review.undo_steps import (
    Added,
    AddedMany,
    Decided,
    EarlierOffsetChange,
    OffsetChanged,
    Removed,
    RemovedMany,
    UndoStep,
)
from speechcal_core.session.model import DECISIONS, FrameSet
from speechcal_core.sync.model import SyncModel

if TYPE_CHECKING:
    from speechcal_core.review.undo_steps import SettingsSwap
    from speechcal_core.session.model import Session

#: key of ``Session.extra`` (top-level in the file) holding the undo and redo steps
UNDO_HISTORY_KEY = "undo_history"
#: the layout of the steps written; a history of a later one is dropped, not guessed at
HISTORY_VERSION = 1
#: steps kept per stack (the newest)
MAX_STEPS = 200
#: characters the steps of both stacks take at most in the file (the undo stack's
#: newest first, then the redo stack's)
MAX_CHARS = 1_000_000

#: what the window says when the steps saved with a session are not taken back in
DROPPED = "the last review's undo steps were dropped: {why}; the decisions are kept"
NOT_MATCHING = ("the frame sets or the audio offset changed since they were saved (edited "
                "by hand, processed again or cameras left out)")
NEWER = "a newer SpeechCal wrote them"
DAMAGED = "they are damaged in the file"


class HistoryError(ValueError):
    """Undo steps read from a session file that cannot be taken back in."""


def history_fingerprint(session: Session, lines: dict[int, tuple[FrameSet, bytes]] | None = None
                        ) -> str:
    """What the undo steps act on, as a hash: the sync's offset and drift and, per set in
    order, its id, time, decision, trigger and cameras. ``lines`` caches each set's part
    by the set object (sets are immutable: a changed set is another object)."""
    digest = hashlib.sha256(_dumps([session.sync.offset_ns, session.sync.drift]).encode())
    for frame_set in session.sets:
        known = lines.get(id(frame_set)) if lines is not None else None
        if known is not None and known[0] is frame_set:
            line = known[1]
        else:
            line = _dumps([frame_set.id, frame_set.t_ns, frame_set.decision,
                           frame_set.trigger.to_dict(),
                           [f.stream for f in frame_set.frames]]).encode()
            if lines is not None:
                lines[id(frame_set)] = (frame_set, line)
        digest.update(b"\n" + line)
    return digest.hexdigest()


class HistoryWriter:
    """Makes the ``undo_history`` entry again and again, each step encoded once (steps
    are immutable) and each set's part of the fingerprint worked out once."""

    def __init__(self) -> None:
        # id(step) -> (step, (encoded, its length), without details or None)
        self._steps: dict[int, tuple[UndoStep, tuple[dict, int],
                                     tuple[dict, int] | None]] = {}
        self._lines: dict[int, tuple[FrameSet, bytes]] = {}
        # the stacks' lists last given, re-used while they hold the same encodings: the
        # session writer then re-uses their text
        self._last: dict[str, tuple[list[int], list[dict]]] = {}

    def entry(self, undo: list[UndoStep], redo: list[UndoStep], session: Session
              ) -> dict[str, Any] | None:
        """The ``undo_history`` entry for the stacks (None when both are empty): a new
        object, the lists in it new unless they are as last time."""
        if not undo and not redo:
            self._steps.clear()
            self._lines.clear()
            return None
        room = MAX_CHARS
        kept: dict[str, list[dict]] = {}
        for name, stack in (("undo", undo), ("redo", redo)):
            out: list[dict] = []
            for step in reversed(stack[-MAX_STEPS:]):  # the newest first
                full, lean = self._encoded(step)
                fits = full if full[1] <= room else lean if lean and lean[1] <= room else None
                if fits is None:
                    room = 0  # an older step without a newer one would undo out of order
                    break
                out.append(fits[0])
                room -= fits[1]
            out.reverse()
            kept[name] = self._same_list(name, out)
        live = {id(s) for s in (*undo, *redo)}
        self._steps = {k: v for k, v in self._steps.items() if k in live}
        live_sets = {id(s) for s in session.sets}
        self._lines = {k: v for k, v in self._lines.items() if k in live_sets}
        return {"version": HISTORY_VERSION,
                "matches": history_fingerprint(session, self._lines),
                "undo": kept["undo"], "redo": kept["redo"]}

    def _encoded(self, step: UndoStep) -> tuple[tuple[dict, int], tuple[dict, int] | None]:
        known = self._steps.get(id(step))
        if known is not None and known[0] is step:
            return known[1], known[2]
        full = encode_step(step)
        lean_step = encode_step(step, details=False)
        sized = (full, len(_dumps(full)))
        lean = (lean_step, len(_dumps(lean_step))) if lean_step != full else None
        self._steps[id(step)] = (step, sized, lean)
        return sized, lean

    def _same_list(self, name: str, items: list[dict]) -> list[dict]:
        """``items``, or the list given last time for this stack when it holds the very
        same encodings."""
        ids = [id(d) for d in items]
        last = self._last.get(name)
        if last is not None and last[0] == ids:
            return last[1]
        self._last[name] = (ids, items)
        return items


def encode_step(step: UndoStep, details: bool = True) -> dict[str, Any]:
    """A step as JSON-ready data; a removed set's frame details left out unless
    ``details``. An offset edit keeps its sync and claps only."""
    if isinstance(step, Decided):
        return {"step": "decided", "set": step.set_id, "previous": step.previous}
    if isinstance(step, OffsetChanged | EarlierOffsetChange):
        if isinstance(step, OffsetChanged):
            evidence = step.evidence if isinstance(step.evidence, dict) else {}
            claps = evidence.get("claps")
        else:
            claps = step.claps
        return {"step": "offset", "sync": step.sync.to_dict(),
                "claps": list(claps) if isinstance(claps, list | tuple) else None}
    if isinstance(step, Added):
        return {"step": "added", "set": step.set_id}
    if isinstance(step, Removed):
        return {"step": "removed", "set": step.frame_set.to_dict(), "index": step.index,
                "details": step.details if details else None}
    if isinstance(step, AddedMany):
        return {"step": "added_many", "sets": list(step.set_ids),
                "settings": _settings_data(step.settings)}
    return {"step": "removed_many",
            "items": [[s.to_dict(), i, d if details else None] for s, i, d in step.items],
            "settings": _settings_data(step.settings)}


def _settings_data(settings: SettingsSwap | None) -> list | None:
    if settings is None:
        return None
    return [[list(words), level, prons] for words, level, prons in settings]


@dataclass(frozen=True)
class ReadHistory:
    """The stacks read back from a session file, and why none were ("" when they were,
    or when it kept none)."""

    undo: list[UndoStep]
    redo: list[UndoStep]
    note: str = ""


def read_history(stored: object, session: Session) -> ReadHistory:
    """The undo and redo steps kept under :data:`UNDO_HISTORY_KEY` for ``session`` as it
    was read (before anything moved its sets). Steps that do not fit it (another
    version, another fingerprint, damaged, or naming sets it has not or has already) are
    all dropped, with a note saying why: never applied to other sets, nor some of them."""
    if stored is None:
        return ReadHistory([], [])
    try:
        if not isinstance(stored, dict):
            raise HistoryError("not an object")
        version = stored.get("version")
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise HistoryError(f"version {version!r}")
        if version > HISTORY_VERSION:
            return ReadHistory([], [], DROPPED.format(why=NEWER))
        if stored.get("matches") != history_fingerprint(session):
            return ReadHistory([], [], DROPPED.format(why=NOT_MATCHING))
        undo = [decode_step(d) for d in _list(stored.get("undo", []))]
        redo = [decode_step(d) for d in _list(stored.get("redo", []))]
        ids = [s.id for s in session.sets]
        _check_fits(undo, ids)
        _check_fits(redo, ids)
    except (HistoryError, KeyError, TypeError, ValueError, AttributeError,
            OverflowError) as exc:
        return ReadHistory([], [], DROPPED.format(why=f"{DAMAGED} ({_reason(exc)})"))
    return ReadHistory(undo, redo)


def decode_step(data: object) -> UndoStep:
    """Inverse of :func:`encode_step` (an offset edit comes back as an
    :class:`EarlierOffsetChange`); HistoryError, KeyError, TypeError or ValueError for
    anything else."""
    if not isinstance(data, dict):
        raise HistoryError(f"a step is {data!r}")
    kind = data.get("step")
    if kind == "decided":
        previous = data["previous"]
        if previous not in DECISIONS:
            raise HistoryError(f"a decision {previous!r}")
        return Decided(_id(data["set"]), previous)
    if kind == "offset":
        claps = data.get("claps")
        if claps is not None and not all(isinstance(c, dict) for c in _list(claps)):
            raise HistoryError(f"claps {claps!r}")
        return EarlierOffsetChange(SyncModel.from_dict(_dict(data["sync"])),
                                   tuple(claps) if claps is not None else None)
    if kind == "added":
        return Added(_id(data["set"]))
    if kind == "removed":
        return Removed(FrameSet.from_dict(_dict(data["set"])), _index(data["index"]),
                       _details(data.get("details")))
    if kind == "added_many":
        return AddedMany(tuple(_id(i) for i in _list(data["sets"])),
                         _settings(data.get("settings")))
    if kind == "removed_many":
        items = []
        for item in _list(data["items"]):
            frame_set, index, details = _list(item)
            items.append((FrameSet.from_dict(_dict(frame_set)), _index(index),
                          _details(details)))
        return RemovedMany(tuple(items), _settings(data.get("settings")))
    raise HistoryError(f"a step of kind {kind!r}")


def _check_fits(stack: list[UndoStep], ids: list[int]) -> None:
    """HistoryError unless every step of ``stack``, taken back from the top with the
    sets ``ids`` in, finds the sets it takes back and none it puts back."""
    present = set(ids)
    for step in reversed(stack):
        if isinstance(step, Decided):
            _need(present, [step.set_id], True)
        elif isinstance(step, Added | AddedMany):
            gone = [step.set_id] if isinstance(step, Added) else list(step.set_ids)
            _need(present, gone, True)
            present -= set(gone)
        elif isinstance(step, Removed | RemovedMany):
            back = [step.frame_set.id] if isinstance(step, Removed) \
                else [s.id for s, _i, _d in step.items]
            _need(present, back, False)
            if len(set(back)) != len(back):
                raise HistoryError(f"set {back} put back twice")
            present |= set(back)


def _need(present: set[int], ids: list[int], there: bool) -> None:
    for set_id in ids:
        if (set_id in present) != there:
            raise HistoryError(f"a step on set {set_id}, which is "
                               f"{'not ' if there else ''}in the session")


def _settings(data: object) -> SettingsSwap | None:
    if data is None:
        return None
    pair = []
    for words, level, prons in _list(data):
        if not all(isinstance(w, str) for w in _list(words)):
            raise HistoryError(f"trigger words {words!r}")
        if level is not None and (isinstance(level, bool)
                                  or not isinstance(level, int | float)):
            raise HistoryError(f"a sensitivity {level!r}")
        if prons is not None and not isinstance(prons, dict):
            raise HistoryError(f"pronunciations {prons!r}")
        pair.append((list(words), level, prons))
    before, after = pair
    return before, after


def _id(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise HistoryError(f"a set id {value!r}")
    return value


def _index(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise HistoryError(f"a place in the list {value!r}")
    return value


def _details(value: object) -> object:
    if value is not None and not isinstance(value, dict):
        raise HistoryError(f"frame details {value!r}")
    return value


def _list(value: object) -> list:
    if not isinstance(value, list):
        raise HistoryError(f"{value!r} is not a list")
    return value


def _dict(value: object) -> dict:
    if not isinstance(value, dict):
        raise HistoryError(f"{value!r} is not an object")
    return value


def _reason(exc: Exception) -> str:
    if isinstance(exc, KeyError):
        return f"the key {exc.args[0]!r} is missing"
    text = str(exc)
    return text if len(text) <= 80 else text[:77] + "…"


def _dumps(value: object) -> str:
    return json.dumps(value, ensure_ascii=False)
