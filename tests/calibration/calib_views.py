"""Exact projections of a target through the synthetic cameras, plus noise, as views."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from speechcal_core.calibration.views import View
from speechcal_core.synth.camera_model import project_points
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import CameraSpec, plan_session


def synthetic_views(fisheye: bool, seed: int = 4, noise_px: float = 0.1,
                    holds: int = 18) -> tuple[CameraSpec, list[View]]:
    """One camera of a synthetic session and its views of every hold (noisy corners)."""
    timeline = plan_session(SynthOptions(cameras=1, fisheye=int(fisheye), duration=80,
                                         seed=seed, width=1280, height=720))
    cam = timeline.cameras[0]
    rot_rig, trans_rig = np.array(cam.rotation_rig), np.array(cam.translation_rig)
    obj = timeline.target.object_points()
    rng = np.random.default_rng(seed)
    views = []
    for k, hold in enumerate(timeline.holds[:holds]):
        rot, trans = timeline.pose_at(hold.start_ns)
        pts = (rot_rig @ (rot @ obj.T + trans[:, None])).T + trans_rig
        px = project_points(cam, pts)
        ok = (px[:, 0] > 0) & (px[:, 0] < cam.width) & (px[:, 1] > 0) & (px[:, 1] < cam.height)
        if ok.sum() >= 20:
            views.append(View(k + 1, obj[ok], px[ok] + rng.normal(0, noise_px, (ok.sum(), 2))))
    return cam, views


def pinhole_views(hfov_deg: float, size: tuple[int, int], distortion: tuple[float, ...],
                  seed: int = 4) -> tuple[CameraSpec, list[View]]:
    """A pinhole camera of ``hfov_deg`` across ``size`` with ``distortion`` (OpenCV's five)
    put in place of a synthetic session's first camera, and its views of 18 holds: the
    board stays near the image's middle, as held for a rig."""
    w, h = size
    timeline = plan_session(SynthOptions(cameras=1, duration=80, seed=seed, width=w,
                                         height=h))
    fx = (w / 2) / np.tan(np.radians(hfov_deg / 2))
    cam = replace(timeline.cameras[0], width=w, height=h,
                  intrinsics=(fx, fx, w / 2 - 0.5, h / 2 - 0.5), distortion=distortion)
    rot_rig, trans_rig = np.array(cam.rotation_rig), np.array(cam.translation_rig)
    obj = timeline.target.object_points()
    rng = np.random.default_rng(seed)
    views = []
    for k, hold in enumerate(timeline.holds[:18]):
        rot, trans = timeline.pose_at(hold.start_ns)
        pts = (rot_rig @ (rot @ obj.T + trans[:, None])).T + trans_rig
        px = project_points(cam, pts)
        ok = ((px[:, 0] > 0) & (px[:, 0] < w) & (px[:, 1] > 0) & (px[:, 1] < h)
              & (pts[:, 2] > 0))
        if ok.sum() >= 20:
            views.append(View(k + 1, obj[ok], px[ok] + rng.normal(0, 0.1, (ok.sum(), 2))))
    return cam, views
