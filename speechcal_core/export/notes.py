"""What a user should know before calibrating on an export (``ExportResult.notes``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from speechcal_core.export.corners import corners_problem
from speechcal_core.export.earlier import TARGET_FORMATS
from speechcal_core.export.kalibr import kalibr_camera
from speechcal_core.target import TargetSpec
from speechcal_core.text import listed

if TYPE_CHECKING:
    from collections.abc import Sequence

    from speechcal_core.export.plan import Plan
    from speechcal_core.session.model import FrameSet, Session

#: kalibr_calibrate_cameras pairs the cameras' images no further apart than this by
#: default (its --approx-sync, 0.02 s)
KALIBR_APPROX_SYNC_NS = 20_000_000


def export_notes(fmt: str, session: Session, plan: Plan, spec: TargetSpec,
                 target_from: str) -> list[str]:
    """The export's notes (:attr:`ExportResult.notes`) for format ``fmt``."""
    notes = [left_out_note(fmt, plan)]
    if fmt in TARGET_FORMATS:
        notes.append(target_note(session, spec, target_from))
    if fmt in ("kalibr", "folders"):
        no_corners = corners_problem(session)
        notes.append(no_corners)
        if fmt == "folders" and not no_corners:
            notes.append(assumed_board_note(
                session, spec, target_from, "corners.json and corners.vnl place the corners on"))
        if not no_corners:
            notes.append(other_board_note(session, spec, target_from))
    if fmt in ("rosbag1", "rosbag2"):
        notes.append(approx_sync_note(plan.sets))
    return [note for note in notes if note]


def other_board_note(session: Session, spec: TargetSpec, target_from: str) -> str:
    """That the corners files keep the board the session's frames were checked against,
    when the given ``spec`` lays out another ("" when it does not)."""
    checked = _checked_board_unlike(session, spec, target_from)
    if not checked:
        return ""
    return (f"corners.json and corners.vnl place the corners on the {checked} the "
            f"session's frames were checked against, not on the given {spec.describe()}: "
            "process the recording again with this --target to find its corners")


def _checked_board_unlike(session: Session, spec: TargetSpec, target_from: str) -> str:
    """The board the session's frames were checked against, described ("assumed 6x6
    AprilGrid …"), when a given ``spec`` lays out another; "" otherwise."""
    stored, assumed = TargetSpec.from_session(session.extra)
    if target_from != "given" or stored is None or \
            (stored.kind, stored.rows, stored.cols) == (spec.kind, spec.rows, spec.cols):
        return ""
    return ("assumed " if assumed else "") + stored.describe()


def left_out_note(fmt: str, plan: Plan) -> str:
    """Which cameras of the recording have no frame in any exported set ("" if none)."""
    missing = plan.left_out
    if not missing:
        return ""
    one = len(missing) == 1
    note = (f"{listed(missing)} {'has' if one else 'have'} no frame in any exported set "
            f"and {'is' if one else 'are'} left out")
    if fmt == "kalibr":
        numbers = ", ".join(kalibr_camera(plan, s) for s in missing)
        note += (f"; the other cameras keep their numbers (no {numbers} "
                 f"folder{'' if one else 's'})")
    return note


def assumed_board_note(session: Session, spec: TargetSpec, target_from: str,
                       subject: str) -> str:
    """``subject`` (what of the export measures with the board) "the 6x6 AprilGrid ...
    process assumes without --target", and why; "" unless ``target_from`` is "default"."""
    if target_from != "default":
        return ""
    stored, assumed = TargetSpec.from_session(session.extra)
    why = ("the session was processed without --target" if assumed else
           "this session, from an earlier SpeechCal, does not say whether it was given"
           if assumed is None and stored is not None else "the session names no board")
    return (f"{subject} the {spec.describe()} process assumes without --target ({why}): "
            "if your board differs, export again with its Kalibr target yaml (speechcal "
            "export --target TARGET.yaml, or Target file… in the window's export dialog); "
            "a wrong tag size scales everything a calibration measures")


def approx_sync_note(sets: Sequence[FrameSet]) -> str:
    """A hint when the frames of one of ``sets`` lie further apart in time than Kalibr's
    default ``--approx-sync`` (KALIBR_APPROX_SYNC_NS) pairs: each camera's best still
    frame is chosen on its own, and cameras are rarely triggered together. "" if not."""
    spread_ns = max((s.skew_ns for s in sets), default=0)
    if spread_ns <= KALIBR_APPROX_SYNC_NS:
        return ""
    tolerance_cs = -(-spread_ns // 10_000_000)  # whole hundredths of a second, up
    shown_ms = -(-spread_ns // 100_000) / 10  # tenths of a millisecond, up
    return (f"the frames of one set lie up to {shown_ms:.1f} ms apart (each camera's "
            f"stillest frame): run kalibr_calibrate_cameras with --approx-sync "
            f"{tolerance_cs / 100:g} (its default {KALIBR_APPROX_SYNC_NS / 1e9:g} s would "
            "drop sets), or export --format kalibr, which names each set's frames alike")


def target_note(session: Session, spec: TargetSpec, target_from: str) -> str:
    """What to tell the user about the ``target.yaml`` describing ``spec``: that it is
    an assumption, or that it is not the board the session's frames were checked
    against (their corner counts are for that one); "" when neither."""
    if target_from == "default":
        return assumed_board_note(session, spec, target_from, "target.yaml describes")
    checked = _checked_board_unlike(session, spec, target_from)
    if not checked:
        return ""
    return (f"target.yaml describes the given {spec.describe()}, but the session's frames "
            f"were checked against the {checked}: the manifest's corner counts are for "
            "that board; process the recording again with this --target to check the "
            "frames against it")
