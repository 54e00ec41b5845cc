"""Fisheye camera, OpenCV's equidistant model with k1..k4 (cv2.fisheye.calibrate)."""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from speechcal_core.calibration.views import CalibrationResult, View, view_errors

_CRITERIA = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 100, 1e-10)
# OpenCV 5 keeps the fisheye flags with the others in cv2.CALIB_*
_FLAGS = cv2.CALIB_RECOMPUTE_EXTRINSIC | cv2.CALIB_FIX_SKEW
#: the joint fit uses at most this many views (spread over the session); every view's
#: pose and error are then found with the fitted intrinsics. The joint fit's time grows
#: with the views (1.5-1.7 s for 108 views of 144 points): 30 of them took 0.4-0.5 s,
#: the RMS 0.0001 px higher and the worst view's error the same
FIT_VIEWS = 30
#: k3 and k4 are fitted only when they lower the RMS by more than this fraction. A board
#: seen no further than 30-35 degrees off the axis of a 130-150 degree lens (as synthetic
#: sessions show it) pins k1, k2 and the focal length, not k3 and k4: fitted, they came out
#: 0.1-1.1 off (truth under 0.01) at the same RMS to 0.001 px, and put the image's corners
#: 300-7400 px from where the lens shows them; left at zero, 4-13 px
FEWER_SLACK = 0.02


def calibrate_fisheye(views: Sequence[View], size: tuple[int, int],
                      guess: np.ndarray | None = None) -> CalibrationResult:
    """Fit fx, fy, cx, cy and k1..k4 (k3, k4 only where they help, see ``FEWER_SLACK``);
    ``guess`` is an optional starting 3x3 camera matrix.

    With more than ``FIT_VIEWS`` views the intrinsics come from a spread subset of them
    and each view's pose from ``cv2.fisheye.solvePnP``; should a pose fail, from a joint
    fit of all views.
    """
    if len(views) > FIT_VIEWS:
        pick = np.unique(np.linspace(0, len(views) - 1, FIT_VIEWS).round().astype(int))
        k, d, _rvecs, _tvecs = _joint_fit([views[i] for i in pick], size, guess)
        poses = _poses(views, k, d)
        if poses is not None:
            return _result(views, k, d, *poses)
    return _result(views, *_joint_fit(views, size, guess))


def _points(view: View) -> tuple[np.ndarray, np.ndarray]:
    """A view's object and image points as the fisheye functions take them."""
    return (view.object_points.reshape(1, -1, 3).astype(np.float64),
            view.image_points.reshape(1, -1, 2).astype(np.float64))


def _joint_fit(views: Sequence[View], size: tuple[int, int], guess: np.ndarray | None,
               ) -> tuple[np.ndarray, np.ndarray, list, list]:
    """Intrinsics, distortion and every view's pose from cv2.fisheye.calibrate: k1..k4,
    or k1, k2 alone when k3 and k4 add nothing (``FEWER_SLACK``)."""
    obj, img = zip(*(_points(v) for v in views), strict=True)
    w, h = size
    start = guess.copy() if guess is not None else np.array(
        [[w / 3.0, 0, w / 2], [0, w / 3.0, h / 2], [0, 0, 1]], np.float64)
    flags = _FLAGS | cv2.CALIB_USE_INTRINSIC_GUESS
    rms, k, d, rvecs, tvecs = cv2.fisheye.calibrate(list(obj), list(img), size, start.copy(),
                                                    np.zeros((4, 1)), flags=flags,
                                                    criteria=_CRITERIA)
    try:
        fewer = cv2.fisheye.calibrate(list(obj), list(img), size, start.copy(),
                                      np.zeros((4, 1)),
                                      flags=flags | cv2.CALIB_FIX_K3 | cv2.CALIB_FIX_K4,
                                      criteria=_CRITERIA)
    except cv2.error:
        fewer = None
    if fewer is not None and fewer[0] <= rms * (1 + FEWER_SLACK):
        _, k, d, rvecs, tvecs = fewer
    return k, d, list(rvecs), list(tvecs)


def _poses(views: Sequence[View], k: np.ndarray, d: np.ndarray) -> tuple[list, list] | None:
    """Every view's pose for the intrinsics ``k``, ``d`` (None if one cannot be found)."""
    rvecs, tvecs = [], []
    for view in views:
        obj, img = _points(view)
        try:
            ok, r, t = cv2.fisheye.solvePnP(obj.reshape(-1, 1, 3), img.reshape(-1, 1, 2), k, d)
        except cv2.error:
            return None
        if not ok or not (np.all(np.isfinite(r)) and np.all(np.isfinite(t))):
            return None
        rvecs.append(r)
        tvecs.append(t)
    return rvecs, tvecs


def _result(views: Sequence[View], k: np.ndarray, d: np.ndarray, rvecs: list,
            tvecs: list) -> CalibrationResult:
    """The fit with every view's reprojection error."""
    residuals = []
    for v, r, t in zip(views, rvecs, tvecs, strict=True):
        proj, _ = cv2.fisheye.projectPoints(_points(v)[0], r, t, k, d)
        residuals.append(proj.reshape(-1, 2) - v.image_points)
    rms, per_view = view_errors(residuals)
    return CalibrationResult("fisheye", [k[0, 0], k[1, 1], k[0, 2], k[1, 2]],
                             d.ravel()[:4].tolist(), rms, per_view,
                             [v.set_id for v in views],
                             [np.asarray(r).reshape(3) for r in rvecs],
                             [np.asarray(t).reshape(3) for t in tvecs])
