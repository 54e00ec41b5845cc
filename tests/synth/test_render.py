"""Rendered synthetic frames: detectable targets where the truth says, blur, clap, scenery."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from speechcal_core.frames.detect import TargetDetector
from speechcal_core.synth import scene
from speechcal_core.synth.camera_model import pixel_rays, project_points
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.render import FrameRenderer, render_frame, renderer_for
from speechcal_core.synth.timeline import Timeline, plan_session

NS = 1_000_000_000


@pytest.fixture(scope="module")
def grid_timeline() -> Timeline:
    """8 s, one pinhole and one fisheye camera, 640x480 (AprilGrid tags need the pixels)."""
    return plan_session(SynthOptions(cameras=2, fisheye=1, duration=8.0, seed=2))


@pytest.fixture(scope="module")
def board_timeline() -> Timeline:
    """8 s, one pinhole and one fisheye camera, 320x240, checkerboard."""
    return plan_session(SynthOptions(cameras=2, fisheye=1, duration=8.0, seed=2, width=320,
                                     height=240, target_kind="checkerboard"))


def _still_times(tl: Timeline) -> list[int]:
    """One instant per still segment, away from the clap (the hands cover a corner)."""
    out = []
    for s in tl.segments:
        if not s.is_hold:
            continue
        lo, hi = s.start_ns + NS // 4, min(s.end_ns, tl.end_ns) - NS // 4
        t = max(np.linspace(lo, hi, 9).astype(np.int64),
                key=lambda c: min(abs(int(c) - k) for k in tl.claps_ns))
        out.append(int(t))
    return out


def _points_in_camera(tl: Timeline, cam_index: int, t_ns: int, pts: np.ndarray) -> np.ndarray:
    cam = tl.cameras[cam_index]
    rot, trans = tl.pose_at(t_ns)
    r_c = np.asarray(cam.rotation_rig)
    t_c = np.asarray(cam.translation_rig)
    return (r_c @ (rot @ pts.T + trans[:, None])).T + t_c


def _projected_corners(tl: Timeline, cam_index: int, t_ns: int) -> np.ndarray:
    """Truth corners in pixels, projected with OpenCV from the truth pose and intrinsics."""
    cam = tl.cameras[cam_index]
    pts = _points_in_camera(tl, cam_index, t_ns, tl.target.object_points())
    if cam.model == "fisheye":
        img, _ = cv2.fisheye.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3),
                                           cam.camera_matrix, np.asarray(cam.distortion))
    else:
        img, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), cam.camera_matrix,
                                   np.asarray(cam.distortion))
    return img.reshape(-1, 2)


def _aprilgrid_detector() -> cv2.aruco.ArucoDetector:
    params = cv2.aruco.DetectorParameters()
    params.markerBorderBits = 2
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    return cv2.aruco.ArucoDetector(dictionary, params)


def _card_mask(tl: Timeline, cam_index: int, t_ns: int, shrink_px: int = 6) -> np.ndarray:
    """Pixels well inside the target's printed area at ``t_ns``."""
    cam = tl.cameras[cam_index]
    w, h = tl.target.extent
    outline = np.array([[0, 0, 0], [w, 0, 0], [w, h, 0], [0, h, 0]], float)
    poly = project_points(cam, _points_in_camera(tl, cam_index, t_ns, outline))
    mask = np.zeros((cam.height, cam.width), np.uint8)
    cv2.fillConvexPoly(mask, np.round(poly).astype(np.int32), 255)
    return cv2.erode(mask, np.ones((2 * shrink_px + 1,) * 2, np.uint8)) > 0


def test_aprilgrid_is_detected_with_kalibr_ids_where_the_truth_projects_it(
    grid_timeline: Timeline,
) -> None:
    tl = grid_timeline
    detector = _aprilgrid_detector()
    for t in _still_times(tl):
        img = render_frame(tl, 0, t)
        corners, ids, _ = detector.detectMarkers(img)
        assert ids is not None and len(ids) >= 30, "most of the 36 tags in a pinhole camera"
        truth = _projected_corners(tl, 0, t).reshape(-1, 4, 2)
        grey = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
        criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-3)
        centres = {}
        for quad, tag in zip(corners, ids.ravel(), strict=True):
            assert 0 <= tag < 36
            # aruco's own corners sit ~2 px inside on Kalibr grids (the corner squares
            # touch the tags); the saddle-point refinement finds the true corner
            quad = cv2.cornerSubPix(grey, quad.reshape(-1, 1, 2).copy(), (4, 4), (-1, -1),
                                    criteria).reshape(4, 2)
            # OpenCV corner k is Kalibr corner (1, 0, 3, 2)[k] on a printed Kalibr sheet
            err = np.linalg.norm(quad - truth[tag][[1, 0, 3, 2]], axis=1)
            assert err.max() < 1.0, f"tag {tag}: {err.max():.2f} px from the truth"
            centres[int(tag)] = quad.mean(axis=0)
        # Kalibr layout: tag 0 lower left, ids along +x then up the rows
        if {0, 5, 30} <= centres.keys():
            assert centres[5][0] > centres[0][0] + 100
            assert centres[30][1] < centres[0][1] - 100


