"""The video clap detector: the one local burst, timed to a fraction of a frame."""

from __future__ import annotations

import numpy as np
import pytest
from video_scenes import clap_clip

from speechcal_core.sync.clap_video import find_video_clap


@pytest.mark.parametrize("fps", [30.0, 15.0])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_clap_found_despite_fan_light_and_board_move(fps: float, seed: int) -> None:
    clap_s = 1.5 + 0.013 * seed
    frames, stamps = clap_clip(fps=fps, seed=seed, clap_s=clap_s)
    c = find_video_clap(frames, stamps, stream="/cam0")
    assert c is not None and c.stream == "/cam0"
    assert c.method == "v-fit"
    assert abs(c.clap_ns / 1e9 - clap_s) < 0.25 / fps  # a quarter of a frame
    x, y, w, h = c.roi
    assert x < 0.25 * 160 < x + w and y < 0.8 * 120 < y + h


def test_colour_frames_and_other_place() -> None:
    frames, stamps = clap_clip(seed=5, hands_at=(0.75, 0.85), board_move_s=None)
    colour = [np.dstack([f, f, f]) for f in frames]
    c = find_video_clap(colour, stamps)
    assert c is not None and abs(c.clap_ns / 1e9 - 1.5) < 0.01


def test_stamp_jitter_averages_out() -> None:
    frames, stamps = clap_clip(seed=3, stamp_jitter_s=0.0008)
    c = find_video_clap(frames, stamps)
    assert c is not None and abs(c.clap_ns / 1e9 - 1.5) < 0.006


def test_no_clap_no_event() -> None:
    frames, stamps = clap_clip(seed=4, clap_s=99.0, board_move_s=None)
    assert find_video_clap(frames, stamps) is None


def test_too_few_frames() -> None:
    frames, stamps = clap_clip(seconds=0.1)
    assert find_video_clap(frames, stamps) is None


@pytest.mark.parametrize("seconds", [0.2, 0.25, 0.3, 0.35])
def test_a_window_shorter_than_a_motion_burst_gives_no_clap_not_an_error(seconds) -> None:
    """6-10 frames (a camera that stops just before the closing clap's window) made the
    smoothing longer than the clip and the search raise ValueError."""
    frames, stamps = clap_clip(seconds=seconds, clap_s=0.1)
    assert find_video_clap(frames, stamps) is None


def test_a_topic_recorded_twice_still_gives_its_clap() -> None:
    """Two recorders on one topic: every frame twice, with the same stamp."""
    frames, stamps = clap_clip(seed=0, clap_s=1.5)
    doubled = [f for f in frames for _ in range(2)]
    stamps2 = np.repeat(np.asarray(stamps), 2)
    c = find_video_clap(doubled, stamps2)
    assert c is not None and abs(c.clap_ns / 1e9 - 1.5) < 0.5 / 30


def test_a_distance_that_neither_closes_nor_parts_has_no_vertex() -> None:
    """At the work width a 1280x800 camera's hands gave distances flat within a pixel
    (noise); their "V" was a frame off and overruled the full-resolution fit, putting
    that camera's clap 32 ms late. Such a series now gives no time; a real V still does."""
    from speechcal_core.sync.clap_video import _vertex

    period = 1 / 30
    times = np.arange(21) * period + 1.0
    flat = 7.2 + 0.3 * np.random.default_rng(0).standard_normal(21)
    assert _vertex(times, flat, 1.35, period) is None
    touch = 1.35
    v = np.where(times < touch, 120 - 330 * (times - touch), 120 + 500 * (times - touch))
    assert _vertex(times, v, touch, period) == pytest.approx(touch, abs=2e-3)


