"""Calibration check per camera: pinhole, fisheye and double-sphere fits over the kept sets."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import cv2
import numpy as np

from speechcal_core.calibration.double_sphere import calibrate_double_sphere, project_double_sphere
from speechcal_core.calibration.fisheye import calibrate_fisheye
from speechcal_core.calibration.pinhole import calibrate_pinhole
from speechcal_core.calibration.views import CalibrationResult, View
from speechcal_core.processes import usable_cores

MODELS = ("pinhole", "fisheye", "double-sphere")
#: with ``wide_only`` the fisheye and double-sphere fits run only for lenses whose pinhole
#: fit shows more than this horizontal field of view (degrees), or cannot reach the image's
#: corners (its fx alone says 90 degrees for an equidistant lens of 115-120)
WIDE_FOV_DEG = 80.0
MIN_VIEWS = 4
MIN_POINTS = 12
#: the simplest model wins unless another one's RMS is lower by more than this factor
SIMPLER_SLACK = 1.15
#: a lens wider than this across the diagonal (degrees, by its fisheye fit) gets a fisheye
#: model, as OpenCV (cv2.fisheye) and Kalibr (pinhole-equi) fit such lenses; the synthetic
#: fisheyes are about 125-155, their pinholes 57-72
FISHEYE_DIAG_DEG = 120.0
#: a pinhole fit whose k3 folds it back inside the image is fitted again with k3 at zero,
#: kept when its RMS is within this factor of the free fit's: a board seen near the middle
#: of a plain lens pins k1 and k2, while k3 (its sixth power of the radius) fitted freely
#: came out large enough to turn a 90-degree pinhole back before its corners, and the
#: check then gave it a fisheye model
PLAIN_K3_SLACK = 1.02


def fit_models(
    views: Sequence[View],
    size: tuple[int, int],
    models: Iterable[str] = MODELS,
    wide_only: bool = False,
) -> dict[str, CalibrationResult]:
    """Every model of ``models`` that converges on the views (a failing model is left out).

    ``wide_only``: fit fisheye and double sphere only when the pinhole fit shows a field
    of view wider than ``WIDE_FOV_DEG`` (or fails).
    """
    models = tuple(models)
    out: dict[str, CalibrationResult] = {}
    views = [v for v in views if v.object_points.shape[0] >= MIN_POINTS]
    if len(views) < MIN_VIEWS:
        return out
    if "pinhole" in models or "double-sphere" in models:
        with contextlib.suppress(cv2.error):
            out["pinhole"] = calibrate_pinhole(views, size)
        if "pinhole" in out and not reaches_corners(out["pinhole"], size):
            with contextlib.suppress(cv2.error):
                plain = calibrate_pinhole(views, size, fix_k3=True)
                if plain.rms_px <= out["pinhole"].rms_px * PLAIN_K3_SLACK:
                    out["pinhole"] = plain
    if wide_only and "pinhole" in out:
        fov = 2 * np.degrees(np.arctan2(size[0] / 2, out["pinhole"].intrinsics[0]))
        if fov <= WIDE_FOV_DEG and reaches_corners(out["pinhole"], size):
            models = tuple(m for m in models if m == "pinhole")
    if "fisheye" in models or "double-sphere" in models:
        guess = None
        if "pinhole" in out:
            fx, fy, cx, cy = out["pinhole"].intrinsics
            guess = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], np.float64)
        try:
            out["fisheye"] = calibrate_fisheye(views, size, guess)
        except cv2.error:
            # a bad pinhole start can spoil the fisheye initialisation
            with contextlib.suppress(cv2.error):
                out["fisheye"] = calibrate_fisheye(views, size, None)
    if "double-sphere" in models:
        seeds = [out[m] for m in ("fisheye", "pinhole") if m in out]
        if seeds:
            start = min(seeds, key=lambda r: r.rms_px)
            ds = calibrate_double_sphere(views, start)
            if np.isfinite(ds.rms_px):
                out["double-sphere"] = ds
    return {m: out[m] for m in MODELS if m in out and m in models}


def corner_angles(fit: CalibrationResult, size: tuple[int, int]) -> np.ndarray | None:
    """Angles (degrees off the axis) of the rays the fitted model gives the image's four
    corners (top left, top right, bottom left, bottom right); None when it gives one none.

    Rays ever further off the axis, towards each corner, must land ever further out until
    they pass that corner: a model that turns back before leaves the image's rim without
    rays however well it fits the board near the middle (a radial-tangential pinhole
    fitted to a synthetic 150-degree fisheye turned back 56 degrees off the axis, 300 px
    from the centre of a 640 x 480 image).
    """
    fx, fy, cx, cy = (float(v) for v in fit.intrinsics[:4])
    w, h = size
    last = 89.5 if fit.model == "pinhole" else 179.5  # a pinhole sees less than 180 degrees
    theta = np.linspace(0.0, last, 720)
    out = []
    for u, v in ((0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)):
        phi = np.arctan2((v - cy) / fy, (u - cx) / fx)
        t = np.radians(theta)
        rays = np.column_stack([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)])
        radius = np.hypot(*(_project(fit, rays) - (cx, cy)).T)
        corner = np.hypot(u - cx, v - cy)
        beyond = np.flatnonzero(~(radius < corner))  # NaN counts too
        if beyond.size == 0 or beyond[0] == 0:
            return None
        j = int(beyond[0])
        if not np.all(np.diff(radius[: j + 1]) > 0):
            return None
        out.append(np.interp(corner, radius[j - 1 : j + 1], theta[j - 1 : j + 1]))
    return np.asarray(out)


def reaches_corners(fit: CalibrationResult, size: tuple[int, int]) -> bool:
    """Whether the fitted lens model gives every pixel of the image a ray (see
    :func:`corner_angles`)."""
    return corner_angles(fit, size) is not None


def diagonal_fov(fit: CalibrationResult, size: tuple[int, int]) -> float | None:
    """The field of view (degrees) across the image's wider diagonal by the fitted model;
    None when the model does not reach the corners."""
    a = corner_angles(fit, size)
    return None if a is None else float(max(a[0] + a[3], a[1] + a[2]))


def _project(fit: CalibrationResult, rays: np.ndarray) -> np.ndarray:
    """Pixels of camera-frame ``rays`` (N x 3) through a fitted model."""
    fx, fy, cx, cy = fit.intrinsics[:4]
    if fit.model == "double-sphere":
        return project_double_sphere(np.asarray(fit.intrinsics, np.float64), rays)
    k = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], np.float64)
    d = np.asarray(fit.distortion, np.float64)
    with np.errstate(all="ignore"):
        if fit.model == "fisheye":
            px, _ = cv2.fisheye.projectPoints(rays.reshape(-1, 1, 3), np.zeros(3), np.zeros(3),
                                              k, d)
        else:
            px, _ = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), k, d)
    return px.reshape(-1, 2)


def best_model(results: Mapping[str, CalibrationResult],
               size: tuple[int, int] | None = None) -> CalibrationResult | None:
    """The simplest model whose RMS is within ``SIMPLER_SLACK`` of the lowest.

    With the image ``size`` given, that is among the models that give every pixel a ray
    (:func:`reaches_corners`; others only when none does), and a lens wider than
    ``FISHEYE_DIAG_DEG`` by its fisheye or double-sphere fit gets one of those: seen near
    the middle, as a board held for a rig's pinholes shows it, a fisheye fits a pinhole's
    five coefficients as closely as its own model, yet that pinhole says nothing true of
    the rim (it folds back inside the image, or stops short of 90 degrees).
    """
    if not results:
        return None
    lowest = min(r.rms_px for r in results.values())
    pools: list[Mapping[str, CalibrationResult]] = [results]
    if size is not None:
        whole = {m: r for m, r in results.items() if reaches_corners(r, size)}
        wide = next((diagonal_fov(whole[m], size) for m in ("fisheye", "double-sphere")
                     if m in whole), None)
        if wide is not None and wide > FISHEYE_DIAG_DEG:
            whole.pop("pinhole", None)
        pools.insert(0, whole)
    for pool in pools:
        for name in MODELS:
            if name in pool and pool[name].rms_px <= lowest * SIMPLER_SLACK:
                return pool[name]
    return min(results.values(), key=lambda r: r.rms_px)


def calibration_entry(results: Mapping[str, CalibrationResult],
                      size: tuple[int, int] | None = None) -> dict[str, Any] | None:
    """The session's ``"calibration"`` entry of one stream: the best model on top, all fits
    under ``"models"`` so a bad set stands out in every one of them. With the image
    ``size``, each fit also says whether it gives every pixel a ray (``"whole_image"``)."""
    best = best_model(results, size)
    if best is None:
        return None
    models = {m: r.to_dict() for m, r in results.items()}
    if size is not None:
        for m, r in results.items():
            models[m]["whole_image"] = reaches_corners(r, size)
    return {**best.to_dict(), "models": models}


def check_cameras(
    views: Mapping[str, Sequence[View]],
    sizes: Mapping[str, tuple[int, int]],
    models: Iterable[str] = MODELS,
    progress: Callable[[str, float], None] | None = None,
    wide_only: bool = False,
) -> dict[str, dict[str, Any]]:
    """``{"<stream>": entry}`` for every stream with enough views (others are left out).

    Cameras are fitted in parallel threads (OpenCV and MINPACK release the GIL).
    ``progress`` is called before and after each camera's fits; when it raises (the
    operator cancelled, or the check is for frames that have changed), no further camera
    is fitted and the exception propagates once the fits already running have ended.
    """
    models = tuple(models)
    names = [s for s in views if s in sizes]
    done = [0]

    def one(stream: str) -> dict[str, Any] | None:
        if progress:
            progress("calibration", done[0] / max(1, len(names)))
        entry = calibration_entry(fit_models(views[stream], sizes[stream], models, wide_only),
                                  sizes[stream])
        done[0] += 1
        if progress:
            progress("calibration", done[0] / max(1, len(names)))
        return entry

    pool = ThreadPoolExecutor(max_workers=min(4, usable_cores()))
    try:
        entries = list(pool.map(one, names))
    finally:
        pool.shutdown(cancel_futures=True)
    return {s: e for s, e in zip(names, entries, strict=True) if e is not None}
