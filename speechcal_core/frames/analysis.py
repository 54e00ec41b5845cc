"""Everything the session gets from the frames: sets, details, coverage and calibration check."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from speechcal_core.calibration.check import MODELS, check_cameras
from speechcal_core.calibration.collect import views_from_sets
from speechcal_core.frames.coverage import coverage, coverage_image
from speechcal_core.frames.detect import Detection, Target
from speechcal_core.frames.sets import FrameSetOptions, build_frame_sets
from speechcal_core.session.model import FrameSet, Trigger

if TYPE_CHECKING:
    import numpy as np

    from speechcal_core.sources.base import FrameSource
    from speechcal_core.sync.model import SyncModel

Progress = Callable[[str, float], None]


@dataclass
class FrameAnalysis:
    """Frame sets and the figures kept beside them in the session.

    ``extra`` holds ``"frame_details"`` (per set: chosen and nearest frames, stillness,
    corners), ``"frame_references"`` (per camera: what sharpness and stillness were judged
    against, for re-scoring sets later), ``"coverage"`` (per camera) and
    ``"checks_basis"`` (what coverage and calibration were computed over, see
    :func:`checks_basis`); ``calibration`` is DESIGN.md §3's entry.
    """

    sets: list[FrameSet]
    extra: dict[str, Any] = field(default_factory=dict)
    calibration: dict[str, Any] = field(default_factory=dict)
    coverage_images: dict[str, np.ndarray] = field(default_factory=dict)
    detections: dict[tuple[int, str], Detection] = field(default_factory=dict)


def analyse_frames(
    source: FrameSource,
    sync: SyncModel,
    triggers: Sequence[Trigger],
    target: Target | None,
    *,
    options: FrameSetOptions | None = None,
    models: Sequence[str] = MODELS,
    wide_only: bool = True,
    progress: Progress | None = None,
) -> FrameAnalysis:
    """Build the frame sets, then coverage and a calibration check per camera.

    ``wide_only`` (default) fits the fisheye and double-sphere models only to wide lenses.
    """
    report = progress or (lambda _s, _f: None)
    result = build_frame_sets(source, sync, triggers, target, options, report)
    extra: dict[str, Any] = {"frame_details": result.details}
    if result.references is not None:
        extra["frame_references"] = result.references.to_dict()
    out = FrameAnalysis(result.sets, extra, detections=result.detections)
    if target is None:
        return out
    checks = frame_checks(result.sets, result.detections, result.image_sizes, target,
                          models, wide_only, report)
    out.extra["coverage"] = checks.coverage
    out.extra["checks_basis"] = checks_basis(result.sets)
    out.calibration = checks.calibration
    out.coverage_images = checks.coverage_images
    return out


@dataclass
class FrameChecks:
    """Coverage (per camera, JSON-ready, and as images) and the calibration check."""

    coverage: dict[str, Any]
    calibration: dict[str, Any]
    coverage_images: dict[str, np.ndarray] = field(default_factory=dict)


def frame_checks(
    sets: Iterable[FrameSet],
    detections: Mapping[tuple[int, str], Detection],
    sizes: Mapping[str, tuple[int, int]],
    target: Target,
    models: Sequence[str] = MODELS,
    wide_only: bool = True,
    progress: Progress | None = None,
) -> FrameChecks:
    """Coverage and calibration check per camera over the sets not rejected.

    ``detections`` are the target corners per (set id, stream), ``sizes`` each stream's
    image (width, height); as :func:`analyse_frames` computes them, also for a session
    whose frames or decisions changed in review.
    """
    obj = target.object_points()
    views = views_from_sets(sets, detections, obj)
    out = FrameChecks({}, {})
    for stream, size in sizes.items():
        dets = [detections[(v.set_id, stream)] for v in views.get(stream, [])]
        if dets:
            out.coverage[stream] = coverage(dets, obj, size).to_dict()
            out.coverage_images[stream] = coverage_image(dets, size)
    out.calibration = check_cameras(views, sizes, models, progress, wide_only)
    return out


#: the last sets :func:`checks_basis` digested, and the digest (the window asks again and
#: again for the same sets: the check line, whether the checks are due, still wanted)
_last_basis: list[tuple[tuple[FrameSet, ...], str] | None] = [None]


def checks_basis(sets: Iterable[FrameSet]) -> str:
    """A digest of what coverage and the calibration check depend on: the chosen frames
    of every set not rejected. Equal digests, equal checks (for one target)."""
    sets = tuple(sets)
    last = _last_basis[0]  # frame sets are immutable: the same objects, the same digest
    if last is not None and len(last[0]) == len(sets) and all(
            a is b for a, b in zip(last[0], sets, strict=True)):
        return last[1]
    kept = [[s.id, [[f.stream, f.index, f.stamp_ns] for f in s.frames]]
            for s in sets if s.decision != "rejected"]
    text = json.dumps(kept, separators=(",", ":"))
    digest = hashlib.sha1(text.encode(), usedforsecurity=False).hexdigest()
    _last_basis[0] = (sets, digest)
    return digest
