"""Calibration check again after review decisions, from the corners kept in the session.

The review keeps coverage and this check up to date as frames and decisions change:
:mod:`speechcal_core.review.checks`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from speechcal_core.calibration.check import MODELS
from speechcal_core.calibration.collect import detections_from_details
from speechcal_core.frames.analysis import frame_checks
from speechcal_core.frames.detect import Target
from speechcal_core.session.model import Session


def recheck_calibration(
    session: Session,
    target: Target,
    sizes: dict[str, tuple[int, int]],
    models: Sequence[str] = MODELS,
    wide_only: bool = False,
) -> dict[str, Any]:
    """The ``"calibration"`` entry over the sets not rejected, without touching any frame.

    Uses the corners stored under ``"frame_details"`` by ``speechcal process``; ``sizes``
    gives each stream's image (width, height). ``wide_only`` as ``process`` has it fits
    fisheye and double-sphere models only to wide lenses.
    """
    details = session.extra.get("frame_details")
    detections = detections_from_details(details if isinstance(details, dict) else {})
    return frame_checks(session.sets, detections, sizes, target, models, wide_only).calibration
