"""Coverage figures and the common-time choice, on small hand-made inputs."""

from __future__ import annotations

import numpy as np

from speechcal_core.frames.coverage import coverage, coverage_image
from speechcal_core.frames.detect import Detection
from speechcal_core.frames.select import choose_common_time, score_camera
from speechcal_core.frames.window import CameraWindow
from speechcal_core.target import TargetSpec

MS = 1_000_000


def _det(target: TargetSpec, x0: float, y0: float, scale: float) -> Detection:
    obj = target.object_points()
    return Detection(obj[:, :2] * scale + (x0, y0), np.arange(len(obj)))


def test_coverage_grows_with_spread_of_board_positions() -> None:
    target = TargetSpec()
    size = (640, 480)
    centre = [_det(target, 250, 170, 600)] * 3
    spread = [_det(target, 10, 10, 600), _det(target, 400, 250, 600),
              _det(target, 200, 100, 1200)]
    one = coverage(centre, target.object_points(), size)
    many = coverage(spread, target.object_points(), size)
    assert one.progress["x"] == 0 and one.progress["size"] == 0
    assert many.progress["x"] > 0.9 and many.progress["y"] > 0.9
    assert many.progress["size"] > 0.5
    assert many.to_dict()["views"] == 3
    img = coverage_image(spread, size)
    assert img.shape == (240, 320) and img.max() == 255 and img[10, 10] > 0 and img[-1, 0] == 0


def _window(stamps_ms: list[int], sharp: list[float], motion: list[float],
            period_ms: int) -> CameraWindow:
    st = np.asarray(stamps_ms, np.int64) * MS
    n = st.size
    return CameraWindow("/c", np.arange(n), st, np.ones(n, bool), np.asarray(sharp, float),
                        np.asarray(motion, float), np.zeros(n, bool), True, period_ms * MS)


def test_common_time_maximizes_the_worst_camera_and_stays_synchronized() -> None:
    # camera a is still from 100 ms on; camera b only from 200 ms on
    a = _window([0, 33, 67, 100, 133, 167, 200, 233, 267], [1] * 9,
                [9, 9, 9, 1, 1, 1, 1, 1, 1], 33)
    b = _window([10, 77, 143, 210, 277], [1] * 5, [9, 9, 9, 1, 1], 67)
    wins = [a, b]
    choice = choose_common_time(wins, [score_camera(w, 1.0) for w in wins], 0)
    assert choice is not None and choice.still
    ta, tb = a.stamps[choice.positions[0]], b.stamps[choice.positions[1]]
    assert ta >= 200 * MS and tb >= 210 * MS
    assert abs(ta - tb) <= 67 * MS // 2


def test_sharper_still_frame_wins_inside_a_hold() -> None:
    a = _window([0, 33, 67, 100, 133], [1.0, 1.0, 3.0, 1.0, 1.0], [1] * 5, 33)
    choice = choose_common_time([a], [score_camera(a, 1.0)], 0)
    assert choice is not None and choice.positions == (2,)


def test_still_stretch_after_the_word_beats_the_previous_pose_before_it() -> None:
    # still (previous pose) until 67 ms, moving, still again from 233 ms; word at 100 ms
    a = _window([0, 33, 67, 100, 133, 167, 200, 233, 267, 300],
                [3, 3, 3, 1, 1, 1, 1, 1, 1, 1], [1, 1, 1, 9, 9, 9, 9, 1, 1, 1], 33)
    choice = choose_common_time([a], [score_camera(a, 1.0)], 100 * MS)
    assert choice is not None and choice.stretch == "after"
    assert a.stamps[choice.positions[0]] >= 233 * MS


def test_a_tiny_noise_floor_does_not_turn_still_frames_into_moving_ones() -> None:
    """Downscaled from a large image, sensor noise averages out: still frames differ by
    ~0.1-0.3 grey levels, several times their lowest difference. Below MIN_NOISE_FLOOR
    the floor is that minimum, so only real motion (grey levels, not tenths) counts."""
    from speechcal_core.frames.select import MIN_NOISE_FLOOR

    a = _window([0, 33, 67, 100, 133], [1] * 5, [0.1, 0.25, 0.3, 0.2, 4.0], 33)
    score = score_camera(a, 0.1)
    assert list(score.still) == [True, True, True, True, False]
    np.testing.assert_allclose(score.motion_ratio, np.array(a.motion) / MIN_NOISE_FLOOR)
    # lossless frames without noise: a floor of zero no longer makes every frame move
    assert list(score_camera(a, 0.0).still) == [True, True, True, True, False]


