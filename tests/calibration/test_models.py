"""Calibration check: pinhole recovers intrinsics, fisheye and double sphere converge."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest
from calib_views import pinhole_views, synthetic_views

from speechcal_core.calibration import fisheye
from speechcal_core.calibration.check import (
    SIMPLER_SLACK,
    best_model,
    calibration_entry,
    corner_angles,
    fit_models,
)
from speechcal_core.calibration.double_sphere import project_double_sphere
from speechcal_core.calibration.views import CalibrationResult, View
from speechcal_core.synth.camera_model import project_points
from speechcal_core.target import TargetSpec


def _relative_error(found: list[float], truth: tuple[float, ...]) -> np.ndarray:
    return np.abs(np.asarray(found[:4]) - np.asarray(truth)) / np.asarray(truth)


def test_pinhole_recovers_intrinsics_within_one_percent() -> None:
    cam, views = synthetic_views(fisheye=False)
    fits = fit_models(views, (cam.width, cam.height), ("pinhole",))
    pin = fits["pinhole"]
    assert _relative_error(pin.intrinsics, cam.intrinsics).max() < 0.01
    assert pin.rms_px < 0.5
    assert len(pin.distortion) == 5


def test_fisheye_and_double_sphere_converge_on_a_fisheye_camera() -> None:
    cam, views = synthetic_views(fisheye=True)
    fits = fit_models(views, (cam.width, cam.height))
    assert fits["fisheye"].rms_px < 0.5
    assert _relative_error(fits["fisheye"].intrinsics, cam.intrinsics).max() < 0.01
    ds = fits["double-sphere"]
    assert ds.rms_px < 0.5
    fx, _fy, cx, cy, xi, _alpha = ds.intrinsics
    # near the axis the double sphere acts like a pinhole of focal fx / (1 + xi)
    assert abs(fx / (1 + xi) - cam.intrinsics[0]) / cam.intrinsics[0] < 0.02
    assert abs(cx - cam.intrinsics[2]) < 5 and abs(cy - cam.intrinsics[3]) < 5


def test_double_sphere_parameters_stay_where_the_model_is_valid() -> None:
    """xi in (-1, 1), alpha in (0, 1): unbounded, this lens's fit wandered to xi 2.5 at
    the same error (and slower fits elsewhere took 200 evaluations)."""
    cam, views = synthetic_views(fisheye=True, seed=1, holds=40)
    fits = fit_models(views, (cam.width, cam.height))
    _fx, _fy, _cx, _cy, xi, alpha = fits["double-sphere"].intrinsics
    assert -1 < xi < 1 and 0 < alpha < 1
    assert fits["double-sphere"].rms_px < 1.05 * fits["fisheye"].rms_px


def test_a_bad_view_stands_out_in_per_view_error() -> None:
    cam, views = synthetic_views(fisheye=False, holds=10)
    bad = views[3]
    shuffled = bad.image_points.copy()
    shuffled[:8] += 6.0  # eight corners off by 6 px (e.g. a mis-detected tag)
    views[3] = View(bad.set_id, bad.object_points, shuffled)
    pin = fit_models(views, (cam.width, cam.height), ("pinhole",))["pinhole"]
    worst = int(np.argmax(pin.view_rms_px))
    assert pin.set_ids[worst] == bad.set_id
    assert pin.view_rms_px[worst] > 3 * np.median(pin.view_rms_px)


def test_double_sphere_projection_matches_the_paper_on_axis_and_off() -> None:
    params = np.array([300.0, 310.0, 320.0, 240.0, 0.0, 0.5])
    # xi = 0, alpha = 0.5: u = fx * x / ((|p| + z) / 2) + cx
    pts = np.array([[0.0, 0.0, 1.0], [0.3, -0.2, 1.0]])
    uv = project_double_sphere(params, pts)
    assert np.allclose(uv[0], [320, 240])
    d = np.linalg.norm(pts[1])
    assert np.allclose(uv[1], [300 * 0.3 / ((d + 1) / 2) + 320, 310 * -0.2 / ((d + 1) / 2) + 240])


def test_calibration_entry_has_design_keys_and_all_models() -> None:
    cam, views = synthetic_views(fisheye=False, holds=8)
    size = (cam.width, cam.height)
    fits = fit_models(views, size, ("pinhole", "fisheye"))
    entry = calibration_entry(fits, size)
    assert entry is not None
    assert {"model", "intrinsics", "distortion", "rms_px", "views", "models"} <= set(entry)
    assert entry["model"] == best_model(fits, size).model == best_model(fits).model == "pinhole"
    assert entry["models"]["pinhole"]["whole_image"] is True
    assert [v["set"] for v in entry["views"]] == [v.set_id for v in views]


def test_a_fisheye_seen_near_the_middle_gets_the_fisheye_model() -> None:
    """The board held for a rig's pinholes stays within about 35 degrees of a 130-degree
    lens's axis: a pinhole fits it as closely (it was chosen, the simpler model), and the
    fisheye fit's k3, k4 were free to put the image's corners hundreds of pixels off. The
    check gives the fisheye model, k1 and k2 only, whose rays reach the corners where the
    lens shows them."""
    cam, views = synthetic_views(fisheye=True, seed=2)
    size = (cam.width, cam.height)
    fits = fit_models(views, size, wide_only=True)
    assert fits["pinhole"].rms_px <= fits["fisheye"].rms_px * SIMPLER_SLACK
    entry = calibration_entry(fits, size)
    assert entry["model"] == "fisheye"
    # its pinhole (k3 at zero where a free k3 folds it) may reach the corners, but says
    # 105 degrees across the diagonal where the fisheye fit says 133: wider than 120
    assert entry["models"]["fisheye"]["whole_image"] is True
    assert _relative_error(entry["intrinsics"], cam.intrinsics).max() < 0.01
    assert entry["distortion"][2:] == [0.0, 0.0]
    # the rays the true lens gives the image's corners (69 degrees off the axis) land on
    # them, give or take 15 px
    corners = np.array([[0, 0], [cam.width - 1, 0], [0, cam.height - 1],
                        [cam.width - 1, cam.height - 1]], np.float64)
    xy = cv2.fisheye.undistortPoints(corners.reshape(-1, 1, 2), cam.camera_matrix,
                                     np.asarray(cam.distortion)).reshape(-1, 2)
    rays = np.column_stack([xy, np.ones(4)])
    assert project_points(cam, rays) == pytest.approx(corners, abs=0.01)
    fit = fits["fisheye"]
    found = project_points(replace(cam, intrinsics=tuple(fit.intrinsics),
                                   distortion=tuple(fit.distortion)), rays)
    assert np.hypot(*(found - corners).T).max() < 15


def test_corner_angles_follow_the_lens_model_and_stop_at_a_fold() -> None:
    size = (640, 480)
    equidistant = CalibrationResult("fisheye", [320.0, 320.0, 320.0, 240.0],
                                    [0.0] * 4, 0.1, [], [])
    # equidistant: angle = radius / f, 400 px from the centre
    assert np.allclose(corner_angles(equidistant, size), np.degrees(400 / 320), atol=0.3)
    # a strong barrel turns back at r = 1, 213 px out: the corners 400 px out get no ray
    barrel = CalibrationResult("pinhole", [320.0, 320.0, 320.0, 240.0],
                               [-1 / 3, 0.0, 0.0, 0.0, 0.0], 0.1, [], [])
    assert corner_angles(barrel, size) is None
    plain = CalibrationResult("pinhole", [320.0, 320.0, 320.0, 240.0], [0.0] * 5, 0.1, [], [])
    assert np.allclose(corner_angles(plain, size), np.degrees(np.arctan(400 / 320)), atol=0.3)


def test_too_few_views_give_no_fit() -> None:
    cam, views = synthetic_views(fisheye=False, holds=3)
    assert fit_models(views[:3], (cam.width, cam.height)) == {}


def test_wide_only_fits_fisheye_models_to_wide_lenses_only() -> None:
    cam, views = synthetic_views(fisheye=False, holds=8)
    assert set(fit_models(views, (cam.width, cam.height), wide_only=True)) == {"pinhole"}
    cam, views = synthetic_views(fisheye=True, holds=8)
    wide = fit_models(views, (cam.width, cam.height), wide_only=True)
    assert set(wide) == {"pinhole", "fisheye", "double-sphere"}


def test_fisheye_on_many_views_fits_a_subset_and_poses_every_view(monkeypatch) -> None:
    """Over ``FIT_VIEWS`` views the intrinsics come from a spread subset (the joint fit of
    108 views took 1.5 s): every view still gets its pose and error, as a joint fit of
    all views gives them, and a bad view stands out as before."""
    cam, views = synthetic_views(fisheye=True, seed=1, holds=100)
    rng = np.random.default_rng(0)
    many = [View(k, v.object_points, v.image_points + rng.normal(0, 0.1, v.image_points.shape))
            for k, v in enumerate(views * 3)]
    assert len(many) > fisheye.FIT_VIEWS
    off = many[40].image_points.copy()
    off[:8] += 6.0  # eight corners off by 6 px (e.g. a mis-detected tag)
    many[40] = View(40, many[40].object_points, off)
    size = (cam.width, cam.height)
    fit = fisheye.calibrate_fisheye(many, size)
    assert fit.set_ids == [v.set_id for v in many] and len(fit.rvecs) == len(many)
    assert _relative_error(fit.intrinsics, cam.intrinsics).max() < 0.01
    monkeypatch.setattr(fisheye, "FIT_VIEWS", len(many))  # one joint fit of every view
    whole = fisheye.calibrate_fisheye(many, size)
    assert fit.rms_px == pytest.approx(whole.rms_px, abs=0.002)
    assert np.allclose(fit.view_rms_px, whole.view_rms_px, atol=0.01)
    assert int(np.argmax(fit.view_rms_px)) == 40


def test_fisheye_fits_k3_and_k4_where_the_views_show_them() -> None:
    """A lens whose k3 and k4 bend it by tens of pixels, seen all over the image: k1 and k2
    alone fit 4 % worse, and all four are fitted."""
    cam, _views = synthetic_views(fisheye=True, seed=2, holds=1)
    cam = replace(cam, distortion=(0.0, 0.05, -0.1, 0.05))
    size = (cam.width, cam.height)
    obj = TargetSpec().object_points()
    centred = obj - obj.mean(axis=0)
    rng = np.random.default_rng(5)
    views = []
    while len(views) < 16:
        angle = np.radians(rng.uniform(0, 40))  # the board's centre this far off the axis
        phi = rng.uniform(-np.pi, np.pi)
        direction = np.array([np.sin(angle) * np.cos(phi), np.sin(angle) * np.sin(phi),
                              np.cos(angle)])
        rot, _ = cv2.Rodrigues(rng.uniform(-0.4, 0.4, 3))
        pts = (rot @ centred.T).T + 0.5 * direction
        px = project_points(cam, pts)
        if (px > 0).all() and (px < size).all():
            views.append(View(len(views), obj, px + rng.normal(0, 0.1, px.shape)))
    fit = fit_models(views, size, ("fisheye",))["fisheye"]
    assert fit.distortion == pytest.approx(cam.distortion, abs=0.01)
    assert fit.rms_px < 0.2


def test_a_plain_wide_pinhole_seen_near_the_middle_keeps_the_pinhole_model() -> None:
    """A 90-degree pinhole (102 across the diagonal) seen near the middle: its free k3
    folded the pinhole back before the image's corners, and the check gave a fisheye
    model. Fitted again with k3 at zero (as close), the pinhole reaches the corners."""
    cam, views = pinhole_views(90.0, (640, 480), (0.0,) * 5)
    size = (cam.width, cam.height)
    entry = calibration_entry(fit_models(views, size, wide_only=True), size)
    assert entry["model"] == "pinhole"
    assert entry["models"]["pinhole"]["whole_image"] is True
    assert entry["distortion"][4] == 0.0
    assert _relative_error(entry["intrinsics"], cam.intrinsics).max() < 0.01
