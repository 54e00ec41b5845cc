"""Fisheye camera, OpenCV's equidistant model with k1..k4 (cv2.fisheye.calibrate)."""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from speechcal_core.calibration.views import CalibrationResult, View, view_errors

_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-10)
# OpenCV 5 keeps the fisheye flags with the others in cv2.CALIB_*
_FLAGS = cv2.CALIB_RECOMPUTE_EXTRINSIC | cv2.CALIB_FIX_SKEW


def calibrate_fisheye(views: Sequence[View], size: tuple[int, int],
                      guess: np.ndarray | None = None) -> CalibrationResult:
    """Fit fx, fy, cx, cy and k1..k4; ``guess`` is an optional starting 3x3 camera matrix."""
    obj = [v.object_points.reshape(1, -1, 3).astype(np.float64) for v in views]
    img = [v.image_points.reshape(1, -1, 2).astype(np.float64) for v in views]
    w, h = size
    k = guess.copy() if guess is not None else np.array(
        [[w / 3.0, 0, w / 2], [0, w / 3.0, h / 2], [0, 0, 1]], np.float64)
    d = np.zeros((4, 1))
    flags = _FLAGS | cv2.CALIB_USE_INTRINSIC_GUESS
    _, k, d, rvecs, tvecs = cv2.fisheye.calibrate(obj, img, size, k, d, flags=flags,
                                                  criteria=_CRITERIA)
    residuals = []
    for v, o, r, t in zip(views, obj, rvecs, tvecs, strict=True):
        proj, _ = cv2.fisheye.projectPoints(o, r, t, k, d)
        residuals.append(proj.reshape(-1, 2) - v.image_points)
    rms, per_view = view_errors(residuals)
    return CalibrationResult("fisheye", [k[0, 0], k[1, 1], k[0, 2], k[1, 2]],
                             d.ravel()[:4].tolist(), rms, per_view,
                             [v.set_id for v in views],
                             [np.asarray(r).reshape(3) for r in rvecs],
                             [np.asarray(t).reshape(3) for t in tvecs])
