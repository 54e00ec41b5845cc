"""Offset, drift and residuals from claps; manual edits make new results marked manual."""

from __future__ import annotations

from dataclasses import replace

import pytest

from speechcal_core.sync.estimate import CameraClap, Clap, build_result, model_from_claps
from speechcal_core.sync.manual import (
    manual_sync,
    nudge_audio,
    nudge_video,
    set_audio_clap,
    set_video_clap,
)

PERIOD = 33_333_333


def _clap(audio_s: float, session_ns: int, offsets: dict[str, int]) -> Clap:
    return Clap(audio_s, tuple(CameraClap(n, session_ns + o, PERIOD, "v-fit")
                               for n, o in offsets.items()))


def test_one_clap_gives_offset_and_zero_drift() -> None:
    r = build_result([_clap(2.5, 10_000_000_000, {"/a": 1_000_000, "/b": -1_000_000})])
    assert r.model.drift == 0.0 and r.model.source == "auto"
    assert r.model.offset_ns == 10_000_000_000 - 2_500_000_000
    cams = {c["name"]: c for c in r.to_dict()["cameras"]}
    assert cams["/a"]["residual_ns"] == 1_000_000 and cams["/b"]["residual_ns"] == -1_000_000
    assert not r.warnings


def test_two_claps_give_drift_and_camera_offsets_cancel() -> None:
    drift = 37e-6
    a1, a2 = 1.7, 58.3
    s1 = 5_000_000_000 + round(a1 * (1 + drift) * 1e9)
    s2 = 5_000_000_000 + round(a2 * (1 + drift) * 1e9)
    offs = {"/a": 3_000_000, "/b": -2_000_000, "/c": 500_000}
    r = build_result([_clap(a2, s2, offs), _clap(a1, s1, offs)])
    assert r.model.drift == pytest.approx(drift, abs=1e-8)
    doc = r.to_dict()
    assert [c["audio_s"] for c in doc["claps"]] == [a1, a2]
    assert set(doc) >= {"offset_ns", "drift", "claps", "cameras"}


def test_camera_with_clock_off_is_reported() -> None:
    r = build_result([_clap(1.0, 3_000_000_000, {"/a": 0, "/b": 0, "/c": 80_000_000})])
    assert any("/c" in w and "clock may be off" in w and "not seen clearly" in w
               for w in r.warnings)


def test_camera_off_by_the_same_amount_at_both_claps_has_its_clock_off() -> None:
    offs = {"/a": 0, "/b": 0, "/c": 80_000_000}
    r = build_result([_clap(1.0, 3_000_000_000, offs), _clap(50.0, 52_000_000_000, offs)])
    assert [w for w in r.warnings if "/c" in w] == [
        "/c: clap +80.0 ms off the other cameras at both claps; its clock is off by that much"]


def test_camera_off_at_the_first_clap_only_timed_it_wrongly() -> None:
    """In line at the second clap, its clock is right: "its clock may be off" asked the
    operator for a fix there is none to make (a 15 fps rolling-shutter camera, 105 ms)."""
    first = _clap(1.0, 3_000_000_000, {"/a": 0, "/b": 0, "/c": -22_500_000})
    second = _clap(50.0, 52_000_000_000, {"/a": 0, "/b": 0, "/c": 0})
    r = build_result([first, second])
    assert [w for w in r.warnings if "/c" in w] == [
        "/c: clap -22.5 ms off the other cameras at the first clap but in line at the "
        "second: it did not time the first clap well, its clock is right; the other "
        "cameras set the offset, nothing to do"]
    assert r.model.offset_ns == 3_000_000_000 - 1_000_000_000  # the others' median
    # two cameras apart at the first clap: which one timed it wrongly is not known
    two = build_result([_clap(1.0, 3_000_000_000, {"/a": 0, "/c": -40_000_000}),
                        _clap(50.0, 52_000_000_000, {"/a": 0, "/c": 0})])
    assert two.warnings and all("its clock may be off, or its clap was not seen clearly"
                                in w for w in two.warnings)


def test_two_cameras_a_few_frames_apart_take_the_clearer_not_their_mean() -> None:
    """A 30 fps camera timed the clap 3 frames early, a 15 fps one saw it clearly: the
    mean weighted by frame rate put the clap 77 ms off. Two cameras more than a frame
    apart cannot both be right, so the clearer one (or one set by hand) is taken."""
    fast = CameraClap("/a", 3_000_000_000 - 91_000_000, PERIOD, "v-fit", score=3.5)
    slow = CameraClap("/b", 3_000_000_000, 2 * PERIOD, "v-fit", score=10.2)
    r = build_result([Clap(1.0, (fast, slow))])
    assert r.claps[0].session_ns == 3_000_000_000
    assert [w.split(":")[0] for w in r.warnings] == ["/a"]
    # within a frame of each other they are averaged, the faster camera counting more
    near = CameraClap("/a", 3_000_000_000 - 20_000_000, PERIOD, "v-fit", score=3.5)
    assert Clap(1.0, (near, slow)).session_ns == 3_000_000_000 - 16_000_000
    # the operator's hand beats the clearer camera
    by_hand = set_video_clap(r, 0, 3_200_000_000, camera="/a")
    assert by_hand.claps[0].session_ns == 3_200_000_000


