"""Calibration views per camera from the frame sets' corners (rejected sets left out)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from speechcal_core.calibration.views import View
from speechcal_core.frames.detect import Detection
from speechcal_core.session.model import FrameSet


def views_from_sets(
    sets: Iterable[FrameSet],
    detections: Mapping[tuple[int, str], Detection],
    object_points: np.ndarray,
) -> dict[str, list[View]]:
    """``{stream: [View]}`` from every set not rejected, in set order; a frame two sets
    chose (two trigger words in one still hold) is one view."""
    out: dict[str, list[View]] = {}
    seen: set[tuple[str, int]] = set()
    for fs in sets:
        if fs.decision == "rejected":
            continue
        for f in fs.frames:
            det = detections.get((fs.id, f.stream))
            if f.index < 0 or det is None or (f.stream, f.index) in seen:
                continue
            seen.add((f.stream, f.index))
            out.setdefault(f.stream, []).append(
                View(fs.id, object_points[det.ids], det.points))
    return out


def detections_from_details(details: Mapping[str, dict]) -> dict[tuple[int, str], Detection]:
    """Corner detections back from the session's stored frame details (for a re-check)."""
    out = {}
    for set_id, d in details.items():
        for stream, entry in d.get("frames", {}).items():
            if "ids" in entry and "points" in entry:
                out[(int(set_id), stream)] = Detection(
                    np.asarray(entry["points"], np.float64).reshape(-1, 2),
                    np.asarray(entry["ids"], np.int32))
    return out
