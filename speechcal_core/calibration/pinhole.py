"""Pinhole camera with OpenCV's 5 radial-tangential coefficients (cv2.calibrateCamera)."""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from speechcal_core.calibration.views import CalibrationResult, View, view_errors

_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 60, 1e-9)


def calibrate_pinhole(views: Sequence[View], size: tuple[int, int], fix_k3: bool = False
                      ) -> CalibrationResult:
    """Fit fx, fy, cx, cy and k1, k2, p1, p2, k3 to the views (``size`` is width, height);
    k3 kept at zero with ``fix_k3`` (Kalibr's ``pinhole-radtan`` has no k3)."""
    obj = [v.object_points.astype(np.float32) for v in views]
    img = [v.image_points.astype(np.float32) for v in views]
    _, k, dist, rvecs, tvecs = cv2.calibrateCamera(
        obj, img, size, None, None, flags=cv2.CALIB_FIX_K3 if fix_k3 else 0,
        criteria=_CRITERIA)
    residuals = []
    for v, r, t in zip(views, rvecs, tvecs, strict=True):
        proj, _ = cv2.projectPoints(v.object_points, r, t, k, dist)
        residuals.append(proj.reshape(-1, 2) - v.image_points)
    rms, per_view = view_errors(residuals)
    return CalibrationResult("pinhole", [k[0, 0], k[1, 1], k[0, 2], k[1, 2]],
                             dist.ravel()[:5].tolist(), rms, per_view,
                             [v.set_id for v in views], list(rvecs), list(tvecs))