def test_manual_edits_are_marked_and_move_the_offset() -> None:
    r = build_result([_clap(1.0, 3_000_000_000, {"/a": 0, "/b": 0})])
    r2 = nudge_audio(r, 0, +1)
    assert r2.model.source == "manual" and r2.claps[0].audio_source == "manual"
    assert r2.model.offset_ns == r.model.offset_ns - 1_000_000
    r3 = nudge_video(r, 0, -1)
    assert r3.model.offset_ns == r.model.offset_ns - PERIOD
    r4 = set_video_clap(r, 0, 3_010_000_000, camera="/a")
    assert r4.claps[0].session_ns == 3_005_000_000
    r5 = set_audio_clap(r, 0, 0.5)
    assert r5.model.offset_ns == 2_500_000_000
    assert r.model.source == "auto"  # the original is unchanged


def test_fully_manual_sync() -> None:
    r = manual_sync([(1.0, 3_000_000_000), (101.0, 103_000_010_000)])
    assert r.model.source == "manual"
    assert r.model.drift == pytest.approx(1e-7)
    assert r.to_dict()["cameras"] == []


def test_model_needs_a_clap() -> None:
    with pytest.raises(ValueError):
        model_from_claps([])


def test_two_cameras_count_by_how_finely_they_time_the_clap() -> None:
    """A 15 fps camera whose clap was timed two frames early pulled the offset half way
    (65 ms on a synthetic session); a 30 fps camera now counts four times as much."""
    fast = CameraClap("/cam0", 1_000_000_000, 33_333_333, "v-fit")
    slow = CameraClap("/cam1", 1_000_000_000 - 120_000_000, 66_666_667, "v-fit")
    clap = Clap(2.0, (fast, slow))
    assert clap.session_ns == pytest.approx(1_000_000_000 - 24_000_000, abs=1_000)
    same_rate = Clap(2.0, (fast, CameraClap("/cam1", 880_000_000, 33_333_333, "v-fit")))
    assert same_rate.session_ns == 940_000_000  # equal periods: the plain mean


def _timed(name: str, clap_ns: int, sigma_ns: int, period: int = PERIOD) -> CameraClap:
    return CameraClap(name, clap_ns, period, "v-fit", sigma_ns=sigma_ns)


def test_drift_leans_on_the_camera_whose_v_fits_timed_both_claps_closely() -> None:
    """A 30 fps camera 4.8 ms off at the closing clap, with a V fit that says so (4.4 ms
    standard error), no longer outweighs a 15 fps camera whose fits hold to 0.7 ms."""
    a1, a2, s1, s2 = 2.0, 39.0, 10_000_000_000, 47_000_000_000
    first = Clap(a1, (_timed("/fast", s1, 470_000), _timed("/slow", s1, 690_000, 2 * PERIOD)))
    last = Clap(a2, (_timed("/fast", s2 - 4_800_000, 4_350_000),
                     _timed("/slow", s2, 600_000, 2 * PERIOD)))
    true_drift = (s2 - s1) / ((a2 - a1) * 1e9) - 1.0
    r = build_result([first, last])
    assert abs(r.model.drift - true_drift) * 1e6 < 10.0
    # without the fits' errors, the cameras count by frame rate as before (fast: 4 to 1)
    plain = build_result([Clap(a1, tuple(replace(c, sigma_ns=0) for c in first.cameras)),
                          Clap(a2, tuple(replace(c, sigma_ns=0) for c in last.cameras))])
    assert (plain.model.drift - true_drift) * 1e6 == pytest.approx(-4.8e6 * 4 / 5 / 37e3,
                                                                   abs=0.5)


def test_cameras_that_disagree_on_the_time_between_claps_are_noted() -> None:
    a1, a2, s1, s2 = 2.0, 39.0, 10_000_000_000, 47_000_000_000
    first = Clap(a1, (_timed("/a", s1, 500_000), _timed("/b", s1, 500_000)))
    last = Clap(a2, (_timed("/a", s2 + 6_000_000, 500_000), _timed("/b", s2, 500_000)))
    notes = build_result([first, last]).warnings
    assert any(n.startswith("the cameras disagree on the time between the claps by 6.0 ms "
                            "(162 ppm of drift)") for n in notes)
    agreeing = Clap(a2, (_timed("/a", s2 + 600_000, 500_000), _timed("/b", s2, 500_000)))
    assert not build_result([first, agreeing]).warnings


def test_a_drift_from_claps_close_together_is_noted_as_uncertain() -> None:
    """Two claps 8 s apart timed to 0.5 ms: the drift is good to about 90 ppm only, which
    in ten minutes of audio is 53 ms; within the claps' span it is under a millisecond."""
    first = Clap(2.0, (_timed("/a", 10_000_000_000, 500_000),))
    last = Clap(10.0, (_timed("/a", 18_000_400_000, 500_000),))
    long_audio = {"audio": {"duration_s": 600.0}}
    r = build_result([first, last], extra=long_audio)
    assert r.model.drift * 1e6 == pytest.approx(50.0, abs=0.1)
    assert [n for n in r.warnings if n.startswith(
        "drift 50 ppm is uncertain by about 88 ppm (53 ms at the words farthest")]
    assert not build_result([first, last]).warnings  # audio length unknown: to the last clap
    assert not build_result([first, last], extra={"audio": {"duration_s": 12.0}}).warnings
    far = Clap(500.0, (_timed("/a", 508_025_000_000, 500_000),))
    assert not build_result([first, far], extra=long_audio).warnings
