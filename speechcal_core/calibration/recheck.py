"""Calibration check again after review decisions, from the corners kept in the session."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from speechcal_core.calibration.check import MODELS, check_cameras
from speechcal_core.calibration.collect import detections_from_details, views_from_sets
from speechcal_core.frames.detect import Target
from speechcal_core.session.model import Session


def recheck_calibration(
    session: Session,
    target: Target,
    sizes: dict[str, tuple[int, int]],
    models: Sequence[str] = MODELS,
) -> dict[str, Any]:
    """The ``"calibration"`` entry over the sets not rejected, without touching any frame.

    Uses the corners stored under ``"frame_details"`` by ``speechcal process``; ``sizes``
    gives each stream's image (width, height).
    """
    details = session.extra.get("frame_details", {})
    detections = detections_from_details(details)
    views = views_from_sets(session.sets, detections, target.object_points())
    return check_cameras(views, sizes, models)
