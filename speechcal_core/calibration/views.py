"""Calibration views (object and image points of one frame) and the result of a fit."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class View:
    """One frame's correspondences: ``object_points`` (N x 3, z = 0), ``image_points`` (N x 2)."""

    set_id: int
    object_points: np.ndarray
    image_points: np.ndarray


@dataclass
class CalibrationResult:
    """A fitted camera model with its reprojection errors."""

    model: str  # pinhole | fisheye | double-sphere
    intrinsics: list[float]  # fx, fy, cx, cy (+ xi, alpha for double-sphere)
    distortion: list[float]
    rms_px: float
    view_rms_px: list[float]
    set_ids: list[int]
    rvecs: list[np.ndarray] = field(default_factory=list, repr=False)
    tvecs: list[np.ndarray] = field(default_factory=list, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form used under ``"calibration"`` in the session (DESIGN.md §3)."""
        return {
            "model": self.model,
            "intrinsics": [round(float(v), 6) for v in self.intrinsics],
            "distortion": [round(float(v), 8) for v in self.distortion],
            "rms_px": round(float(self.rms_px), 4),
            "views": [{"set": s, "rms_px": round(float(e), 4)}
                      for s, e in zip(self.set_ids, self.view_rms_px, strict=True)],
        }


def view_errors(residuals: list[np.ndarray]) -> tuple[float, list[float]]:
    """Overall RMS and per-view RMS (pixels) from per-view N x 2 residual arrays."""
    per_view = [float(np.sqrt(np.mean(np.sum(r * r, axis=1)))) for r in residuals]
    total = np.concatenate(residuals)
    return float(np.sqrt(np.mean(np.sum(total * total, axis=1)))), per_view
