"""The plan of a synthetic session: cameras, clock, target trajectory, claps and speech slots.

Everything the video renderer and the audio renderer share is decided here, once, from the
seed, so the two sides agree by construction. Times are session (reference clock) ns; a
camera's header stamps add that camera's ``clock_offset_ns`` and jitter.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from speechcal_core.errors import UsageError
from speechcal_core.sync.model import SyncModel
from speechcal_core.synth.options import SynthOptions
from speechcal_core.target import TargetSpec

NS = 1_000_000_000
#: first frame of every synthetic recording, a plausible wall-clock stamp
SESSION_EPOCH_NS = 1_700_000_000 * NS
HOLD_RANGE_S = (0.8, 2.5)
MOVE_RANGE_S = (0.7, 1.6)
LEAD_IN_S = 1.5  # before the clap
CLAP_TO_FIRST_MOVE_S = 1.5
EARLY_TRIGGER_FRACTION = 0.2  # triggers said while the board is still settling
EARLY_MIN_MOVE_S = 1.0  # ... after a move this long at least (one word ends, the next starts)


@dataclass(frozen=True)
class CameraSpec:
    """One synthetic camera: model, intrinsics, mounting and clock behaviour."""

    name: str  # topic, e.g. "/cam0/image_raw"
    model: str  # "pinhole" (OpenCV 5-coefficient radtan) or "fisheye" (OpenCV equidistant)
    width: int
    height: int
    fps: float
    intrinsics: tuple[float, float, float, float]  # fx, fy, cx, cy
    distortion: tuple[float, ...]  # pinhole: k1 k2 p1 p2 k3; fisheye: k1 k2 k3 k4
    rotation_rig: tuple[tuple[float, float, float], ...]  # 3x3, camera-from-rig
    translation_rig: tuple[float, float, float]  # camera-from-rig, metres
    clock_offset_ns: int  # added to every header stamp of this camera
    jitter_ns: int  # std-dev of stamp jitter
    drop_rate: float  # probability that a frame is missing
    exposure_s: float
    rolling_shutter_s: float  # readout time top to bottom; 0 = global shutter

    @property
    def camera_matrix(self) -> np.ndarray:
        """3x3 K matrix."""
        fx, fy, cx, cy = self.intrinsics
        return np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]], dtype=np.float64)

    def truth_dict(self) -> dict:
        """The camera's entry in truth.json."""
        return {
            "name": self.name,
            "model": self.model,
            "width": self.width,
            "height": self.height,
            "fps": self.fps,
            "intrinsics": list(self.intrinsics),
            "distortion": list(self.distortion),
            "T_cam_rig": {"R": [list(r) for r in self.rotation_rig],
                          "t": list(self.translation_rig)},
            "clock_offset_ns": self.clock_offset_ns,
            "jitter_ns": self.jitter_ns,
            "drop_rate": self.drop_rate,
            "exposure_s": self.exposure_s,
            "rolling_shutter_s": self.rolling_shutter_s,
        }


@dataclass(frozen=True)
class Pose:
    """Target pose in the rig frame: ``x_rig = R @ x_target + t``."""

    rotation: np.ndarray  # 3x3
    translation: np.ndarray  # 3


@dataclass(frozen=True)
class Segment:
    """A still hold (``from_pose == to_pose``) or a move between two poses."""

    start_ns: int
    end_ns: int
    from_pose: int
    to_pose: int
    kind: str = "hold"  # "hold" (a trigger is said), "move", or "rest" (before/after)

    @property
    def is_hold(self) -> bool:
        return self.from_pose == self.to_pose


@dataclass(frozen=True)
class SpeechSlot:
    """Where the audio renderer places one spoken item.

    ``align`` is ``"center"`` (the word's midpoint at ``anchor_ns``) or ``"end"`` (the
    word ends at ``anchor_ns``, i.e. it is said while the board is still settling).
    ``kind`` is ``"trigger"`` or ``"distractor"``; ``hold`` the hold index for triggers.
    """

    kind: str
    anchor_ns: int
    align: str = "center"
    hold: int = -1
    max_duration_s: float = 1.2