def test_checkerboard_is_found_where_the_truth_projects_it_in_pinhole_and_fisheye(
    board_timeline: Timeline,
) -> None:
    tl = board_timeline
    t = _still_times(tl)[0]  # the rest before the first move: facing the rig
    for cam_index in (0, 1):
        grey = cv2.cvtColor(render_frame(tl, cam_index, t), cv2.COLOR_BGR2GRAY)
        ok, found = cv2.findChessboardCornersSB(grey, (tl.target.cols, tl.target.rows),
                                                flags=cv2.CALIB_CB_ACCURACY)
        assert ok, tl.cameras[cam_index].model
        truth = _projected_corners(tl, cam_index, t)
        found = found.reshape(-1, 2)
        dist = np.linalg.norm(truth[:, None] - found[None], axis=2)
        assert sorted(dist.argmin(axis=1)) == list(range(len(truth))), "one-to-one match"
        assert dist.min(axis=1).max() < 1.0


def test_a_fisheye_is_a_full_frame_fisheye_that_sees_the_board_large() -> None:
    """The board, held for the pinholes, still fills a fair part of a fisheye's image.

    (A fisheye of 230 degrees across the diagonal saw it about 110 px wide, with tags of
    9-17 px that detection mostly missed.) The lens stays a fisheye: wider than 120 degrees
    across the diagonal, every pixel seeing.
    """
    for seed in range(10):
        tl = plan_session(SynthOptions(cameras=4, fisheye=1, duration=30.0, seed=seed))
        index, cam = next((i, c) for i, c in enumerate(tl.cameras) if c.model == "fisheye")
        fx = cam.intrinsics[0]  # equidistant: angle = radius / f
        assert 2 * np.degrees(np.hypot(cam.width / 2, cam.height / 2) / fx) > 120
        if seed == 0:
            assert pixel_rays(cam, step=8)[1].all()
        for hold in tl.holds:
            t = (hold.start_ns + hold.end_ns) // 2
            px = _projected_corners(tl, index, t).reshape(-1, 4, 2)
            edge = np.linalg.norm(np.roll(px, -1, axis=1) - px, axis=2).mean(axis=1)
            assert np.median(edge) > 14.0, f"seed {seed}: tags of {np.median(edge):.1f} px"
            assert np.ptp(px[..., 0]) > 0.18 * cam.width
            assert (px >= 0).all() and (px[..., 0] < cam.width).all() \
                and (px[..., 1] < cam.height).all(), "all of the board in the fisheye's view"