def test_one_frame_split_wrongly_at_the_touch_leaves_the_vertex_in_place() -> None:
    """The parts' distances (px) a 30 fps camera of ``speechcal synth --seed 7`` gave at
    the work width around its first clap (times from the true clap). The frame just after
    the touch was split wrongly and sits far above its neighbours, which a V never does;
    the fit through it put the clap 92 ms early."""
    from speechcal_core.sync.clap_video import _vertex

    times = np.array([-0.4217, -0.3879, -0.3540, -0.3209, -0.2897, -0.2550, -0.2222,
                      -0.1889, -0.1543, -0.1220, -0.0883, -0.0547, 0.0123, 0.0454, 0.0780,
                      0.1115, 0.1455, 0.1788, 0.2126, 0.2445, 0.2777])
    dists = np.array([31.43, 29.96, 28.05, 26.58, 24.93, 23.23, 21.79, 20.17, 18.41, 16.80,
                      15.47, 13.99, 29.35, 14.41, 16.65, 18.95, 21.44, 23.80, 26.26, 28.82,
                      31.13])
    assert _vertex(times, dists, 0.0123, 1 / 30) == pytest.approx(0.0, abs=3e-3)
    kept = np.arange(times.size) != 12  # without that frame: the same vertex
    assert _vertex(times[kept], dists[kept], 0.0123, 1 / 30) == pytest.approx(0.0, abs=3e-3)


def _noisy_vs(count: int) -> list[tuple[np.ndarray, np.ndarray, float, float]]:
    """Distance series as the clap's V fit meets them: (times, distances, t_min, period)."""
    rng = np.random.default_rng(7)
    series = []
    for _ in range(count):
        period = 1.0 / rng.choice([15, 25, 30, 60])
        times = np.arange(int(rng.integers(6, 40))) * period + rng.uniform(0, 3)
        touch = rng.uniform(times[2], times[-1])
        closing, opening = rng.uniform(50, 400), rng.uniform(50, 600)
        d = np.where(times < touch, -closing, opening) * (times - touch) + 40
        d += rng.normal(0, rng.choice([0.0, 0.5, 3.0]), times.size)
        series.append((times, d, float(times[np.argmin(d)]), period))
    return series


def test_the_v_fit_takes_a_vertex_as_good_as_a_least_squares_scan_finds() -> None:
    """The grid's vertices are fitted in one batch, in closed form; the vertex taken fits
    as well as the best of a least-squares solve per vertex (the same one, where only one
    does), and a clean V's vertex is the scan's."""
    from v_fit_scan import scan_vertices, vertex_fit

    from speechcal_core.sync.clap_video import _fit_v

    same = 0
    for times, d, t_min, period in _noisy_vs(60):
        want, want_err = scan_vertices(times, d, t_min, period)
        got, got_err = _fit_v(times, d, t_min, period)
        assert (got is None) == (want is None)
        if got is None:
            continue
        err, coef = vertex_fit(times, d, got)
        assert coef[1] < 0 < coef[2]
        assert err == pytest.approx(want_err, rel=1e-9, abs=1e-12 * float(d @ d))
        assert got_err == pytest.approx(err, rel=1e-9, abs=1e-12 * float(d @ d))
        same += got == want
    assert same >= 50  # the rest: stretches of the grid that fit alike
    period = 1 / 30
    times = np.arange(21) * period + 1.0
    v = np.where(times < 1.3512, -330.0, 500.0) * (times - 1.3512) + 120
    v += 0.2 * np.random.default_rng(1).standard_normal(21)
    assert _fit_v(times, v, 1.35, period)[0] == scan_vertices(times, v, 1.35, period)[0]


def test_the_v_fit_needs_no_solve_per_vertex(monkeypatch: pytest.MonkeyPatch) -> None:
    """A 30 fps V fit searches about 2,300 vertices; a least-squares solve for each (35,000
    per sync) took most of a sync's time."""
    from speechcal_core.sync import clap_video

    solves = []
    lstsq = np.linalg.lstsq
    monkeypatch.setattr(np.linalg, "lstsq", lambda *a, **k: solves.append(1) or lstsq(*a, **k))
    times, d, t_min, period = _noisy_vs(1)[0]
    clap_video._fit_v(times, d, t_min, period)
    assert solves == []
