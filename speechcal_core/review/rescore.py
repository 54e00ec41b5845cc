"""Frame sets chosen and measured again after an offset edit or an added set.

Which sets need it (:func:`needs_rescore`), what to run (:func:`rescore_request`) and how
results are taken (:func:`apply_rescore`) are plain functions of the session, shared by
the review model (which adds events and autosave) and ``speechcal export`` (which re-scores
what a closed review left waiting, :func:`rescore_waiting`). :meth:`RescoreRequest.run`
does the work in between, on any thread: it reads only its own snapshot and the
(thread-safe) recording.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from speechcal_core.frames.sets import FrameReferences, FrameSetOptions, rescore_frame_sets
from speechcal_core.session.model import FrameSet, Session
from speechcal_core.sync.model import SyncModel
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource

Progress = Callable[[str, float], None]

#: share of the progress bar for each stage of the frame search
_STAGES = {"windows": (0.0, 0.75), "corners": (0.75, 0.25)}


@dataclass(frozen=True)
class RescoreResult:
    """Re-scored sets for ``sync`` with their frame details (keyed by set id as text).

    ``references`` is set when they were measured over the whole session (and then
    replace the session's).
    """

    sync: SyncModel
    sets: tuple[FrameSet, ...]
    details: dict[str, Any] = field(default_factory=dict)
    references: FrameReferences | None = None


@dataclass(frozen=True)
class RescoreRequest:
    """Sets to choose and measure again for ``sync``: a snapshot, review goes on meanwhile.

    ``references`` None means the request holds every set of the session and the
    references are measured over them, exactly as ``speechcal process`` does.
    """

    sync: SyncModel
    sets: tuple[FrameSet, ...]
    target: TargetSpec
    references: FrameReferences | None = None
    options: FrameSetOptions = field(default_factory=FrameSetOptions)

    @property
    def text(self) -> str:
        """What the status line says while this runs."""
        n = len(self.sets)
        return f"re-scoring {n} frame set{'' if n == 1 else 's'}…"

    def run(self, source: FrameSource, progress: Progress | None = None) -> RescoreResult:
        """The best-still search and measurements (about 0.1 s per set of four VGA cameras).

        ``progress(text, fraction)`` may raise to cancel; it is called from worker threads.
        """
        report = progress or (lambda _t, _f: None)
        text = self.text

        def stage(name: str, fraction: float) -> None:
            start, span = _STAGES.get(name, (0.0, 1.0))
            report(text, start + span * fraction)

        report(text, 0.0)
        result = rescore_frame_sets(source, self.sync, self.sets, self.target, self.options,
                                    self.references, stage)
        return RescoreResult(self.sync, tuple(result.sets), result.details,
                             result.references if self.references is None else None)


def needs_rescore(session: Session, frame_set: FrameSet) -> bool:
    """Whether a set shows nearest frames that the best-still search should replace.

    True for sets without frame details (added, or moved by an offset edit) once the
    session keeps details, and for details measured at another offset.
    """
    all_details = session.extra.get("frame_details")
    if not isinstance(all_details, dict):
        return False  # a session made without the search, and not edited since
    details = all_details.get(str(frame_set.id))
    if not isinstance(details, dict):
        return True
    measured_at = details.get("trigger_ns")
    return measured_at is not None and \
        measured_at != int(session.sync.to_session(frame_set.trigger.t_s))


def rescore_ids(session: Session) -> list[int]:
    """Ids of the sets that need re-scoring (see :func:`needs_rescore`), in order."""
    return [s.id for s in session.sets if needs_rescore(session, s)]


def export_waits_for(session: Session, *, include_undecided: bool = False) -> list[int]:
    """Ids of the sets an export would hold that still show nearest frames.

    An export of these would write frames that are not the best still ones: re-score
    first. Rejected sets (never exported) do not count.
    """
    wanted = ("accepted", "undecided") if include_undecided else ("accepted",)
    return [s.id for s in session.sets
            if s.decision in wanted and needs_rescore(session, s)]


def rescore_request(session: Session) -> RescoreRequest | None:
    """What to re-score now (None: nothing).

    Just the sets that need it when the session knows what its figures are judged
    against (``"frame_references"``); otherwise, and when every set needs it (after
    an offset edit), all sets, measured as ``speechcal process`` measures them.
    """
    todo = [s for s in session.sets if needs_rescore(session, s)]
    if not todo:
        return None
    extra = session.extra
    references = FrameReferences.from_dict(extra.get("frame_references"))
    if references is None or len(todo) == len(session.sets):
        todo, references = list(session.sets), None
    target = TargetSpec.from_stored(extra.get("target")) or TargetSpec()
    return RescoreRequest(session.sync, tuple(todo), target, references)


def apply_rescore(session: Session, result: RescoreResult) -> list[int]:
    """Put re-scored sets into ``session``; returns the ids taken.

    A result for another sync than the session's is stale and dropped whole; sets
    removed meanwhile (or whose id now names another trigger) are skipped. Decisions
    stay as they are in the session now.
    """
    if result.sync != session.sync:
        return []
    all_details = session.extra.get("frame_details")
    if not isinstance(all_details, dict):
        all_details = session.extra["frame_details"] = {}
    taken = []
    # one pass to find every set: a search per result set took 60 ms for 1000 sets
    where = {s.id: i for i, s in enumerate(session.sets)}
    for new in result.sets:
        index = where.get(new.id, -1)
        if index < 0:
            continue
        old = session.sets[index]
        if old.trigger != new.trigger:
            continue  # another set with a re-used id
        # the time follows the sync (a file whose offset was edited by hand kept old times)
        session.sets[index] = replace(old, t_ns=new.t_ns, frames=new.frames)
        if str(new.id) in result.details:
            all_details[str(new.id)] = result.details[str(new.id)]
        taken.append(new.id)
    if result.references is not None:
        session.extra["frame_references"] = result.references.to_dict()
    return taken


def rescore_waiting(session: Session, source: FrameSource,
                    progress: Progress | None = None) -> list[int]:
    """Re-score, in this thread, every set of ``session`` that needs it; returns their ids.

    For a session saved while its review was still re-scoring (``speechcal export``
    does this before writing anything).
    """
    request = rescore_request(session)
    if request is None:
        return []
    return apply_rescore(session, request.run(source, progress))
