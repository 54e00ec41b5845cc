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

    gone = set(names)
    extra = session.extra
    checks_current = extra.get("checks_basis") == checks_basis(session.sets)
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
    # checks made before a decision they wait for (still due) stay due
    extra[STREAMS_KEY] = list(kept)
