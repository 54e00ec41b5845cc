"""Coverage and the calibration check, kept up to date with the frames and decisions of a review.

``speechcal process`` stores both with a digest of what they were computed over
(``"checks_basis"``, :func:`~speechcal_core.frames.analysis.checks_basis`). Once
re-scoring has chosen other frames, or a set was rejected, taken back, added or removed,
they are due again (:func:`checks_due`). A :class:`ChecksRequest` holds a snapshot of
what they need, so they can be recomputed on any thread; :func:`apply_checks` takes the
result unless the session changed meanwhile.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from speechcal_core.calibration.check import MIN_POINTS, MIN_VIEWS
from speechcal_core.calibration.collect import detections_from_details
from speechcal_core.frames.analysis import checks_basis, frame_checks
from speechcal_core.frames.unseen_cameras import SMALLEST_TAG_PX
from speechcal_core.review.rescore import rescore_ids
from speechcal_core.session.model import FrameSet, Session
from speechcal_core.target import TargetSpec
from speechcal_core.text import WARNING_SYMBOL, counted

if TYPE_CHECKING:
    from speechcal_core.frames.detect import Detection
    from speechcal_core.sources.base import FrameSource

Progress = Callable[[str, float], None]


@dataclass(frozen=True)
class ChecksResult:
    """Coverage and calibration check computed over the sets whose digest is ``basis``."""

    basis: str
    calibration: dict[str, Any]
    coverage: dict[str, Any]


@dataclass(frozen=True)
class ChecksRequest:
    """What the checks need, copied out of the session: review goes on meanwhile."""

    basis: str
    sets: tuple[FrameSet, ...]
    #: the session's frame details by set id (a copy of the mapping; the review replaces
    #: a set's details, never changes them in place): their corners are read in :meth:`run`
    details: Mapping[str, dict]
    sizes: Mapping[str, tuple[int, int]]
    target: TargetSpec

    def detections(self) -> dict[tuple[int, str], Detection]:
        """The corners found per (set id, stream), read from the details (tens of
        milliseconds for a hundred sets of a dozen cameras: :meth:`run` does it, on the
        thread that computes the checks, not the one that asks)."""
        return detections_from_details(self.details)

    def run(self, progress: Progress | None = None) -> ChecksResult:
        """Coverage and calibration fits per camera (tens of milliseconds for the demo)."""
        checks = frame_checks(self.sets, self.detections(), self.sizes, self.target,
                              progress=progress)
        return ChecksResult(self.basis, checks.calibration, checks.coverage)


def stream_sizes(source: FrameSource) -> dict[str, tuple[int, int]]:
    """Each stream's image (width, height), as the checks need them."""
    return {s.name: (s.width, s.height) for s in source.streams if s.width > 0 and s.height > 0}


def checks_due(session: Session) -> bool:
    """Whether coverage and the calibration check should be computed again now.

    True when they were computed over other frames or decisions than the session has
    (or it does not say over which), for a session that keeps target corners; never while
    sets still wait for re-scoring (their nearest frames are about to be replaced).
    """
    if not isinstance(session.extra.get("frame_details"), dict):
        return False  # no corners to check with
    if session.extra.get("checks_basis") == checks_basis(session.sets):
        return False
    return not rescore_ids(session)


def checks_request(session: Session, sizes: Mapping[str, tuple[int, int]]) -> ChecksRequest | None:
    """A snapshot to compute the checks from, or None when they are not due."""
    if not checks_due(session):
        return None
    details = session.extra["frame_details"]
    target = TargetSpec.from_stored(session.extra.get("target")) or TargetSpec()
    return ChecksRequest(checks_basis(session.sets), tuple(session.sets), dict(details),
                         dict(sizes), target)


def still_wanted(session: Session, basis: str) -> bool:
    """Whether checks computed over ``basis`` (a request's, a result's) are over the
    frames and decisions the session has now, so they would be taken."""
    return basis == checks_basis(session.sets)


def apply_checks(session: Session, result: ChecksResult) -> bool:
    """Store the checks in the session unless its frames or decisions changed since the
    request was made (then False: they are due again)."""
    if not still_wanted(session, result.basis):
        return False
    session.calibration = result.calibration
    session.extra["coverage"] = result.coverage
    session.extra["checks_basis"] = result.basis
    return True


def recheck_due(session: Session, sizes: Mapping[str, tuple[int, int]],
                progress: Progress | None = None) -> bool:
    """Compute the checks in this thread if they are due; True if they were."""
    request = checks_request(session, sizes)
    return request is not None and apply_checks(session, request.run(progress))


@dataclass(frozen=True)
class CheckSummary:
    """What the window says about the checks: one line, one line per camera, a warning."""

    line: str
    cameras: tuple[str, ...]
    warning: bool  # a camera has no fit


