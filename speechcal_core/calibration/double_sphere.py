"""Double-sphere camera model (Usenko et al. 2018): projection and a Levenberg-Marquardt fit."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.optimize import least_squares
from scipy.special import expit

from speechcal_core.calibration.views import CalibrationResult, View, view_errors

#: the joint fit uses at most this many views and points per view; every view's error is
#: then measured on all its points with the fitted intrinsics. Three wide 1280 x 720
#: lenses with 95-103 views each: 30 views of 48 points took 1.6, 11.1 and 0.9 s, these
#: 0.9, 1.6 and 0.6 s, the RMS at most 0.003 px higher
FIT_VIEWS = 15
FIT_POINTS = 32
#: the joint fit stops once a step lowers the cost by less than this fraction of it. On
#: lenses of modest width fx and xi trade against each other along a valley of equal
#: cost, and the solver crept along it for all its 200 evaluations (1.6 s); stopping
#: here left the RMS the same to 0.0001 px on five synthetic wide lenses and took
#: 10-40 % off the three models' fit of 104-108 views
FIT_FTOL = 1e-5
_STEP = 1e-6


def project_double_sphere(params: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Project N x 3 camera-frame points with ``params`` = fx, fy, cx, cy, xi, alpha."""
    fx, fy, cx, cy, xi, alpha = params
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    d1 = np.sqrt(x * x + y * y + z * z)
    zz = xi * d1 + z
    d2 = np.sqrt(x * x + y * y + zz * zz)
    den = alpha * d2 + (1.0 - alpha) * zz
    den = np.where(np.abs(den) < 1e-12, 1e-12, den)
    return np.stack([fx * x / den + cx, fy * y / den + cy], axis=1)


def rotate(rvecs: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Rotate ``points`` (N x 3) by Rodrigues vectors ``rvecs`` (N x 3), row by row."""
    theta = np.linalg.norm(rvecs, axis=1, keepdims=True)
    safe = np.where(theta < 1e-12, 1.0, theta)
    k = rvecs / safe
    cos, sin = np.cos(theta), np.sin(theta)
    cross = np.cross(k, points)
    dot = np.sum(k * points, axis=1, keepdims=True)
    return points * cos + cross * sin + k * dot * (1.0 - cos)


def model_intrinsics(free: np.ndarray) -> np.ndarray:
    """fx, fy, cx, cy, xi, alpha from the solver's free parameters, which hold xi as
    atanh(xi) and alpha as its logit: the model is valid for xi in (-1, 1) and alpha in
    (0, 1), and on a lens a pinhole fits well, unbounded they wander far outside (xi 8,
    alpha -22) while the reprojection error hardly changes, or take 200 evaluations
    without converging (11 s for 99 views of 1280 x 720)."""
    fx, fy, cx, cy, u, v = free
    return np.array([fx, fy, cx, cy, np.tanh(u), expit(v)])


def _problem(views: Sequence[View], intr: np.ndarray | None) -> tuple[
        Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], np.ndarray], list[int]]:
    """Residual and Jacobian functions over ``[intrinsics (6, unless fixed)] + poses``.

    Each view's pose only moves its own residuals, so one perturbation of parameter j of
    every pose at once gives all their Jacobian columns: 6 + 6 evaluations per Jacobian.
    """
    n = len(views)
    counts = [v.object_points.shape[0] for v in views]
    obj = np.concatenate([v.object_points for v in views]).astype(np.float64)
    img = np.concatenate([v.image_points for v in views]).astype(np.float64)
    owner = np.repeat(np.arange(n), counts)
    n_intr = 6 if intr is None else 0

    def residuals(p: np.ndarray) -> np.ndarray:
        params = model_intrinsics(p[:6]) if intr is None else intr
        poses = p[n_intr:].reshape(n, 6)
        cam = rotate(poses[owner, :3], obj) + poses[owner, 3:]
        return (project_double_sphere(params, cam) - img).ravel()

    rows = np.repeat(owner, 2)

    def jacobian(p: np.ndarray) -> np.ndarray:
        base = residuals(p)
        jac = np.zeros((base.size, p.size))
        for j in range(n_intr):
            q = p.copy()
            h = _STEP * max(1.0, abs(q[j]))
            q[j] += h
            jac[:, j] = (residuals(q) - base) / h
        for j in range(6):
            q = p.copy()
            cols = n_intr + 6 * np.arange(n) + j
            h = _STEP * np.maximum(1.0, np.abs(q[cols]))
            q[cols] += h
            jac[np.arange(base.size), n_intr + 6 * rows + j] = (residuals(q) - base) / h[rows]
        return jac

    return residuals, jacobian, counts


def calibrate_double_sphere(views: Sequence[View], start: CalibrationResult) -> CalibrationResult:
    """Fit fx, fy, cx, cy, xi, alpha and every view's pose, starting from ``start``.

    ``start`` is a pinhole or fisheye fit of the same views: its focal length, principal
    point and poses seed the solver (xi = 0, alpha = 0.5 agrees with them near the axis).
    Levenberg-Marquardt on a subset of views and points fits the intrinsics; then every
    view's pose is refined on all its points to give its reprojection error.
    """
    n = len(views)
    poses0 = [np.concatenate([np.ravel(r), np.ravel(t)]).astype(np.float64)
              for r, t in zip(start.rvecs, start.tvecs, strict=True)]
    pick = np.unique(np.linspace(0, n - 1, min(n, FIT_VIEWS)).round().astype(int))
    sub = []
    for k in pick:
        v = views[k]
        m = v.object_points.shape[0]
        keep = np.unique(np.linspace(0, m - 1, min(m, FIT_POINTS)).round().astype(int))
        sub.append(View(v.set_id, v.object_points[keep], v.image_points[keep]))
    res_fn, jac_fn, _ = _problem(sub, None)
    x0 = np.concatenate([np.asarray(start.intrinsics[:4], np.float64),
                         [0.0, 0.0],  # xi = 0, alpha = 0.5
                         *[poses0[k] for k in pick]])
    fit = least_squares(res_fn, x0, jac=jac_fn, method="lm", x_scale="jac", max_nfev=200,
                        ftol=FIT_FTOL)
    intr = model_intrinsics(fit.x[:6])
    residuals_all, poses = [], []
    for k, v in enumerate(views):
        r_fn, j_fn, _ = _problem([v], intr)
        one = least_squares(r_fn, poses0[k], jac=j_fn, method="lm", max_nfev=50)
        residuals_all.append(r_fn(one.x).reshape(-1, 2))
        poses.append(one.x)
    rms, per_view = view_errors(residuals_all)
    return CalibrationResult("double-sphere", intr.tolist(), [], rms, per_view,
                             [v.set_id for v in views], [p[:3] for p in poses],
                             [p[3:] for p in poses])
