"""Projection models of the synthetic cameras: per-pixel viewing rays and point projection.

``pinhole`` is OpenCV's 5-coefficient radial-tangential model (``cv2.projectPoints``),
``fisheye`` OpenCV's equidistant model (``cv2.fisheye``). Pixel centres sit at integer
coordinates, as in OpenCV.
"""

from __future__ import annotations

import cv2
import numpy as np

from speechcal_core.synth.timeline import CameraSpec

#: a pixel whose ray re-projects further than this from the pixel has no ray (outside the
#: region where the lens model is invertible)
MAX_REPROJECTION_PX = 0.05


def project_points(camera: CameraSpec, points_cam: np.ndarray) -> np.ndarray:
    """Project N x 3 points given in the camera frame to N x 2 pixel coordinates."""
    pts = np.asarray(points_cam, dtype=np.float64).reshape(-1, 3)
    fx, fy, cx, cy = camera.intrinsics
    x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
    if camera.model == "fisheye":
        k1, k2, k3, k4 = camera.distortion[:4]
        r = np.hypot(x, y)
        theta = np.arctan2(r, z)
        t2 = theta * theta
        theta_d = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
        scale = np.divide(theta_d, r, out=np.ones_like(r), where=r > 1e-12)
        xd, yd = x * scale, y * scale
    else:
        k1, k2, p1, p2, k3 = (tuple(camera.distortion) + (0.0,) * 5)[:5]
        xn, yn = x / z, y / z
        r2 = xn * xn + yn * yn
        radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3))
        xd = xn * radial + 2 * p1 * xn * yn + p2 * (r2 + 2 * xn * xn)
        yd = yn * radial + p1 * (r2 + 2 * yn * yn) + 2 * p2 * xn * yn
    return np.stack([fx * xd + cx, fy * yd + cy], axis=1)


def pixel_rays(camera: CameraSpec, step: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Unit viewing rays (H x W x 3, float32) of every ``step``-th pixel and a validity mask.

    Rays are in the camera frame (``z`` forward). Pixels the lens model cannot invert
    (beyond the fold of a strong barrel distortion) get a zero ray and ``False``.
    """
    ys, xs = np.mgrid[0 : camera.height : step, 0 : camera.width : step].astype(np.float64)
    pix = np.stack([xs.ravel(), ys.ravel()], axis=1)
    rays = _fisheye_rays(camera, pix) if camera.model == "fisheye" else _pinhole_rays(camera, pix)
    with np.errstate(invalid="ignore"):
        back = project_points(camera, rays)
    err = np.hypot(*(back - pix).T)
    valid = np.isfinite(err) & (err < MAX_REPROJECTION_PX) & np.all(np.isfinite(rays), axis=1)
    rays[~valid] = 0.0
    shape = ys.shape
    return rays.reshape(*shape, 3).astype(np.float32), valid.reshape(shape)


def _pinhole_rays(camera: CameraSpec, pix: np.ndarray) -> np.ndarray:
    dist = np.asarray((tuple(camera.distortion) + (0.0,) * 5)[:5], dtype=np.float64)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-12)
    und = cv2.undistortPoints(pix.reshape(-1, 1, 2), camera.camera_matrix, dist,
                              None, None, None, criteria).reshape(-1, 2)
    rays = np.column_stack([und, np.ones(len(und))])
    return rays / np.linalg.norm(rays, axis=1, keepdims=True)


def _fisheye_rays(camera: CameraSpec, pix: np.ndarray) -> np.ndarray:
    fx, fy, cx, cy = camera.intrinsics
    k1, k2, k3, k4 = camera.distortion[:4]
    xd, yd = (pix[:, 0] - cx) / fx, (pix[:, 1] - cy) / fy
    theta_d = np.hypot(xd, yd)
    theta = theta_d.copy()
    for _ in range(30):  # Newton on theta_d = theta * (1 + k1 t^2 + ... + k4 t^8)
        t2 = theta * theta
        f = theta * (1 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))) - theta_d
        df = 1 + t2 * (3 * k1 + t2 * (5 * k2 + t2 * (7 * k3 + t2 * 9 * k4)))
        theta = theta - f / df
    phi = np.arctan2(yd, xd)
    s = np.sin(theta)
    rays = np.column_stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)])
    rays[(theta < 0) | (theta > np.pi)] = np.nan
    return rays