@pytest.mark.parametrize("seed", [2, 3, 7])
def test_a_fisheye_finds_the_board_at_most_holds(seed: int) -> None:
    tl = plan_session(SynthOptions(cameras=2, fisheye=1, duration=30.0, seed=seed))
    detector = TargetDetector(tl.target)
    found = []
    for hold in tl.holds:
        detection = detector.detect(render_frame(tl, 1, (hold.start_ns + hold.end_ns) // 2))
        found.append(detection.count if detection is not None else 0)
    # 8 corners: fewer and a set is flagged "no target"
    assert sum(n >= 8 for n in found) >= 0.75 * len(found), found
    assert max(found) >= 130, found


def test_frames_blur_while_the_target_moves_fast() -> None:
    tl = plan_session(SynthOptions(cameras=1, duration=16.0, seed=7))
    e_ns = int(tl.cameras[0].exposure_s * NS)

    def image_motion(t: int) -> float:  # mean corner travel during the exposure, pixels
        travel = _projected_corners(tl, 0, t + e_ns // 2) - _projected_corners(tl, 0, t - e_ns // 2)
        return float(np.linalg.norm(travel, axis=1).mean())

    moves = [s for s in tl.segments if not s.is_hold]
    fast = max(moves, key=lambda s: image_motion((s.start_ns + s.end_ns) // 2))
    t_fast = (fast.start_ns + fast.end_ns) // 2  # cosine ramp: fastest mid-move
    assert image_motion(t_fast) > 1.0
    sharp_tl = replace(tl, cameras=tuple(replace(c, exposure_s=0.0) for c in tl.cameras))

    def sharpness(timeline: Timeline, t: int) -> float:
        grey = cv2.cvtColor(render_frame(timeline, 0, t), cv2.COLOR_BGR2GRAY)
        lap = cv2.Laplacian(grey, cv2.CV_64F)
        return float(lap[_card_mask(tl, 0, t)].var())

    moving = sharpness(tl, t_fast)
    # the same pose without exposure time: only the blur differs
    assert moving < 0.8 * sharpness(sharp_tl, t_fast)
    # and the holds on either side of the move are sharper
    for hold in (s for s in tl.segments if s.is_hold and fast.start_ns - 1 <= s.end_ns
                 and s.start_ns <= fast.end_ns + 1):
        assert moving < 0.75 * sharpness(tl, (hold.start_ns + min(hold.end_ns, tl.end_ns)) // 2)


def test_clap_hands_close_linearly_touch_at_the_clap_and_flash(grid_timeline: Timeline) -> None:
    tl = grid_timeline
    cam = tl.cameras[0]
    clap = tl.claps_ns[0]
    x0, y0, x1, y1 = scene.hands_region(cam.width, cam.height)
    row = int(scene.HANDS_CENTRE[1] * cam.height) - y0
    mid = scene.HANDS_CENTRE[0] * cam.width - x0
    empty = render_frame(tl, 0, clap - int(0.8 * NS))[y0:y1, x0:x1].astype(int)

    def hands(t: int) -> np.ndarray:
        patch = render_frame(tl, 0, t)[y0:y1, x0:x1].astype(int)
        return np.abs(patch - empty).sum(axis=2) > 60

    def gap_px(t: int) -> float:
        cols = np.flatnonzero(hands(t)[row])
        left, right = cols[cols < mid], cols[cols >= mid]
        if not left.size or not right.size:
            return 0.0
        return float(right.min() - left.max() - 1)

    assert not hands(clap - int(0.6 * NS)).any(), "no hands well before the clap"
    assert not hands(clap + int(0.5 * NS)).any(), "hands gone after the clap"
    g30, g15 = gap_px(clap - int(0.30 * NS)), gap_px(clap - int(0.15 * NS))
    expected30 = scene.HAND_GAP * cam.width * 0.30 / scene.CLAP_APPROACH_S
    assert abs(g30 - expected30) < 3.0, (g30, expected30)
    assert abs(g15 - expected30 / 2) < 3.0, (g15, expected30 / 2)
    assert gap_px(clap - int(0.002 * NS)) < 2.0, "the hands touch at the clap"
    # the flash: frames exposed within [clap, clap + 25 ms] are brighter there
    lit = render_frame(tl, 0, clap + int(scene.FLASH_S * NS / 2))[y0:y1, x0:x1].mean()
    before = render_frame(tl, 0, clap - int(0.05 * NS))[y0:y1, x0:x1].mean()
    assert lit > before + 40


def test_still_frames_repeat_the_target_while_fan_and_light_keep_moving(
    grid_timeline: Timeline,
) -> None:
    tl = grid_timeline
    cam = tl.cameras[0]
    fx0, fy0, fx1, fy1 = scene.fan_region(cam.width, cam.height)
    lx0, ly0, lx1, ly1 = scene.light_region(cam.width, cam.height)

    def hides_fan_or_light(t: int) -> bool:  # the board is in front of them
        card = _card_mask(tl, 0, t, shrink_px=0)
        return bool(card[fy0:fy1, fx0:fx1].any() or card[ly0:ly1, lx0:lx1].any())

    hold = next(s for s in tl.segments
                if s.is_hold and not hides_fan_or_light(s.start_ns + int(0.3 * NS)))
    a = render_frame(tl, 0, hold.start_ns + int(0.3 * NS)).astype(int)
    b = render_frame(tl, 0, hold.start_ns + int(0.3 * NS) + NS // 10).astype(int)
    card = _card_mask(tl, 0, hold.start_ns + int(0.3 * NS))
    assert np.abs(a - b)[card].mean() < 3.0, "only sensor noise on the held target"
    assert np.abs(a - b)[fy0:fy1, fx0:fx1].mean() > 5.0, "the fan turns"
    # the light blinks: some frames of the hold differ there
    levels = [render_frame(tl, 0, hold.start_ns + k * NS // 10)[ly0:ly1, lx0:lx1].mean()
              for k in range(8)]
    assert max(levels) - min(levels) > 40


def test_rendering_is_deterministic_and_shared_per_timeline(grid_timeline: Timeline) -> None:
    tl = grid_timeline
    t = tl.start_ns + int(3.3 * NS)
    assert renderer_for(tl) is renderer_for(tl)
    fresh = FrameRenderer(tl).render(1, t)
    assert np.array_equal(fresh, render_frame(tl, 1, t))
    assert fresh.shape == (tl.cameras[1].height, tl.cameras[1].width, 3)
    assert fresh.dtype == np.uint8


def test_rolling_shutter_skews_moving_frames_only() -> None:
    opts = dict(cameras=1, duration=8.0, seed=4, width=320, height=240)
    glob = plan_session(SynthOptions(**opts))
    roll = plan_session(SynthOptions(**opts, rolling_shutter=True))
    move = next(s for s in glob.segments if not s.is_hold)
    t_move = (move.start_ns + move.end_ns) // 2
    t_still = glob.start_ns + NS // 2
    card = _card_mask(glob, 0, t_still)
    still_diff = np.abs(render_frame(glob, 0, t_still).astype(int)
                        - render_frame(roll, 0, t_still).astype(int))[card].mean()
    move_diff = np.abs(render_frame(glob, 0, t_move).astype(int)
                       - render_frame(roll, 0, t_move).astype(int)).mean()
    assert still_diff < 3.0
    assert move_diff > 4 * still_diff
