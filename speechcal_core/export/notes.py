"""What a user should know before calibrating on an export (``ExportResult.notes``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from collections.abc import Sequence

    from speechcal_core.export.plan import Plan
    from speechcal_core.session.model import FrameSet, Session

#: kalibr_calibrate_cameras pairs the cameras' images no further apart than this by
#: default (its --approx-sync, seconds)
KALIBR_APPROX_SYNC_S = 0.02


def export_notes(fmt: str, session: Session, plan: Plan, spec: TargetSpec,
                 target_from: str) -> list[str]:
    """The export's notes (:attr:`ExportResult.notes`) for format ``fmt``."""
    if fmt == "kalibr":
        note = target_note(session, spec, target_from)
    elif fmt in ("rosbag1", "rosbag2"):
        note = approx_sync_note(plan.sets)
    else:
        note = ""
    return [note] if note else []


def approx_sync_note(sets: Sequence[FrameSet]) -> str:
    """A hint when the frames of one of ``sets`` lie further apart in time than Kalibr's
    default ``--approx-sync`` (KALIBR_APPROX_SYNC_S) pairs: each camera's best still
    frame is chosen on its own, and cameras are rarely triggered together. "" if not."""
    spread_s = max((s.skew_ns for s in sets), default=0) / 1e9
    if spread_s <= KALIBR_APPROX_SYNC_S:
        return ""
    tolerance = math.ceil(spread_s * 100) / 100
    return (f"the frames of one set lie up to {spread_s * 1e3:.1f} ms apart (each camera's "
            f"stillest frame): run kalibr_calibrate_cameras with --approx-sync "
            f"{tolerance:g} (its default {KALIBR_APPROX_SYNC_S:g} s would drop sets), or "
            "export --format kalibr, which names each set's frames alike")


def target_note(session: Session, spec: TargetSpec, target_from: str) -> str:
    """What to tell the user about the ``target.yaml`` describing ``spec``: that it is
    an assumption, or that it is not the board the session's frames were checked
    against (their corner counts are for that one); "" when neither."""
    if target_from == "default":
        return (f"target.yaml describes the assumed {spec.describe()} (the session "
                "was processed without --target): if your board differs, export again "
                "with --target TARGET.yaml; a wrong tag size scales everything Kalibr "
                "measures")
    stored = TargetSpec.from_stored(session.extra.get("target"))
    if target_from != "given" or stored is None or \
            (stored.kind, stored.rows, stored.cols) == (spec.kind, spec.rows, spec.cols):
        return ""
    checked = ("assumed " if session.extra.get("target_assumed") else "") + \
        stored.describe()
    return (f"target.yaml describes the given {spec.describe()}, but the session's frames "
            f"were checked against the {checked}: the manifest's corner counts are for "
            "that board; process the recording again with this --target to check the "
            "frames against it")
