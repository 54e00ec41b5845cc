"""Leaving a camera out keeps the other cameras' checks, current or due as they were."""

from __future__ import annotations

from speechcal_core.frames.analysis import checks_basis
from speechcal_core.review.checks import checks_due
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
from speechcal_core.session.streams import leave_out_streams
from speechcal_core.sync.model import SyncModel

CAMS = ("/cam0", "/cam1", "/cam2")


def _session() -> Session:
    sets = [FrameSet(k, k * 10**9, Trigger("capture", k, k + 0.4),
                     tuple(FrameChoice(c, 10 * k, k * 10**9) for c in CAMS))
            for k in range(1, 4)]
    details = {str(s.id): {"frames": {c: {} for c in CAMS}} for s in sets}  # scored
    session = Session(["rec.bag"], "mic.ogg", SyncModel(0), sets,
                      extra={"frame_details": details})
    session.extra["checks_basis"] = checks_basis(session.sets)
    return session


def test_checks_current_before_stay_current_for_the_cameras_left() -> None:
    session = _session()
    leave_out_streams(session, ["/cam2"], CAMS[:2])
    assert not checks_due(session)


def test_checks_due_before_stay_due() -> None:
    """A set rejected while the checks were updating, then a camera left out: the old
    checks (with the rejected set's views) were stored as current."""
    session = _session()
    session.sets[0] = session.sets[0].with_decision("rejected")
    assert checks_due(session)
    leave_out_streams(session, ["/cam2"], CAMS[:2])
    assert checks_due(session)