def test_a_camera_without_frames_near_the_word_is_left_out_not_a_reason_to_move() -> None:
    """A camera that started late (no frames in the window) used to zero every time's
    score: the others got moving frames. Now it is left out and the others hold still."""
    a = _window([0, 33, 67, 100, 133, 167, 200, 233], [1] * 8, [9, 9, 9, 1, 1, 1, 1, 1], 33)
    late = _window([], [], [], 33)
    wins = [a, late]
    choice = choose_common_time(wins, [score_camera(w, 1.0) for w in wins], 150 * MS,
                                [a.stamps, np.array([9_000 * MS])])
    assert choice is not None and choice.still and choice.positions[1] == -1
    assert a.stamps[choice.positions[0]] >= 100 * MS


def test_a_gap_in_one_camera_gives_way_to_times_where_every_camera_has_a_frame() -> None:
    """Camera b dropped its frames from 90 to 190 ms; both are still from 100 ms on. The
    set takes a time where b has a frame too; with b gone for the whole hold, the others'
    still frames are taken and b is left out."""
    a = _window([0, 33, 67, 100, 133, 167, 200, 233, 267], [1] * 9,
                [9, 9, 9, 1, 1, 1, 1, 1, 1], 33)
    b = _window([10, 43, 77, 210, 243], [1] * 5, [9, 9, 9, 1, 1], 33)
    choice = choose_common_time([a, b], [score_camera(w, 1.0) for w in (a, b)], 120 * MS)
    assert choice is not None and choice.still and min(choice.positions) >= 0
    assert b.stamps[choice.positions[1]] >= 210 * MS
    gone = _window([10, 43, 77], [1] * 3, [9, 9, 9], 33)  # stopped before the hold
    choice = choose_common_time([a, gone], [score_camera(w, 1.0) for w in (a, gone)],
                                120 * MS)
    assert choice is not None and choice.still and choice.positions[1] == -1
    assert a.stamps[choice.positions[0]] >= 100 * MS


def test_a_sparse_scan_does_not_hide_a_gap_in_a_cameras_frames() -> None:
    """Scanning every 4th frame, a camera counted as present anywhere within one scan
    step (133 ms) of a scanned frame, across a gap in its frames too: its frame 108 ms
    from the others' flagged the whole set "skew". Its full stamps now decide."""
    every = np.arange(0, 1000, 33) * MS
    real = every[(every < 280 * MS) | (every > 390 * MS)]  # a gap from 280 to 390 ms
    scanned = real[::4]
    a = CameraWindow("/a", np.arange(scanned.size), scanned, np.ones(scanned.size, bool),
                     np.ones(scanned.size), np.ones(scanned.size), np.zeros(scanned.size, bool),
                     True, 4 * 33 * MS, stride=4)
    # b's sharpest frames lie in a's gap: the worst camera's quality is highest there
    sharp = [2.0 if 280 * MS < t < 390 * MS else 1.0 for t in every]
    b = _window(list(every // MS), sharp, [1] * every.size, 33)
    wins = [a, b]
    choice = choose_common_time(wins, [score_camera(w, 1.0) for w in wins], 330 * MS,
                                [real, every])
    assert choice is not None and choice.positions[0] >= 0
    nearest_real = real[np.argmin(np.abs(real - choice.t_ns))]
    assert abs(nearest_real - choice.t_ns) <= 17 * MS


def test_a_skipped_frame_next_to_a_gap_is_taken_when_every_camera_is_still() -> None:
    """Scanning every 4th frame, the frame at the chosen time lies between a scanned still
    frame and the first one after a gap (which the gap shows as moving): the scanned frame
    100 ms away was kept. With every camera still at that time, the nearer frame is."""
    from speechcal_core.frames.sets import _refine

    every = np.arange(0, 1200, 33) * MS
    real = every[(every < 340 * MS) | (every > 800 * MS)]
    idx = np.arange(0, real.size, 4)
    win = CameraWindow("/a", idx, real[idx], np.ones(idx.size, bool), np.ones(idx.size),
                       np.where(real[idx] > 800 * MS, 9.0, 1.0), np.zeros(idx.size, bool),
                       True, 4 * 33 * MS, stride=4)
    score = score_camera(win, 1.0)
    p = int(np.flatnonzero(real[idx] == 264 * MS)[0])
    t = 330 * MS
    assert real[_refine(real, win, score, p, t)] == 264 * MS  # stillness unknown at t
    assert real[_refine(real, win, score, p, t, still_at_t=True)] == 330 * MS
