"""Leave streams out of a session already made, keeping its review work."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from speechcal_core.session.model import STREAMS_KEY, Session

#: keys of ``Session.extra`` holding one entry per stream
PER_STREAM_KEYS = ("coverage",)
#: keys of ``Session.extra`` holding a mapping per stream under each of their entries
NESTED_PER_STREAM_KEYS = ("frame_references",)
#: entries of each set's ``frame_details`` record keyed by stream
DETAIL_PER_STREAM_KEYS = ("nearest", "frames")


def leave_out_streams(session: Session, names: Sequence[str], kept: Sequence[str]) -> None:
    """Take the streams ``names`` out of ``session``: their frames from every set, their
    calibration, coverage and frame records; the session then uses ``kept``. Decisions and
    the choice of each set's moment stay as they are."""
    from speechcal_core.frames.analysis import checks_basis
    from speechcal_core.review.undo_history import UNDO_HISTORY_KEY, history_fingerprint

    gone = set(names)
    extra = session.extra
    checks_current = extra.get("checks_basis") == checks_basis(session.sets)
    history = extra.get(UNDO_HISTORY_KEY)
    history_current = isinstance(history, dict) \
        and history.get("matches") == history_fingerprint(session)
    session.sets = [replace(s, frames=tuple(f for f in s.frames if f.stream not in gone))
                    for s in session.sets]
    for name in gone:
        session.calibration.pop(name, None)
    for key in PER_STREAM_KEYS:
        if isinstance(extra.get(key), dict):
            extra[key] = {k: v for k, v in extra[key].items() if k not in gone}
    for key in NESTED_PER_STREAM_KEYS:
        if isinstance(extra.get(key), dict):
            extra[key] = {k: ({s: x for s, x in v.items() if s not in gone}
                              if isinstance(v, dict) else v) for k, v in extra[key].items()}
    for detail in (extra.get("frame_details") or {}).values():
        for key in DETAIL_PER_STREAM_KEYS:
            if isinstance(detail, dict) and isinstance(detail.get(key), dict):
                detail[key] = {s: x for s, x in detail[key].items() if s not in gone}
    if checks_current:  # the other cameras' checks stand as they were
        extra["checks_basis"] = checks_basis(session.sets)
    if history_current:  # the review's undo steps go on with the cameras kept
        extra[UNDO_HISTORY_KEY] = {**_history_without(history, gone),
                                   "matches": history_fingerprint(session)}
    # checks made before a decision they wait for (still due) stay due
    extra[STREAMS_KEY] = list(kept)


def _history_without(history: dict, gone: set[str]) -> dict:
    """The ``undo_history`` entry with the streams ``gone`` taken out of the sets its
    steps put back (their frames and frame details), as out of the session's sets: taking
    a removal back then gives a set of the cameras kept. Anything not shaped as written
    is left as it is (reading it back drops it as damaged)."""

    def removed_set(data: object) -> object:
        if not isinstance(data, dict) or not isinstance(data.get("frames"), list):
            return data
        return {**data, "frames": [f for f in data["frames"]
                                   if not (isinstance(f, dict) and f.get("stream") in gone)]}

    def details(data: object) -> object:
        if not isinstance(data, dict):
            return data
        return {k: ({s: x for s, x in v.items() if s not in gone}
                    if k in DETAIL_PER_STREAM_KEYS and isinstance(v, dict) else v)
                for k, v in data.items()}

    def step(data: object) -> object:
        if not isinstance(data, dict):
            return data
        if data.get("step") == "removed":
            return {**data, "set": removed_set(data.get("set")),
                    "details": details(data.get("details"))}
        if data.get("step") == "removed_many" and isinstance(data.get("items"), list):
            return {**data, "items": [
                [removed_set(item[0]), item[1], details(item[2])]
                if isinstance(item, list) and len(item) == 3 else item
                for item in data["items"]]}
        return data

    return {k: ([step(d) for d in v] if k in ("undo", "redo") and isinstance(v, list) else v)
            for k, v in history.items()}
