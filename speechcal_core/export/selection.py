"""Which frame sets an export holds: the accepted ones, optionally the undecided too."""

from __future__ import annotations

from typing import TYPE_CHECKING

from speechcal_core.export.errors import ExportError

if TYPE_CHECKING:
    from speechcal_core.session.model import FrameSet, Session


def select_sets(
    session: Session, *, include_undecided: bool = False, where: str = "the session"
) -> list[FrameSet]:
    """The sets to export, in time order.

    Accepted sets always; undecided ones only with ``include_undecided``; rejected never.
    Sets without any chosen frame are left out. ``ExportError`` when nothing is left.
    """
    wanted = ("accepted", "undecided") if include_undecided else ("accepted",)
    chosen = [s for s in session.sets
              if s.decision in wanted and s.has_frames]
    if not chosen:
        counts = session.counts()
        frameless = frameless_sets(session, include_undecided=include_undecided)
        if frameless:
            n = len(frameless)
            raise ExportError(
                f"{where}: {n} set{'' if n == 1 else 's'} to export, but no camera has a "
                f"frame at {'its' if n == 1 else 'their'} time; check the audio offset "
                f"(the clap) in the review window: it puts the triggers outside the recording"
            )
        if include_undecided:
            raise ExportError(
                f"{where}: no accepted or undecided frame sets with frames "
                f"({counts['rejected']} rejected); nothing to export"
            )
        raise ExportError(
            f"{where}: no accepted frame sets ({counts['undecided']} undecided, "
            f"{counts['rejected']} rejected); accept sets in the review window first "
            "(speechcal review SESSION.json) or pass --include-undecided"
        )
    return sorted(chosen, key=lambda s: (s.t_ns, s.id))


def frameless_sets(session: Session, *, include_undecided: bool = False) -> list[FrameSet]:
    """The sets :func:`select_sets` leaves out although their decision asks for them: no
    camera has a frame there (a trigger past the recording's end, say)."""
    wanted = ("accepted", "undecided") if include_undecided else ("accepted",)
    return [s for s in session.sets
            if s.decision in wanted and not s.has_frames]