@dataclass(frozen=True)
class Timeline:
    """The whole plan of a synthetic session."""

    options: SynthOptions
    target: TargetSpec
    cameras: tuple[CameraSpec, ...]
    start_ns: int
    end_ns: int
    poses: tuple[Pose, ...]
    segments: tuple[Segment, ...]
    claps_ns: tuple[int, ...]
    speech: tuple[SpeechSlot, ...]
    sync: SyncModel
    audio_duration_s: float
    seed_sequence: np.random.SeedSequence = field(repr=False)

    @property
    def holds(self) -> list[Segment]:
        """The still holds in which a trigger is said, in time order (index = hold index)."""
        return [s for s in self.segments if s.kind == "hold"]

    def rng(self, purpose: str) -> np.random.Generator:
        """An independent generator per purpose, stable for a given seed."""
        key = sum(ord(ch) * 31**i for i, ch in enumerate(purpose)) % (2**32)
        return np.random.default_rng([self.options.seed, key])

    def pose_at(self, t_ns: int | float) -> tuple[np.ndarray, np.ndarray]:
        """Target rotation (3x3) and translation (3) in the rig frame at session time t."""
        seg = self.segment_at(t_ns)
        a, b = self.poses[seg.from_pose], self.poses[seg.to_pose]
        if seg.is_hold:
            return a.rotation, a.translation
        u = (float(t_ns) - seg.start_ns) / max(1, seg.end_ns - seg.start_ns)
        s = 0.5 - 0.5 * np.cos(np.pi * min(max(u, 0.0), 1.0))  # smooth start and stop
        return _slerp(a.rotation, b.rotation, s), (1 - s) * a.translation + s * b.translation

    def segment_at(self, t_ns: int | float) -> Segment:
        """The hold or move covering t (clamped to the first/last segment)."""
        for seg in self.segments:
            if t_ns < seg.end_ns:
                return seg
        return self.segments[-1]


def plan_session(options: SynthOptions) -> Timeline:
    """Decide cameras, trajectory, claps, speech slots and clocks from the options' seed."""
    ss = np.random.SeedSequence(options.seed)
    rng = np.random.default_rng(ss.spawn(1)[0])
    target = TargetSpec(kind=options.target_kind,
                        rows=6,
                        cols=6 if options.target_kind == "aprilgrid" else 8,
                        size=0.055 if options.target_kind == "aprilgrid" else 0.045)
    cameras = tuple(_make_camera(i, options, rng) for i in range(options.cameras))
    start_ns = SESSION_EPOCH_NS + int(rng.integers(0, 1000)) * 1_000_000
    end_ns = start_ns + int(options.duration * NS)

    poses = [_random_pose(target, rng, first=True)]
    segments: list[Segment] = []
    speech: list[SpeechSlot] = []
    claps = [start_ns + int(LEAD_IN_S * NS)]
    t = claps[0] + int(CLAP_TO_FIRST_MOVE_S * NS)
    # the board rests at pose 0 from the start through the clap
    segments.append(Segment(start_ns, t, 0, 0, "rest"))
    tail_ns = int((3.0 if options.claps == 2 else 0.8) * NS)
    hold_index = 0
    while True:
        move_ns = int(rng.uniform(*MOVE_RANGE_S) * NS)
        hold_ns = int(rng.uniform(*HOLD_RANGE_S) * NS)
        if t + move_ns + hold_ns > end_ns - tail_ns:
            break
        if options.triggers is not None and hold_index >= options.triggers:
            break
        poses.append(_random_pose(target, rng))
        p = len(poses) - 1
        segments.append(Segment(t, t + move_ns, p - 1, p, "move"))
        # distractor speech during some moves
        if rng.random() < 0.6:
            speech.append(SpeechSlot("distractor", t + move_ns // 2, "center", -1,
                                     max_duration_s=move_ns / NS * 0.9))
        t += move_ns
        segments.append(Segment(t, t + hold_ns, p, p))
        early = rng.random() < EARLY_TRIGGER_FRACTION
        if early and move_ns >= int(EARLY_MIN_MOVE_S * NS):
            # said while settling: the word ends up to 0.3 s before the hold starts, and
            # (words last up to 0.8 s) clear of the previous hold's word
            lead = min(0.3, move_ns / NS - EARLY_MIN_MOVE_S)
            anchor = t - int(rng.uniform(0.0, lead) * NS)
            speech.append(SpeechSlot("trigger", anchor, "end", hold_index))
        else:
            lo, hi = t + int(0.35 * NS), t + hold_ns - int(0.35 * NS)
            anchor = int(rng.uniform(lo, max(lo, hi)))
            speech.append(SpeechSlot("trigger", anchor, "center", hold_index))
        t += hold_ns
        hold_index += 1
    if options.triggers is not None and hold_index < options.triggers:
        raise UsageError(
            f"--duration {options.duration:g} s holds only {hold_index} triggers, "
            f"{options.triggers} asked; give a longer --duration"
        )
    # rest at the last pose until the end; optional closing clap
    segments.append(Segment(t, end_ns + NS, len(poses) - 1, len(poses) - 1, "rest"))
    if options.claps == 2:
        claps.append(end_ns - int(1.5 * NS))

    # microphone clock: audio starts 0.5-2.5 s before the first frame, drifts
    drift = options.drift_ppm * 1e-6
    audio_lead_s = float(rng.uniform(0.5, 2.5))
    sync = SyncModel(offset_ns=start_ns - int(audio_lead_s * NS), drift=drift, source="truth")
    audio_duration_s = float(sync.to_audio(end_ns)) + float(rng.uniform(0.5, 1.5))
    return Timeline(options, target, cameras, start_ns, end_ns, tuple(poses), tuple(segments),
                    tuple(claps), tuple(speech), sync, audio_duration_s, ss)


