"""The "blurred" flag: a still board is sharp at any distance, a board that never stops is not."""

from __future__ import annotations

import cv2
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
FPS = 30
K = np.array([[400.0, 0, 240], [0, 400, 180], [0, 0, 1]])


def _view(target: TargetSpec, distance: float, shift: float = 0.0,
          blur_px: int = 0) -> np.ndarray:
    """A 480x360 view of the board; ``blur_px``: smeared along the diagonal (a fast move)."""
    rvec, tvec = facing_pose(target, distance, (0.2, 0.1), (shift, 0.0))
    img = render_view(target, K, rvec, tvec, (480, 360), noise=0)
    if blur_px:
        img = cv2.filter2D(img, -1, np.eye(blur_px, dtype=np.float32) / blur_px)
    return img


def _stream(frames: list[np.ndarray], seed: int = 0) -> tuple[np.ndarray, list[np.ndarray]]:
    """Stamps at FPS and ``frames``, each with its own sensor noise."""
    rng = np.random.default_rng(seed)
    noisy = [np.clip(f + rng.normal(0, 2, f.shape), 0, 255).astype(np.uint8) for f in frames]
    return np.arange(len(frames), dtype=np.int64) * (NS // FPS) + 10 * NS, noisy


def _source(frames: list[np.ndarray]) -> ArraySource:
    """One camera showing ``frames``."""
    return ArraySource({"/cam": _stream(frames)})


def _words(at_s: tuple[float, ...]) -> list[Trigger]:
    return [Trigger("capture", t - 0.1, t + 0.1) for t in at_s]


def test_a_board_held_still_is_sharp_at_any_distance() -> None:
    # the QA session whose chosen frames of set 2 were flagged blurred inside a still hold
    # (0.24 and 0.25 of the session's sharp frames: the board was near, its edges sparse)
    timeline = plan_session(SynthOptions(cameras=5, duration=40, rolling_shutter=True,
                                         claps=2, seed=8, width=640, height=400))
    source = RenderedSource(timeline)
    words = [s for s in timeline.speech if s.kind == "trigger"]
    triggers = []
    for slot in words:
        end = slot.anchor_ns if slot.align == "end" else slot.anchor_ns + NS // 4
        end_s = float(timeline.sync.to_audio(end))
        triggers.append(Trigger("capture", end_s - 0.5, end_s))
    result = build_frame_sets(source, timeline.sync, triggers, timeline.target,
                              FrameSetOptions(workers=2))
    widths = []
    for fs, slot in zip(result.sets, words, strict=True):
        hold = timeline.holds[slot.hold]
        for f in fs.frames:
            assert hold.start_ns <= source.true_ns(f.stream)[f.index] <= hold.end_ns
            assert "blurred" not in f.flags and f.sharpness is not None
            assert f.sharpness > 0.95, (fs.id, f.stream, f.sharpness)
        points = result.detections[(fs.id, "/cam2/image_raw")].points
        widths.append(float(np.ptp(points[:, 0])))
    assert max(widths) > 1.3 * min(widths)  # the board seen near and far


def test_a_still_frame_is_judged_against_its_own_hold_not_a_nearer_one() -> None:
    target = TargetSpec()
    near, far = _view(target, 0.5), _view(target, 1.0)
    # held near for 1 s, then far: the window around the first word sees both holds, and
    # the far board, with more edges per pixel, scores far higher than the near one
    source = _source([near] * FPS + [far] * 2 * FPS)
    result = build_frame_sets(source, SyncModel(10 * NS), _words((0.5, 2.0)), target)
    first, second = (fs.frames[0] for fs in result.sets)
    assert first.index < FPS and second.index >= FPS
    for f in (first, second):
        assert "blurred" not in f.flags and f.sharpness is not None and f.sharpness > 0.95


def test_a_board_that_never_stops_in_the_window_is_flagged_blurred() -> None:
    target = TargetSpec()
    # still for 2 s, then sliding (smeared by its motion) for 2 s, then still again
    moving = [_view(target, 0.6, -0.05 + 0.1 * i / (2 * FPS - 1), blur_px=4)
              for i in range(2 * FPS)]
    source = _source([_view(target, 0.6, -0.05)] * 2 * FPS + moving
                     + [_view(target, 0.6, 0.05)] * 2 * FPS)
    result = build_frame_sets(source, SyncModel(10 * NS), _words((1.0, 3.0, 5.0)), target,
                              FrameSetOptions(window_s=(-0.3, 0.3), extend_s=0))
    before, during, after = (fs.frames[0] for fs in result.sets)
    assert {"blurred", "moving"} <= set(during.flags)
    assert during.sharpness is not None and during.sharpness < 0.25
    for f in (before, after):
        assert f.flags == () and f.sharpness is not None and f.sharpness > 0.95


def test_a_moving_frame_beside_a_still_stretch_is_judged_against_that_stretch() -> None:
    target = TargetSpec()

    def camera(move: tuple[float, float]) -> list[np.ndarray]:
        """2.2 s of the board sliding diagonally (0.1 m/s each way, smeared over ~3 px) from
        ``move[0]`` to ``move[1]`` (s), held still before and after."""
        frames = []
        for i in range(round(2.2 * FPS)):
            t = i / FPS
            moving = move[0] < t < move[1]
            d = 0.1 * (min(max(t, move[0]), move[1]) - move[0]) - 0.05
            rvec, tvec = facing_pose(target, 0.6, (0.2, 0.1), (d, d))
            img = render_view(target, K, rvec, tvec, (480, 360), noise=0)
            if moving:
                img = cv2.filter2D(img, -1, np.eye(3, dtype=np.float32) / 3)
            frames.append(img)
        return frames

    # one camera starts moving just before the word, the other stops just after: no moment
    # has both still, and a frame chosen while its camera moves lies next to its hold
    source = ArraySource({"/a": _stream(camera((1.4, 2.2))),
                          "/b": _stream(camera((0.8, 1.6)), seed=1)})
    result = build_frame_sets(source, SyncModel(10 * NS), _words((1.5,)), target,
                              FrameSetOptions(window_s=(-0.3, 0.3), extend_s=0))
    moving = [f for f in result.sets[0].frames if "moving" in f.flags]
    assert moving
    for f in moving:  # about a third as sharp as the still board beside it, at full size
        assert "blurred" in f.flags and f.sharpness is not None and f.sharpness < 0.5
