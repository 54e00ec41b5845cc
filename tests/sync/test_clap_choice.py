"""Pairing a heard clap with the cameras' clap by where it lays the audio's sound."""

from __future__ import annotations

import numpy as np

from speechcal_core.audio.loader import Audio
from speechcal_core.sync.clap_audio import ClapCandidate
from speechcal_core.sync.clap_choice import (
    SoundTimes,
    choose_opening,
    closing_after,
    sound_times,
)
from speechcal_core.sync.clap_video import VideoClap

S = 1_000_000_000


def _clap(t: float, score: float = 0.9) -> ClapCandidate:
    return ClapCandidate(time_s=t, score=score, jump_db=30.0, peak_dbfs=-6.0, rise_ms=1.0,
                         decay_ms=40.0, flatness=0.5, centroid_hz=3000.0, sustain_db=-25.0,
                         clipped=False)


def test_sound_times_skip_digital_silence_and_room_noise() -> None:
    rate = 8000
    rng = np.random.default_rng(0)
    room = 0.001 * rng.standard_normal(20 * rate)
    room[5 * rate:7 * rate] += 0.1 * np.sin(np.arange(2 * rate) * 0.3)  # 2 s of "speech"
    x = np.concatenate([np.zeros(10 * rate), room]).astype(np.float32)
    times = sound_times(Audio(x, rate)).times_s
    assert times.min() >= 15.0 and times.max() <= 17.0
    assert 1.8 <= times.size * 0.1 <= 2.1
    assert sound_times(Audio(np.zeros(rate, np.float32), rate)).times_s.size == 0


def test_the_loud_closing_clap_loses_to_the_one_that_lays_the_speech_over_the_video() -> None:
    """Speech from 3 to 38 s of audio; claps heard at 2 s and (louder) at 39 s; the video
    runs 0-40 s with its first clap at 1.5 s."""
    sound = SoundTimes(np.arange(3.0, 38.0, 0.1))
    claps = [_clap(2.0, 0.7), _clap(39.0, 0.95)]
    choice = choose_opening(claps, sound, int(1.5 * S), (0, 40 * S))
    assert choice.clap.time_s == 2.0 and choice.share > 0.95
    assert closing_after(claps, choice.clap, 5.0) == claps[1]
    assert closing_after(claps, claps[1], 5.0) is None


def test_a_knock_just_before_the_clap_loses_to_the_clearer_clap() -> None:
    """Both pairings lay nearly all the sound over the video; the clap score decides."""
    sound = SoundTimes(np.arange(3.0, 38.0, 0.1))
    claps = [_clap(1.0, 0.65), _clap(2.0, 0.9)]
    assert choose_opening(claps, sound, int(1.5 * S), (0, 40 * S)).clap.time_s == 2.0


def test_a_closing_clap_heard_alone_lays_little_sound_over_the_video() -> None:
    """The microphone started after the opening clap: paired with the cameras' first clap,
    the only heard clap throws the speech before the video; with their last, it fits."""
    sound = SoundTimes(np.arange(0.5, 33.0, 0.1))
    claps = [_clap(34.0)]
    assert choose_opening(claps, sound, int(1.5 * S), (0, 40 * S)).share < 0.1
    assert choose_opening(claps, sound, int(38.5 * S), (0, 40 * S)).share > 0.95


def _seen(offset_s: float, stream: str = "/cam0") -> VideoClap:
    return VideoClap(stream, int(10 * S + offset_s * S), 0, 5.0, "v-fit", (0, 0, 8, 8),
                     33_333_333)


def test_a_double_clap_pairs_clap_for_clap_with_what_the_cameras_saw() -> None:
    """Two claps 0.45 s apart, the second louder: loudness took the second while the
    cameras' clap was the first of their two. Each heard clap is tried in the cameras'
    clap's place; the one whose neighbours fall on the cameras' other events wins."""
    from speechcal_core.sync.pipeline import _in_the_same_place

    heard = [_clap(2.42, 0.9), _clap(2.87, 0.9)]
    both = [_seen(0.0), _seen(0.45), _seen(0.0, "/cam1"), _seen(0.45, "/cam1")]
    assert _in_the_same_place(heard, heard[1], both, 10 * S) == (heard[0], [])
    # the cameras saw the second as theirs: the second stays
    assert _in_the_same_place(heard, heard[1], [_seen(-0.45), _seen(0.0)], 10 * S) == (
        heard[1], [])
    # they saw one clap where two were heard: a tie, named for a note
    assert _in_the_same_place(heard, heard[1], [_seen(0.0)], 10 * S) == (heard[1], [heard[0]])


def test_sound_outside_the_video_is_split_into_before_and_after() -> None:
    """Talk from 0 to 10 s of audio, the clap at 10 s, talk to 30 s: with the video from
    the clap (at 0 s) to 15 s, a third of the sound comes before it and a sixth after."""
    sound = SoundTimes(np.arange(0.05, 30.0, 0.1))
    before, after = sound.shares_outside(10.0, 0, (0, 15 * S))
    assert (round(before, 2), round(after, 2)) == (0.33, 0.17)
    assert round(sound.share_over(10.0, 0, (0, 15 * S)), 2) == 0.5
    assert SoundTimes(np.zeros(0)).shares_outside(1.0, 0, (0, S)) == (0.0, 0.0)