def _make_camera(i: int, options: SynthOptions, rng: np.random.Generator) -> CameraSpec:
    fisheye = i >= options.cameras - options.fisheye
    w, h = options.width, options.height
    if fisheye:
        # equidistant, about 145 degrees across the diagonal and 115 across the width: a
        # full-frame fisheye (every pixel sees), not a circular one (at 16:9, 125-140 across
        # the diagonal; a pinhole fit's focal length alone calls it 90 wide). The board,
        # placed for the pinholes, reaches only 30-35 degrees off its axis (a fit learns the
        # lens no further out) and looks about half as wide here as there, its tags mostly
        # 17-27 px, which detection needs. (w / 3.2 was 230 degrees across the diagonal,
        # wider than any full-frame fisheye: the board about 110 px wide, tags of 9-17 px,
        # mostly missed.)
        f = w / 2.0 * rng.uniform(0.95, 1.05)
        dist: tuple[float, ...] = tuple(float(x) for x in (
            rng.uniform(-0.05, 0.05), rng.uniform(-0.02, 0.02),
            rng.uniform(-0.01, 0.01), rng.uniform(-0.005, 0.005)))
    else:
        f = w * 0.95 * rng.uniform(0.9, 1.1)
        dist = tuple(float(x) for x in (
            rng.uniform(-0.25, 0.05), rng.uniform(-0.05, 0.1),
            rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3), 0.0))
    cx = w / 2 + rng.uniform(-0.03, 0.03) * w
    cy = h / 2 + rng.uniform(-0.03, 0.03) * h
    # cameras on a horizontal bar, 12 cm apart, toed in towards a point 1 m ahead
    x = (i - (options.cameras - 1) / 2) * 0.12
    yaw = np.arctan2(x, 1.0)
    rot = _rot_y(yaw)  # camera-from-rig: turning the camera towards the centre
    trans = -rot @ np.array([x, 0.0, 0.0])
    fps = 30.0 if i % 2 == 0 else 15.0
    return CameraSpec(
        name=f"/cam{i}/image_raw",
        model="fisheye" if fisheye else "pinhole",
        width=w, height=h, fps=fps,
        intrinsics=(float(f), float(f * rng.uniform(0.998, 1.002)), float(cx), float(cy)),
        distortion=dist,
        rotation_rig=tuple(tuple(float(v) for v in row) for row in rot),
        translation_rig=tuple(float(v) for v in trans),
        clock_offset_ns=int(rng.uniform(-4e6, 4e6)),
        jitter_ns=int(rng.uniform(0.2e6, 1.0e6)),
        drop_rate=0.01,
        exposure_s=float(rng.uniform(0.008, 0.016)),
        rolling_shutter_s=0.02 if options.rolling_shutter else 0.0,
    )


def _random_pose(target: TargetSpec, rng: np.random.Generator, first: bool = False) -> Pose:
    """A target pose facing the rig at 0.55-0.9 m, tilted up to ~35 degrees.

    As an operator holds it: as close as the pinholes (about 55 degrees wide) still see all
    of it, and never so far that it shrinks to a small patch of a wide lens's image. Draws
    from ``rng`` as many numbers, in the same order, whatever the ranges (the speech slots
    drawn after them stay put).
    """
    w, h = target.extent
    dist = rng.uniform(0.75, 0.9) if first else rng.uniform(0.55, 0.9)
    tilt = 0.0 if first else 0.6
    rx, ry = rng.uniform(-tilt, tilt, 2)
    rz = rng.uniform(-0.3, 0.3) if not first else 0.0
    # printed side towards the rig: target z points at the cameras, x right, y up, so the
    # cameras see Kalibr's sheet as printed (tag 0 lower left), not its mirror image
    rot = _rot_z(rz) @ _rot_y(ry) @ _rot_x(rx) @ _rot_x(np.pi)
    centre = np.array([rng.uniform(-0.08, 0.08), rng.uniform(-0.06, 0.06), dist])
    if first:
        centre[:2] = 0.0
    # the target's own origin sits at its corner; place its centre at `centre`
    translation = centre - rot @ np.array([w / 2, h / 2, 0.0])
    return Pose(rot, translation)


def _rot_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _slerp(ra: np.ndarray, rb: np.ndarray, s: float) -> np.ndarray:
    """Rotation s of the way from ra to rb (geodesic)."""
    import cv2

    rel = ra.T @ rb
    rvec, _ = cv2.Rodrigues(rel)
    step, _ = cv2.Rodrigues(rvec * s)
    return ra @ step
