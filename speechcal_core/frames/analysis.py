"""Everything the session gets from the frames: sets, details, coverage and calibration check."""

from __future__ import annotations

from collections.abc import Callable, Sequence
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
    against, for re-scoring sets later) and ``"coverage"`` (per camera); ``calibration`` is
    DESIGN.md §3's entry.
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
    obj = target.object_points()
    views = views_from_sets(result.sets, result.detections, obj)
    cov = {}
    for stream, size in result.image_sizes.items():
        dets = [result.detections[(v.set_id, stream)] for v in views.get(stream, [])]
        if dets:
            cov[stream] = coverage(dets, obj, size).to_dict()
            out.coverage_images[stream] = coverage_image(dets, size)
    out.extra["coverage"] = cov
    out.calibration = check_cameras(views, result.image_sizes, models, report, wide_only)
    return out
