"""The export facade the CLI and the review window call: select, plan, write, manifest.

Everything is written into a hidden sibling of the output folder that is renamed into
place only when complete (``fsutil.staged_directory``): a failed or cancelled export
leaves nothing behind, and an existing folder is replaced only with ``force``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from speechcal_core.errors import UsageError
from speechcal_core.export.errors import ExportError
from speechcal_core.export.manifest import manifest_document, write_manifest
from speechcal_core.export.plan import Progress, make_plan
from speechcal_core.export.selection import select_sets
from speechcal_core.fsutil import OutputExistsError, staged_directory
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from speechcal_core.export.plan import Outcome, Plan
    from speechcal_core.session.model import FrameSet, Session
    from speechcal_core.sources.base import FrameSource

FORMATS = ("kalibr", "folders", "rosbag1", "rosbag2")


@dataclass(frozen=True)
class ExportResult:
    """What an export wrote (the ``--json`` document of ``speechcal export``)."""

    out: Path
    format: str
    sets: int
    frames: int
    files: int
    skipped: list[str] = field(default_factory=list)
    target: str = ""  # where target.yaml came from (kalibr only): given | session | default

    def to_dict(self) -> dict[str, Any]:
        doc: dict[str, Any] = {"out": str(self.out), "format": self.format, "sets": self.sets,
                               "frames": self.frames, "files": self.files,
                               "skipped": self.skipped}
        if self.target:
            doc["target"] = self.target
        return doc


def _noop(_text: str, _fraction: float) -> None:
    pass


def check_output(out: Path, force: bool, protected: list[Path]) -> None:
    """Refuse an existing ``out`` without ``force``, and always one that holds the input."""
    out = out.absolute()
    for p in protected:
        p = p.absolute()
        if p == out or out in p.parents:
            raise ExportError(
                f"{out}: this folder holds {p.name}, which the export reads; "
                "choose another output folder"
            )
    if out.exists() and not force:
        raise OutputExistsError(f"{out} already exists; choose another folder or pass --force")


def export_target(session: Session, target: TargetSpec | None) -> tuple[TargetSpec, str]:
    """The calibration target to describe: the given one, the session's, or the default
    6x6 AprilGrid that ``speechcal process`` also assumes without ``--target``."""
    if target is not None:
        return target, "given"
    stored = TargetSpec.from_stored(session.extra.get("target"))
    if stored is not None:
        return stored, "session"
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

    write = write_rosbag1 if fmt == "rosbag1" else write_rosbag2
    kinds = {s.name: s.msgtype for s in source.streams}
    return write(source, plan, root, progress), {n: topic_for(n, kinds[n]) for n in plan.streams}


def _preflight(session: Session, fmt: str, out: Path, *, force: bool, include_undecided: bool,
               session_path: str | Path | None) -> list[FrameSet]:
    """The sets to export, after the checks that need no recording: format, sets, folder."""
    if fmt not in FORMATS:
        raise UsageError(f"unknown export format {fmt!r}; use one of {', '.join(FORMATS)}")
    where = str(session_path) if session_path else "the session"
    sets = select_sets(session, include_undecided=include_undecided, where=where)
    protected = [Path(p) for p in session.recording]
    if session_path:
        protected.append(Path(session_path))
    check_output(out, force, protected)
    return sets


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
                      session_path=session_path)
    return _export(session, source, sets, fmt, out, force=force,
                   include_undecided=include_undecided, target=target,
                   session_path=session_path, progress=progress)


def _export(session: Session, source: FrameSource, sets: list[FrameSet], fmt: str, out: Path,
            *, force: bool, include_undecided: bool, target: TargetSpec | None,
            session_path: str | Path | None, progress: Progress | None) -> ExportResult:
    """:func:`export_frame_sets` once :func:`_preflight` has passed."""
    report = progress or _noop
    where = str(session_path) if session_path else "the session"
    report("checking the chosen frames", 0.0)
    plan = make_plan(source, sets, where)
    spec, target_from = export_target(session, target)
    with staged_directory(out, force=force) as root:
        outcome, cameras = _write(fmt, source, plan, root, spec,
                                  lambda text, f: report(text, 0.95 * f))
        report("writing the manifest", 0.95)
        header: dict[str, Any] = {
            "schema": 1,
            "format": fmt,
            "session": str(Path(session_path).absolute()) if session_path else None,
            "recording": list(session.recording),
            "include_undecided": include_undecided,
        }
        if fmt == "kalibr":
            header["target"] = {"kind": spec.kind, "rows": spec.rows, "cols": spec.cols,
                                "size": spec.size, "spacing": spec.spacing,
                                "from": target_from}
        document = manifest_document(plan, outcome, cameras, header)
        outcome.written.extend(write_manifest(root, document))
    report("done", 1.0)
    skipped = [f"set {sid} {stream}: {why}" for (sid, stream), why in outcome.skipped.items()]
    return ExportResult(out, fmt, len(plan.sets), len(outcome.files), len(outcome.written),
                        skipped, target_from if fmt == "kalibr" else "")


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
    from speechcal_core.session.store import load_session
    from speechcal_core.sources import open_recording

    session_path = Path(session_path)
    out = Path(out).absolute()
    session = load_session(session_path)
    sets = _preflight(session, fmt, out, force=force, include_undecided=include_undecided,
                      session_path=session_path)
    for p in session.recording:
        if not Path(p).exists():
            raise ExportError(
                f"{session_path}: its recording {p} is missing; put it back there "
                "(paths are kept relative to the session file) or process it again"
            )
    report = progress or _noop
    report("opening the recording", 0.0)
    with open_recording(session.recording) as source:
        return _export(session, source, sets, fmt, out, force=force,
                       include_undecided=include_undecided, target=target,
                       session_path=session_path, progress=progress)

