"""Calibration check per camera: pinhole, fisheye and double-sphere fits over the kept sets."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import cv2
import numpy as np

from speechcal_core.calibration.double_sphere import calibrate_double_sphere
from speechcal_core.calibration.fisheye import calibrate_fisheye
from speechcal_core.calibration.pinhole import calibrate_pinhole
from speechcal_core.calibration.views import CalibrationResult, View
from speechcal_core.processes import usable_cores

MODELS = ("pinhole", "fisheye", "double-sphere")
#: with ``wide_only`` the fisheye and double-sphere fits run only for lenses whose pinhole
#: fit shows more than this horizontal field of view (degrees)
WIDE_FOV_DEG = 80.0
MIN_VIEWS = 4
MIN_POINTS = 12
#: the simplest model wins unless another one's RMS is lower by more than this factor
SIMPLER_SLACK = 1.15


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
    if wide_only and "pinhole" in out:
        fov = 2 * np.degrees(np.arctan2(size[0] / 2, out["pinhole"].intrinsics[0]))
        if fov <= WIDE_FOV_DEG:
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


def best_model(results: Mapping[str, CalibrationResult]) -> CalibrationResult | None:
    """The simplest model whose RMS is within ``SIMPLER_SLACK`` of the lowest."""
    if not results:
        return None
    lowest = min(r.rms_px for r in results.values())
    for name in MODELS:
        if name in results and results[name].rms_px <= lowest * SIMPLER_SLACK:
            return results[name]
    return min(results.values(), key=lambda r: r.rms_px)


def calibration_entry(results: Mapping[str, CalibrationResult]) -> dict[str, Any] | None:
    """The session's ``"calibration"`` entry of one stream: the best model on top, all fits
    under ``"models"`` so a bad set stands out in every one of them."""
    best = best_model(results)
    if best is None:
        return None
    return {**best.to_dict(), "models": {m: r.to_dict() for m, r in results.items()}}


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
        entry = calibration_entry(fit_models(views[stream], sizes[stream], models, wide_only))
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
