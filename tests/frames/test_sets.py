"""Frame sets: best still frames inside the holds, nearest kept, flags, background ignored."""

from __future__ import annotations

import numpy as np
from board_images import facing_pose, render_view
from rendered_source import ArraySource, RenderedSource

from speechcal_core.frames.sets import FrameSetOptions, build_frame_sets
from speechcal_core.session.model import Trigger
from speechcal_core.sync.model import SyncModel
from speechcal_core.synth.options import SynthOptions
from speechcal_core.synth.timeline import plan_session
from speechcal_core.target import TargetSpec

NS = 1_000_000_000


def _word(sync: SyncModel, end_ns: int, duration_s: float = 0.5) -> Trigger:
    end_s = float(sync.to_audio(end_ns))
    return Trigger("capture", end_s - duration_s, end_s)


def test_chosen_frames_lie_inside_holds_even_when_the_word_ends_before_the_hold() -> None:
    timeline = plan_session(SynthOptions(cameras=2, duration=20, seed=11, width=480,
                                         height=360))
    source = RenderedSource(timeline)
    holds = timeline.holds[:4]
    # words ending 0.3 s, 0.15 s and 0 s before the board settles, and one well inside
    ends = [holds[0].start_ns - int(0.3 * NS), holds[1].start_ns - int(0.15 * NS),
            holds[2].start_ns, (holds[3].start_ns + holds[3].end_ns) // 2 + int(0.25 * NS)]
    triggers = [_word(timeline.sync, e) for e in ends]
    result = build_frame_sets(source, timeline.sync, triggers, timeline.target,
                              FrameSetOptions(workers=2))
    nearest_outside = 0
    for fs, hold in zip(result.sets, holds, strict=True):
        for f in fs.frames:
            assert f.index >= 0 and "moving" not in f.flags
            t = source.true_ns(f.stream)[f.index]
            assert hold.start_ns <= t <= hold.end_ns, (fs.id, f.stream, (t - hold.start_ns) / 1e6)
            assert f.corners and f.corners >= 60
        near = result.details[str(fs.id)]["nearest"]
        for name, n in near.items():
            t = source.true_ns(name)[n["index"]]
            nearest_outside += not hold.start_ns <= t <= hold.end_ns
    assert nearest_outside > 0  # the baseline picks moving frames for the early words


def _board_in_view(target: TargetSpec) -> np.ndarray:
    """A 480x360 grey view of the board, facing the camera, filling much of the frame."""
    k = np.array([[400.0, 0, 240], [0, 400, 180], [0, 0, 1]])
    rvec, tvec = facing_pose(target, 0.8, (0.2, 0.1), (0.04, 0.0))
    return render_view(target, k, rvec, tvec, (480, 360), noise=0)


def test_background_blinking_and_spinning_does_not_count_as_motion() -> None:
    target = TargetSpec()
    board = _board_in_view(target)
    rng = np.random.default_rng(0)
    stamps = np.arange(60, dtype=np.int64) * (NS // 30) + 10 * NS
    frames = []
    for i in range(60):
        img = board.astype(np.int16)
        img[10:60, 10:60] = 250 if (i // 3) % 2 else 20  # a blinking light
        angle = i * 0.7  # a fan blade
        x, y = int(440 + 30 * np.cos(angle)), int(320 + 30 * np.sin(angle))
        img[y - 8:y + 8, x - 8:x + 8] = 0
        frames.append(np.clip(img + rng.normal(0, 2, img.shape), 0, 255).astype(np.uint8))
    source = ArraySource({"/cam": (stamps, frames)})
    sync = SyncModel(10 * NS)
    result = build_frame_sets(source, sync, [Trigger("capture", 0.9, 1.1)], target)
    (frame,) = result.sets[0].frames
    assert "moving" not in frame.flags
    details = result.details["1"]
    assert details["frames"]["/cam"]["target_region"] is True
    assert details["still_ns"] is not None


def test_camera_without_a_frame_near_the_trigger_is_flagged() -> None:
    period = NS // 20
    stamps = np.arange(100, dtype=np.int64) * period
    gap = (stamps < 1.5 * NS) | (stamps > 3.5 * NS)  # the second camera drops two seconds
    img = np.full((120, 160), 128, np.uint8)
    source = ArraySource({"/a": (stamps, [img] * 100),
                          "/b": (stamps[gap], [img] * int(gap.sum()))})
    sync = SyncModel(0)
    for search in (True, False):
        result = build_frame_sets(source, sync, [Trigger("capture", 2.4, 2.6)], None,
                                  FrameSetOptions(search=search, extend_s=0))
        flags = {f.stream: f.flags for f in result.sets[0].frames}
        assert "no-frame" in flags["/b"]
        assert "no-frame" not in flags["/a"]


def test_nearest_only_mode_picks_the_nearest_stamps() -> None:
    stamps = np.arange(50, dtype=np.int64) * (NS // 10)
    img = np.full((60, 80), 100, np.uint8)
    source = ArraySource({"/a": (stamps, [img] * 50)})
    result = build_frame_sets(source, SyncModel(0), [Trigger("capture", 1.22, 1.3)], None,
                              FrameSetOptions(search=False))
    (frame,) = result.sets[0].frames
    assert frame.index == 13 and frame.stamp_ns == stamps[13]
    assert result.details["1"]["method"] == "nearest"


def test_a_frame_without_the_target_is_not_judged_blurred_against_frames_with_it() -> None:
    target = TargetSpec()
    board = _board_in_view(target)
    rng = np.random.default_rng(1)
    wall = np.clip(128 + rng.normal(0, 6, board.shape), 0, 255).astype(np.uint8)
    stamps = np.arange(150, dtype=np.int64) * (NS // 30) + 10 * NS
    frames = [wall if 30 <= i < 120 else board for i in range(150)]  # no board in 1-4 s
    source = ArraySource({"/cam": (stamps, frames)})
    triggers = [Trigger("capture", t - 0.1, t + 0.1) for t in (0.5, 2.5, 4.5)]
    result = build_frame_sets(source, SyncModel(10 * NS), triggers, target,
                              FrameSetOptions(extend_s=0.2))
    seen, empty, again = (fs.frames[0] for fs in result.sets)
    assert "no-target" in empty.flags and "blurred" not in empty.flags
    assert empty.sharpness is None
    for f in (seen, again):
        assert f.flags == () and f.sharpness is not None and f.sharpness > 0.5


def test_a_still_frame_without_the_board_gives_way_to_a_neighbour_showing_it(
        tiny_synth, monkeypatch) -> None:
    """The tiny session's 256x192 fisheye reads one tag of its board (the rest grown from
    it) in 26 of the 36 frames of its last hold, noise deciding; the still search chose one
    of the other ten. A still neighbour that shows the board takes its place, inside the
    hold and a frame or two from it."""
    from speechcal_core.frames import sets
    from speechcal_core.sources import open_recording

    folder, truth = tiny_synth
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")
    trig = truth["triggers"][-1]
    word = [Trigger(trig["word"], trig["start_s"], trig["end_s"])]
    fisheye = next(c["name"] for c in truth["cameras"] if c["model"] == "fisheye")
    found = {}
    for retries in (0, sets.STILL_RETRIES):
        monkeypatch.setattr(sets, "STILL_RETRIES", retries)
        with open_recording([str(folder / truth["recording"])]) as source:
            result = build_frame_sets(source, sync, word, TargetSpec(),
                                      FrameSetOptions(workers=2))
            period = source.stamps(fisheye)[1] - source.stamps(fisheye)[0]
        found[retries] = next(f for f in result.sets[0].frames if f.stream == fisheye)
    alone, retried = found[0], found[sets.STILL_RETRIES]
    assert alone.corners == 0 and "no-target" in alone.flags
    assert retried.corners >= 60 and "no-target" not in retried.flags
    assert 0 < abs(retried.stamp_ns - alone.stamp_ns) <= 2 * period
    start, end = trig["hold"]
    assert start <= retried.stamp_ns <= end
