"""The export facade the CLI and the review window call: select, plan, write, manifest.

Everything is written into a hidden sibling of the output folder that is renamed into
place only when complete (``fsutil.staged_directory``): a failed or cancelled export
leaves nothing behind, and an existing folder is replaced only with ``force``.

Only best still frames are exported: sets that a review left with their nearest frames
(re-scoring after an offset edit or an added set had not finished) are re-scored first
by :func:`export_session_file`, and refused by :func:`export_frame_sets` (the review
window waits for its re-scoring instead).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from speechcal_core.errors import UsageError
from speechcal_core.export.corners import corners_board, corners_problem, write_corners
from speechcal_core.export.earlier import (
    FORMATS,
    TARGET_FORMATS,
    enclosing_export,
    not_replaceable,
)
from speechcal_core.export.errors import ExportError
from speechcal_core.export.manifest import manifest_document, write_manifest
from speechcal_core.export.notes import export_notes
from speechcal_core.export.plan import Progress, make_plan
from speechcal_core.export.selection import frameless_sets, select_sets
from speechcal_core.fsutil import (
    OutputExistsError,
    file_in_the_way,
    overlap,
    staged_directory,
)
from speechcal_core.session.same_frames import first_of_same_frames
from speechcal_core.session.store import check_recording_present
from speechcal_core.sources.bag_source import twin_notes
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from speechcal_core.export.plan import Outcome, Plan
    from speechcal_core.session.model import FrameSet, Session
    from speechcal_core.sources.base import FrameSource


#: formats that write images, and with them the corners found in each
IMAGE_FORMATS = ("kalibr", "folders")

@dataclass(frozen=True)
class ExportResult:
    """What an export wrote (the ``--json`` document of ``speechcal export``)."""

    out: Path
    format: str
    sets: int
    frames: int
    files: int
    skipped: list[str] = field(default_factory=list)
    #: where target.yaml came from (TARGET_FORMATS only): given | session | default
    target: str = ""
    #: what the user should know before calibrating on the export: target.yaml describes
    #: an assumed board, or not the board the session's frames were checked against; a
    #: bag's frames of one set lie further apart than Kalibr pairs by default
    notes: list[str] = field(default_factory=list)
    #: sets re-scored (and saved to the session file) before exporting, see
    #: :func:`export_session_file`
    rescored: int = 0

    def to_dict(self) -> dict[str, Any]:
        doc: dict[str, Any] = {"out": str(self.out), "format": self.format, "sets": self.sets,
                               "frames": self.frames, "files": self.files,
                               "skipped": self.skipped, "notes": list(self.notes)}
        if self.target:
            doc["target"] = self.target
        if self.rescored:
            doc["rescored"] = self.rescored
        return doc


def _noop(_text: str, _fraction: float) -> None:
    pass


def check_output(out: Path, force: bool, protected: dict[str, list[Path]],
                 board: TargetSpec | None = None) -> None:
    """Refuse an existing ``out`` without ``force``; always one that is, holds or lies
    inside an input the export reads (``protected``: what it is -> its paths), one that
    :func:`~speechcal_core.export.earlier.not_replaceable` keeps (``board``: the one a
    Kalibr export writes in its target.yaml), and one under a file."""
    touched = overlap(out, protected)
    if touched is not None:
        relation, what, p = touched
        where = {"is": "this is", "holds": "this folder holds",
                 "inside": "this lies inside"}[relation]
        named = "the session file" if what == "session file" else f"the session's {what}"
        raise ExportError(f"{out.absolute()}: {where} {named} {p}, which the export reads; "
                          "choose another output folder")
    around = enclosing_export(out)
    if around is not None:
        raise ExportError(f"{out.absolute()}: this lies inside the earlier export {around}, "
                          "whose readers would take these frames as its own; choose a folder "
                          "outside it")
    if os.path.lexists(out):
        # what even --force may not replace is said first: "pass --force" would not help
        problem = not_replaceable(out, board)
        if not problem and not force:
            raise OutputExistsError(f"{out} already exists; choose another folder or pass "
                                    "--force")
    else:
        in_the_way = file_in_the_way(out.absolute().parent)
        problem = f"cannot write there ({in_the_way})" if in_the_way else ""
    if problem:
        raise ExportError(f"{out.absolute()}: {problem}; choose another output folder")


def export_target(session: Session, target: TargetSpec | None) -> tuple[TargetSpec, str]:
    """The calibration target to describe: the given one, the session's, or the default
    6x6 AprilGrid that ``speechcal process`` also assumes without ``--target`` ("default"
    also when the session holds that assumption, or may: see ``TargetSpec.from_session``)."""
    if target is not None:
        return target, "given"
    stored, assumed = TargetSpec.from_session(session.extra)
    if stored is not None:
        return stored, "session" if assumed is False else "default"
    return TargetSpec(), "default"


def _write(fmt: str, source: FrameSource, plan: Plan, root: Path, target: TargetSpec,
           progress: Progress) -> tuple[Outcome, dict[str, str]]:
    if fmt == "kalibr":
        from speechcal_core.export.kalibr import kalibr_folders, write_kalibr

        return write_kalibr(source, plan, root, target, progress), kalibr_folders(plan)
    if fmt == "folders":
        from speechcal_core.export.folders import topic_folders, write_folders

        return write_folders(source, plan, root, progress), topic_folders(plan)
    from speechcal_core.export.bag_messages import topic_for
    from speechcal_core.export.bags import write_rosbag1, write_rosbag2
    from speechcal_core.export.kalibr import write_target_file

    write = write_rosbag1 if fmt == "rosbag1" else write_rosbag2
    kinds = {s.name: s.msgtype for s in source.streams}
    outcome = write(source, plan, root, progress)
    write_target_file(root, target, outcome)  # the bag and its board in one folder
    return outcome, {n: topic_for(n, kinds[n]) for n in plan.streams}


def _preflight(session: Session, fmt: str, out: Path, *, force: bool, include_undecided: bool,
               session_path: str | Path | None, target: TargetSpec | None) -> list[FrameSet]:
    """The sets to export, after the checks that need no recording: format, sets, folder."""
    if fmt not in FORMATS:
        raise UsageError(f"unknown export format {fmt!r}; use one of {', '.join(FORMATS)}")
    where = str(session_path) if session_path else "the session"
    sets = select_sets(session, include_undecided=include_undecided, where=where)
    check_output(out, force, session_inputs(session, session_path),
                 _board_written(session, fmt, target))
    if fmt == "rosbag2":
        from speechcal_core.export.bags import rosbag2_path_problem

        too_long = rosbag2_path_problem(out)
        if too_long:
            raise ExportError(too_long)
    return sets


def _board_written(session: Session, fmt: str, target: TargetSpec | None) -> TargetSpec | None:
    """The board an export in ``fmt`` describes in its target.yaml (TARGET_FORMATS)."""
    return export_target(session, target)[0] if fmt in TARGET_FORMATS else None


def session_inputs(session: Session, session_path: str | Path | None
                   ) -> dict[str, list[Path]]:
    """What an export of ``session`` reads and must never write over, for
    :func:`check_output`: its recording, audio and session file."""
    protected = {"recording": [Path(p) for p in session.recording]}
    if session.audio:
        protected["audio"] = [Path(session.audio)]
    if session_path:
        protected["session file"] = [Path(session_path)]
    return protected


def export_frame_sets(
    session: Session,
    source: FrameSource,
    fmt: str,
    out: str | Path,
    *,
    force: bool = False,
    include_undecided: bool = False,
    target: TargetSpec | None = None,
    session_path: str | Path | None = None,
    progress: Progress | None = None,
) -> ExportResult:
    """Write the session's accepted (and with ``include_undecided`` undecided) frame sets
    from the open ``source`` to the folder ``out`` in ``fmt`` (one of :data:`FORMATS`)."""
    out = Path(out).absolute()
    sets = _preflight(session, fmt, out, force=force, include_undecided=include_undecided,
                      session_path=session_path, target=target)
    _refuse_waiting(session, include_undecided, session_path)
    return _export(session, source, sets, fmt, out, force=force,
                   include_undecided=include_undecided, target=target,
                   session_path=session_path, progress=progress)


def _refuse_waiting(session: Session, include_undecided: bool,
                    session_path: str | Path | None) -> None:
    """``ExportError`` when sets to export still show nearest frames, not best still ones."""
    from speechcal_core.review.rescore import export_waits_for

    waiting = export_waits_for(session, include_undecided=include_undecided)
    if waiting:
        where = str(session_path) if session_path else "the session"
        n = len(waiting)
        raise ExportError(
            f"{where}: {n} frame set{'' if n == 1 else 's'} to export still show the frames "
            "nearest the trigger (re-scoring after an offset edit or an added set has not "
            "finished); re-score them first (speechcal export SESSION.json does)"
        )


def _export(session: Session, source: FrameSource, sets: list[FrameSet], fmt: str, out: Path,
            *, force: bool, include_undecided: bool, target: TargetSpec | None,
            session_path: str | Path | None, progress: Progress | None) -> ExportResult:
    """:func:`export_frame_sets` once :func:`_preflight` has passed."""
    report = progress or _noop
    where = str(session_path) if session_path else "the session"
    report("checking the chosen frames", 0.0)
    sets, repeated = first_of_same_frames(sets)
    plan = make_plan(source, sets, where)
    spec, target_from = export_target(session, target)
    yaml_board = spec if fmt in TARGET_FORMATS else None  # what its target.yaml describes
    with staged_directory(out, force=force,
                          may_replace=lambda p: not_replaceable(p, yaml_board)) as root, \
            _named_as(root, out):
        outcome, cameras = _write(fmt, source, plan, root, spec,
                                  lambda text, f: report(text, 0.95 * f))
        if not outcome.files and outcome.skipped:  # every frame damaged: nothing to give
            (set_id, stream), why = next(iter(outcome.skipped.items()))
            raise ExportError(
                f"{where}: none of the frames to export could be read (set {set_id} "
                f"{stream}: {why}); nothing was exported: reject those sets in the review "
                "window, or check the recording")
        board = corners_board(session, spec) if fmt in IMAGE_FORMATS else None
        if board is not None and not corners_problem(session):
            outcome.written.extend(write_corners(source, plan, outcome, root, session, board))
        report("writing the manifest", 0.95)
        header: dict[str, Any] = {
            "schema": 1,
            "format": fmt,
            "session": str(Path(session_path).absolute()) if session_path else None,
            "recording": list(session.recording),
            "include_undecided": include_undecided,
        }
        if fmt in TARGET_FORMATS:
            header["target"] = {"kind": spec.kind, "rows": spec.rows, "cols": spec.cols,
                                "size": spec.size, "spacing": spec.spacing,
                                "from": target_from}
        document = manifest_document(plan, outcome, cameras, header)
        outcome.written.extend(write_manifest(root, document))
    report("done", 1.0)
    skipped = [f"set {s.id}: no camera has a frame at its time"
               for s in frameless_sets(session, include_undecided=include_undecided)]
    skipped += [f"set {sid}: the same frames as set {kept} (two trigger words in one still "
                "hold): written once" for sid, kept in repeated.items()]
    skipped += [f"set {sid} {stream}: {why}" for (sid, stream), why in outcome.skipped.items()]
    twins = twin_notes(source, plan.streams)
    return ExportResult(out, fmt, len(plan.sets), len(outcome.files), len(outcome.written),
                        skipped, target_from if fmt in TARGET_FORMATS else "",
                        [*twins, *export_notes(fmt, session, plan, spec, target_from)])


@contextlib.contextmanager
def _named_as(staging: Path, out: Path) -> Iterator[None]:
    """Errors of the block name ``out`` where they named the hidden ``staging`` folder
    (removed by the time the user reads them)."""
    try:
        yield
    except ExportError as exc:
        raise ExportError(str(exc).replace(str(staging), str(out.absolute()))) from None


def export_session_file(
    session_path: str | Path,
    fmt: str,
    out: str | Path,
    *,
    force: bool = False,
    include_undecided: bool = False,
    target: TargetSpec | None = None,
    progress: Progress | None = None,
) -> ExportResult:
    """:func:`export_frame_sets` on a session file, opening its recording."""
    from speechcal_core.session.store import file_stamp, load_session, session_file
    from speechcal_core.sources import open_recording

    session_path = session_file(session_path)  # a link: its target is read and saved
    out = Path(out).absolute()
    stamp = file_stamp(session_path)
    session = load_session(session_path)
    sets = _preflight(session, fmt, out, force=force, include_undecided=include_undecided,
                      session_path=session_path, target=target)
    check_recording_present(session, session_path)
    report = progress or _noop
    report("opening the recording", 0.0)
    with open_recording(session.recording, streams=session.stream_choice()) as source:
        rescored = _rescore_waiting(session, source, session_path, stamp, include_undecided,
                                    report)
        if rescored:
            sets = select_sets(session, include_undecided=include_undecided,
                               where=str(session_path))
            report = _scaled(report, RESCORE_SHARE)
        result = _export(session, source, sets, fmt, out, force=force,
                         include_undecided=include_undecided, target=target,
                         session_path=session_path, progress=report)
    return replace(result, rescored=rescored)


#: share of the progress of ``speechcal export`` that re-scoring takes when it is needed
RESCORE_SHARE = 0.4


def _scaled(report: Progress, start: float, span: float | None = None) -> Progress:
    span = 1.0 - start if span is None else span
    return lambda text, f: report(text, start + span * f)


def _rescore_waiting(session: Session, source: FrameSource, session_path: Path,
                     stamp: tuple[int, int, int] | None, include_undecided: bool,
                     report: Progress) -> int:
    """Re-score the sets a closed review left with nearest frames, if any is to be
    exported, then the checks over them, and save the session file (unless it changed
    since it was read, at ``stamp``: a window's decisions are not overwritten); returns
    how many.

    What the review window does when the session is opened again, done here so the
    export holds best still frames and the session file says which ones.
    """
    from speechcal_core.review.checks import recheck_due, stream_sizes
    from speechcal_core.review.rescore import export_waits_for, rescore_waiting
    from speechcal_core.session.store import SessionFileError, save_session

    waiting = export_waits_for(session, include_undecided=include_undecided)
    if not waiting:
        return 0
    report(f"{session_path.name}: {len(waiting)} of the frame sets to export still show the "
           "frames nearest the trigger (the review closed before re-scoring them); "
           "choosing their best still frames first", 0.0)
    rescored = rescore_waiting(session, source,
                               _scaled(report, 0.0, RESCORE_SHARE * 0.95))
    report("checking the calibration over the re-scored sets", RESCORE_SHARE * 0.95)
    recheck_due(session, stream_sizes(source))
    try:
        save_session(session, session_path, expect=stamp)  # not over a window's decisions
    except SessionFileError as exc:  # the export is right all the same
        report(f"{exc}; the session file keeps the nearest frames", RESCORE_SHARE)
    return len(rescored)