def check_summary(session: Session, streams: Sequence[str]) -> CheckSummary | None:
    """The checks in words (None for a session without target corners).

    While they are not for the session's frames and decisions they are "updating", or
    wait for re-scoring while sets show nearest frames.
    """
    if not isinstance(session.extra.get("frame_details"), dict):
        return None
    if session.extra.get("checks_basis") != checks_basis(session.sets):
        if rescore_ids(session):
            return CheckSummary("calibration check: after re-scoring", (), False)
        return CheckSummary("calibration check: updating…", (), False)
    kept = sum(1 for s in session.sets if s.decision != "rejected")
    if not kept:  # nothing to check: say why rather than count a check over no sets
        why = ("every frame set is rejected; accept some to check the calibration"
               if session.sets else "no frame sets to check")
        return CheckSummary(f"calibration check: {why}", (), bool(session.sets))
    fits = session.calibration or {}
    cover = session.extra.get("coverage") or {}
    lines = []
    central = []
    for name in streams:
        entry, cov = fits.get(name), cover.get(name) or {}
        progress = cov.get("progress") or {}
        spread = " ".join(f"{k} {v:.0%}" for k, v in progress.items())
        spread = f"; coverage {spread}" if spread else ""
        if isinstance(entry, dict) and near_centre_only(progress):
            central.append(name)
            spread += f"; {WARNING_SYMBOL} {CENTRE_ONLY}"
        if isinstance(entry, dict):
            lines.append(f"{name}: {entry.get('model')} RMS {entry.get('rms_px', 0):.2f} px "
                         f"over {len(entry.get('views') or [])} views{spread}")
        else:
            views = int(cov.get("views", 0))
            unseen = f"; {WARNING_SYMBOL} {UNSEEN_HERE}" \
                if views == 0 and _most_views(cover, streams) > 0 else ""
            lines.append(f"{name}: no model fits its {views} views of the "
                         f"target (at least {MIN_VIEWS} with {MIN_POINTS} corners or more are "
                         f"needed){spread}{unseen}")
    rms = [e["rms_px"] for e in fits.values() if isinstance(e, dict) and "rms_px" in e]
    line = (f"calibration check over {kept} set{'' if kept == 1 else 's'} not rejected: "
            f"{len(rms)} of {counted(len(streams), 'camera')} fit")
    if rms:
        line += f", RMS ≤ {max(rms):.2f} px"
    elif 0 < kept < MIN_VIEWS:  # too few to tell anything about the board
        line += f" (a fit needs the target in {MIN_VIEWS} sets or more)"
    elif 0 < (seen := _most_views(cover, streams)) < MIN_VIEWS:
        # the board was found, in too few sets (others show no frame, or no board)
        line += (f" (a fit needs the target in {MIN_VIEWS} sets or more; no camera saw it "
                 f"in more than {seen})")
    elif kept and not seen:  # the board is nowhere: it may not be the one looked for
        target = TargetSpec.from_stored(session.extra.get("target")) or TargetSpec()
        line += (f" (looked for a {target.describe()}: if the board is "
                 "another one, process again with --target TARGET.yaml into a new session "
                 "file)")
    if central:  # the tooltip's camera lines say which
        line += (f"; {counted(len(central), 'camera')} saw the board only near the image "
                 "centre")
    return CheckSummary(line, tuple(lines), len(rms) < len(streams) or bool(central))


#: coverage (``progress`` of the board's centre across the image, as ROS
#: camera_calibration counts it) under which a camera's views all lie near the image centre
CENTRE_ONLY_BELOW = 0.3
CENTRE_ONLY = ("the board stayed near the image centre: the fit says little of the lens "
               "toward the edges (a fisheye's most), hold it near the edges and corners too")


#: why a camera saw the target in no set that other cameras saw it in
UNSEEN_HERE = ("the target was found in none of its frames while other cameras found it: "
               "it likely shows too small there to read (a fisheye lens or a low "
               "resolution shows the board small; AprilGrid tags need about "
               f"{SMALLEST_TAG_PX} px or more), or out of its view; hold the board closer to "
               "this camera, or record it at a higher resolution")


def near_centre_only(progress: Mapping[str, Any]) -> bool:
    """Whether the board's centre covered under :data:`CENTRE_ONLY_BELOW` of the image
    both across and down (seen on synthetic fisheye cameras: 15-25 %; pinhole cameras
    of the same sessions 34-100 %)."""
    x, y = progress.get("x"), progress.get("y")
    return isinstance(x, (int, float)) and isinstance(y, (int, float)) \
        and x < CENTRE_ONLY_BELOW and y < CENTRE_ONLY_BELOW


def _most_views(coverage: Mapping[str, Any], streams: Sequence[str]) -> int:
    """The most sets any of ``streams`` saw the target in, as the coverage counts them."""
    return max((int((coverage.get(name) or {}).get("views", 0)) for name in streams),
               default=0)
