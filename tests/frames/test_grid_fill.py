"""Filling in AprilGrid tags the marker detector missed: found where they are, never invented."""

from __future__ import annotations

import cv2
import numpy as np
import pytest
from board_images import facing_pose, render_view

from speechcal_core.frames.detect import TargetDetector
from speechcal_core.frames.grid_fill import fill_missing_tags
from speechcal_core.synth.camera_model import project_points
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.render import render_frame, renderer_for
from speechcal_core.synth.timeline import plan_session
from speechcal_core.target import TargetSpec

K = np.array([[600.0, 0, 322], [0, 600, 238], [0, 0, 1]])
TARGET = TargetSpec()


POSE = facing_pose(TARGET, 0.7, (0.3, -0.2), (0.02, 0.01), 0.2)


def _pinhole_view() -> np.ndarray:
    return render_view(TARGET, K, *POSE, (640, 480))


def _fill(gray: np.ndarray, points: np.ndarray, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    detector = TargetDetector(TARGET)
    return fill_missing_tags(gray, points, ids, TARGET.object_points(), TARGET.pitch,
                             detector._dictionary, 2.0)


def _tags(ids: np.ndarray) -> set[int]:
    return set((ids // 4).tolist())


def test_found_tags_grow_into_the_whole_grid_on_the_true_corners() -> None:
    gray = _pinhole_view()
    full = TargetDetector(TARGET).detect(gray)
    assert full is not None and full.count == 144
    keep = np.isin(full.ids // 4, [14, 15])  # two neighbours in the middle of the board
    points, ids = _fill(gray, full.points[keep], full.ids[keep])
    assert _tags(ids) == set(range(36))
    truth, _ = cv2.projectPoints(TARGET.object_points()[ids], *POSE, K, None)
    assert np.linalg.norm(truth.reshape(-1, 2) - points, axis=1).max() < 0.3


@pytest.mark.parametrize("cover", ["blank", "another tag", "itself turned", "itself mirrored"])
def test_a_covered_tag_is_not_filled_in(cover: str) -> None:
    gray = _pinhole_view()
    full = TargetDetector(TARGET).detect(gray)
    assert full is not None
    quad = full.points[full.ids // 4 == 21][np.argsort(full.ids[full.ids // 4 == 21])]
    if cover == "blank":  # a sticker over the tag: light paper where its code was
        centre = quad.mean(axis=0)
        cv2.fillConvexPoly(gray, np.round(centre + 0.8 * (quad - centre)).astype(np.int32),
                           200)
    else:  # the same black border carrying another code, or its own code the wrong way
        d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
        tag = 35 if cover == "another tag" else 21
        other = cv2.aruco.generateImageMarker(d, tag, 100, borderBits=2)[::-1, ::-1]
        if cover == "itself turned":
            other = np.ascontiguousarray(np.rot90(other))
        elif cover == "itself mirrored":
            other = np.ascontiguousarray(other[:, ::-1])
        src = np.float32([[0, 100], [100, 100], [100, 0], [0, 0]])  # Kalibr corner order
        warp = cv2.getPerspectiveTransform(src, quad.astype(np.float32))
        patch = cv2.warpPerspective(other, warp, gray.shape[::-1], flags=cv2.INTER_AREA)
        inside = cv2.warpPerspective(np.full_like(other, 255), warp, gray.shape[::-1]) > 0
        gray[inside] = patch[inside] * 0.8 + 20
    rest = full.ids // 4 != 21
    _, ids = _fill(gray, full.points[rest], full.ids[rest])
    assert _tags(ids) == set(range(36)) - {21}


def test_fisheye_board_at_the_edge_is_found_whole_and_on_the_true_corners() -> None:
    # the marker detector alone found 72 of these 144 corners (the tags are ~20 px)
    timeline = plan_session(SynthOptions(cameras=1, fisheye=1, duration=12, seed=0))
    hold = timeline.holds[1]
    t = (hold.start_ns + hold.end_ns) // 2
    det = TargetDetector(timeline.target).detect(render_frame(timeline, 0, t))
    assert det is not None and det.count == 144
    renderer = renderer_for(timeline)
    rot, trans = renderer._target_in_camera(renderer._state(0), t)
    truth = project_points(timeline.cameras[0],
                           (rot @ timeline.target.object_points()[det.ids].T).T + trans)
    err = np.linalg.norm(truth - det.points, axis=1)
    assert err.mean() < 0.2 and err.max() < 1.0


def test_one_found_tag_is_enough_to_find_the_rest() -> None:
    gray = _pinhole_view()
    full = TargetDetector(TARGET).detect(gray)
    assert full is not None
    keep = full.ids // 4 == 0  # a corner tag: its neighbours lie on one side only
    points, ids = _fill(gray, full.points[keep], full.ids[keep])
    assert _tags(ids) == set(range(36))
    truth, _ = cv2.projectPoints(TARGET.object_points()[ids], *POSE, K, None)
    assert np.linalg.norm(truth.reshape(-1, 2) - points, axis=1).max() < 0.3
