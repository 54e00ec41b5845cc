"""Render synthetic camera frames: the target projected through each lens, blur, scenery, noise.

Per camera the undistorted viewing ray of every pixel is computed once; a frame then maps
rays to texels with one 3x3 homography (target plane <- camera) and samples the target
texture with ``cv2.remap``. Motion blur averages sub-exposure samples whose number follows
the image-space displacement during the exposure; with a rolling shutter each band of rows
has its own exposure time. Frames inside a still hold reuse a cached target layer.
Content is rendered at the *true* (reference clock) time, never the camera's stamp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np

from speechcal_core.synth import scene
from speechcal_core.synth.camera_model import pixel_rays
from speechcal_core.synth.target_texture import TargetTexture, make_target_texture
from speechcal_core.synth.timeline import CameraSpec, Segment, Timeline

NS = 1_000_000_000
COARSE_STEP = 8  # pixel step of the grid used to find the target's image region
MAX_BLUR_STEP_PX = 1.5  # image-space displacement between two sub-exposure samples
MAX_SAMPLES = 24
RS_BAND_ROWS = 16  # rows per band of equal exposure time with a rolling shutter
NOISE_SIGMA = 2.0  # grey levels
NOISE_SLACK = 1 << 16  # extra noise samples so each frame can take a random window
PAPER_TINT_BGR = (0.97, 1.0, 1.0)
CACHE_HOLDS = 4  # cached still-hold layers per camera
OFF_TEXTURE = -1.0e4  # map value for pixels whose ray misses the target plane


@dataclass
class TargetLayer:
    """The target as seen by one camera in one frame, on the rectangle ``rect``.

    ``premult`` is grey premultiplied by coverage, ``alpha`` the coverage (both uint8).
    """

    rect: tuple[int, int, int, int]
    premult: np.ndarray
    alpha: np.ndarray
    colour: np.ndarray  # BGR multiplier of the paper under this frame's light
    samples: int = 1


@dataclass
class _CameraState:
    camera: CameraSpec
    rays: np.ndarray  # H x W x 3 float32 unit rays (zero where the lens has none)
    coarse: np.ndarray  # the same every COARSE_STEP pixels
    coarse_valid: np.ndarray
    rot_rig: np.ndarray
    trans_rig: np.ndarray
    background: np.ndarray
    noise_pos: np.ndarray
    noise_neg: np.ndarray
    fan: scene.Fan
    holds: dict[int, tuple[TargetLayer | None, np.ndarray]] = field(default_factory=dict)


class FrameRenderer:
    """Renders frames of every camera of one timeline; keeps per-camera state and caches."""

    def __init__(self, timeline: Timeline) -> None:
        self.timeline = timeline
        max_f = max(max(c.intrinsics[:2]) for c in timeline.cameras)
        # about one texel per pixel at the closest plausible distance
        self.texture: TargetTexture = make_target_texture(timeline.target, 1.2 * max_f / 0.5)
        self._states: dict[int, _CameraState] = {}
        self._segment_index = {id(s): i for i, s in enumerate(timeline.segments)}

    # ---- public -------------------------------------------------------------------------
    def render(self, camera_index: int, t_true_ns: int) -> np.ndarray:
        """The BGR uint8 frame of camera ``camera_index`` exposed around true time ``t_true_ns``."""
        st = self._state(camera_index)
        cam = st.camera
        t_ns = int(t_true_ns)
        half_ns = int((cam.exposure_s + cam.rolling_shutter_s) * NS / 2)
        seg = self.timeline.segment_at(t_ns - half_ns)
        still = seg.is_hold and seg is self.timeline.segment_at(t_ns + half_ns)
        if still:
            frame, layer = self._still_frame(st, seg, t_ns)
        else:
            layer = self.target_layer(camera_index, t_ns)
            frame = st.background.copy()
            if layer is not None:
                _blend(frame, (0, 0, cam.width, cam.height), layer)
        self._draw_scenery(st, frame, layer, t_ns)
        self._add_noise(st, frame, camera_index, t_ns)
        return frame

    def target_layer(self, camera_index: int, t_true_ns: int) -> TargetLayer | None:
        """The target (blurred over the exposure) for one frame, or None when out of view."""
        st = self._state(camera_index)
        cam = st.camera
        e_ns = cam.exposure_s * NS
        rs_ns = cam.rolling_shutter_s * NS
        t = float(t_true_ns)
        found = self._target_region(st, t, e_ns, rs_ns)
        if found is None:
            return None
        (x0, y0, x1, y1), texels_per_px, shift_px = found
        # samples at most MAX_BLUR_STEP_PX apart; under half a pixel of travel, no blur
        samples = min(MAX_SAMPLES, max(2, math.ceil(shift_px / MAX_BLUR_STEP_PX))
                      if shift_px >= 0.5 else 1)
        levels = self.texture.levels
        level = min(len(levels) - 1, max(0, math.floor(math.log2(max(texels_per_px, 1.0)))))
        tex = levels[level]
        to_texel = self.texture.target_to_texel(level)
        if rs_ns > 0:
            bands = [(y, min(y + RS_BAND_ROWS, y1)) for y in range(y0, y1, RS_BAND_ROWS)]
        else:
            bands = [(y0, y1)]
        plans = []
        for b0, b1 in bands:
            row_t = t + rs_ns * ((b0 + b1 - 1) / 2 / cam.height - 0.5)
            rays = st.rays[b0:b1, x0:x1]
            if samples == 1:
                g = to_texel @ self._plane_from_camera(st, row_t)
                plans.append((b0, b1, _apply_homography(g, rays), None))
                continue
            g0 = to_texel @ self._plane_from_camera(st, row_t - e_ns / 2)
            g1 = to_texel @ self._plane_from_camera(st, row_t + e_ns / 2)
            plans.append((b0, b1, _apply_homography(g0, rays), _apply_homography(g1, rays)))
        shape = (y1 - y0, x1 - x0)
        premult = np.empty(shape, np.uint8)
        alpha = np.empty(shape, np.uint8)
        for b0, b1, m0, m1 in plans:
            rows = slice(b0 - y0, b1 - y0)
            if m1 is None:
                mx, my = m0
                warped = _sample(tex, mx, my)
                premult[rows] = warped[..., 0]
                alpha[rows] = warped[..., 1]
                continue
            acc = np.zeros((b1 - b0, x1 - x0, 4), np.float32)
            for k in range(samples):
                mx, my = _mix(m0, m1, (k + 0.5) / samples)
                cv2.accumulate(_sample(tex, mx, my), acc)
            mean = cv2.convertScaleAbs(acc, alpha=1.0 / samples)
            premult[rows] = mean[..., 0]
            alpha[rows] = mean[..., 1]
        return TargetLayer((x0, y0, x1, y1), premult, alpha, self._paper_colour(st, t), samples)

    # ---- geometry -----------------------------------------------------------------------
    def _state(self, i: int) -> _CameraState:
        st = self._states.get(i)
        if st is None:
            cam = self.timeline.cameras[i]
            rays, valid = pixel_rays(cam)
            rays[~valid] = 0.0
            coarse, coarse_valid = pixel_rays(cam, COARSE_STEP)
            bg = scene.make_background(cam.width, cam.height, self.timeline.rng(f"bg{i}"))
            rng = self.timeline.rng(f"noise{i}")
            n = cam.width * cam.height * 3 + NOISE_SLACK
            noise = np.round(rng.normal(0.0, NOISE_SIGMA, n)).clip(-127, 127)
            st = _CameraState(
                camera=cam,
                rays=rays,
                coarse=coarse,
                coarse_valid=coarse_valid,
                rot_rig=np.asarray(cam.rotation_rig, np.float64),
                trans_rig=np.asarray(cam.translation_rig, np.float64),
                background=bg,
                noise_pos=np.maximum(noise, 0).astype(np.uint8),
                noise_neg=np.maximum(-noise, 0).astype(np.uint8),
                fan=scene.Fan(cam.width, cam.height, cam.exposure_s),
            )
            self._states[i] = st
        return st

    def _target_in_camera(self, st: _CameraState, t_ns: float) -> tuple[np.ndarray, np.ndarray]:
        rot, trans = self.timeline.pose_at(t_ns)
        return st.rot_rig @ rot, st.rot_rig @ trans + st.trans_rig

    def _plane_from_camera(self, st: _CameraState, t_ns: float) -> np.ndarray:
        """3x3 matrix taking a camera ray to homogeneous target-plane ``(x, y, 1)``."""
        rot, trans = self._target_in_camera(st, t_ns)
        m = np.column_stack([rot[:, 0], rot[:, 1], trans])
        return np.linalg.inv(m)

    def _target_region(self, st: _CameraState, t: float, e_ns: float, rs_ns: float
                       ) -> tuple[tuple[int, int, int, int], float, float] | None:
        """Where the card is during one exposure, on the coarse pixel grid.

        Returns the pixel rectangle it covers at any instant of the exposure (all rows),
        texels (level 0) per image pixel there, and the largest image-space displacement
        of a card point during the exposure of one row; None when the card is not in view.
        """
        tex = self.texture.levels[0]
        to_texel = self.texture.target_to_texel(0)
        hit = np.zeros(st.coarse_valid.shape, bool)
        maps = {}
        for t_k in {t - e_ns / 2 - rs_ns / 2, t - e_ns / 2, t, t + e_ns / 2,
                    t + e_ns / 2 + rs_ns / 2}:
            maps[t_k] = uv = _apply_homography(to_texel @ self._plane_from_camera(st, t_k),
                                               st.coarse)
            hit |= _on_card(uv, tex, margin=2.0) & st.coarse_valid
        if not hit.any():
            return None
        u, v = maps[t]
        inside = _on_card((u, v), tex) & st.coarse_valid
        scale = 1.0
        if inside[:, 1:].any() and inside[1:, :].any():
            du = np.hypot(np.diff(u, axis=1), np.diff(v, axis=1))[inside[:, 1:]]
            dv = np.hypot(np.diff(u, axis=0), np.diff(v, axis=0))[inside[1:, :]]
            if du.size and dv.size:
                scale = math.sqrt(float(np.median(du)) * float(np.median(dv))) / COARSE_STEP
        (u0, v0), (u1, v1) = maps[t - e_ns / 2], maps[t + e_ns / 2]
        moved = hit & (np.abs(u0) < 1e6) & (np.abs(u1) < 1e6)
        shift = float(np.hypot(u1 - u0, v1 - v0)[moved].max()) / scale if moved.any() else 0.0
        rows = np.flatnonzero(hit.any(axis=1))
        cols = np.flatnonzero(hit.any(axis=0))
        cam = st.camera
        pad = COARSE_STEP + 2
        x0 = max(0, int(cols[0]) * COARSE_STEP - pad)
        x1 = min(cam.width, int(cols[-1]) * COARSE_STEP + pad + 1)
        y0 = max(0, int(rows[0]) * COARSE_STEP - pad)
        y1 = min(cam.height, int(rows[-1]) * COARSE_STEP + pad + 1)
        return (x0, y0, x1, y1), scale, shift

    def _paper_colour(self, st: _CameraState, t_ns: float) -> np.ndarray:
        """Paper brightness under a light near the camera: darker when tilted away."""
        rot, _ = self._target_in_camera(st, t_ns)
        facing = abs(float(rot[2, 2]))
        return np.asarray(PAPER_TINT_BGR, np.float32) * np.float32(0.82 + 0.18 * facing)

    # ---- frame assembly -----------------------------------------------------------------
    def _still_frame(self, st: _CameraState, seg: Segment, t_ns: int
                     ) -> tuple[np.ndarray, TargetLayer | None]:
        key = self._segment_index[id(seg)]
        cached = st.holds.get(key)
        if cached is None:
            mid = (seg.start_ns + seg.end_ns) // 2  # any instant of the hold: same pose
            layer = self.target_layer(self.timeline.cameras.index(st.camera), mid)
            frame = st.background.copy()
            if layer is not None:
                _blend(frame, (0, 0, st.camera.width, st.camera.height), layer)
            if len(st.holds) >= CACHE_HOLDS:
                st.holds.pop(next(iter(st.holds)))
            cached = st.holds[key] = (layer, frame)
        layer, frame = cached
        return frame.copy(), layer

    def _draw_scenery(self, st: _CameraState, frame: np.ndarray, layer: TargetLayer | None,
                      t_ns: int) -> None:
        cam = st.camera
        w, h = cam.width, cam.height
        origin = self.timeline.start_ns
        for region in (st.fan.rect, scene.light_region(w, h)):
            x0, y0, x1, y1 = region
            row_s = cam.rolling_shutter_s * ((y0 + y1) / 2 / h - 0.5)
            t0 = (t_ns - origin) / NS + row_s - cam.exposure_s / 2
            patch = st.background[y0:y1, x0:x1].copy()
            if region == st.fan.rect:
                st.fan.draw(patch, t0)
            else:
                scene.draw_light(patch, region, w, h, t0, t0 + cam.exposure_s)
            if layer is not None:
                _blend(patch, region, layer)
            frame[y0:y1, x0:x1] = patch
        x0, y0, x1, y1 = scene.hands_region(w, h)
        row_s = cam.rolling_shutter_s * ((y0 + y1) / 2 / h - 0.5)
        t0 = (t_ns - origin) / NS + row_s - cam.exposure_s / 2
        claps = tuple((c - origin) / NS for c in self.timeline.claps_ns)
        scene.draw_hands(frame, claps, t0, t0 + cam.exposure_s)

    def _add_noise(self, st: _CameraState, frame: np.ndarray, camera_index: int,
                   t_ns: int) -> None:
        seed = (self.timeline.options.seed, camera_index, t_ns & 0xFFFFFFFF, t_ns >> 32)
        offset = int(np.random.default_rng(seed).integers(0, NOISE_SLACK))
        n = frame.size
        shape = frame.shape
        cv2.add(frame, st.noise_pos[offset : offset + n].reshape(shape), dst=frame)
        cv2.subtract(frame, st.noise_neg[offset : offset + n].reshape(shape), dst=frame)


def _apply_homography(g: np.ndarray, rays: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Texel coordinates (float32 maps) of rays under ``g``; rays missing the plane go far off."""
    u, v, w = cv2.split(cv2.transform(rays, g.astype(np.float32)))
    miss = w <= 1e-9
    u = cv2.divide(u, w)
    v = cv2.divide(v, w)
    u[miss] = OFF_TEXTURE
    v[miss] = OFF_TEXTURE
    return u, v


def _mix(m0: tuple[np.ndarray, np.ndarray], m1: tuple[np.ndarray, np.ndarray], f: float
         ) -> tuple[np.ndarray, np.ndarray]:
    """Maps a fraction ``f`` of the way from ``m0`` to ``m1`` (motion within one exposure)."""
    return (cv2.addWeighted(m0[0], 1 - f, m1[0], f, 0.0),
            cv2.addWeighted(m0[1], 1 - f, m1[1], f, 0.0))


def _sample(texture: np.ndarray, mx: np.ndarray, my: np.ndarray) -> np.ndarray:
    return cv2.remap(texture, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                     borderValue=0)


def _on_card(uv: tuple[np.ndarray, np.ndarray], tex: np.ndarray, margin: float = 1.0
             ) -> np.ndarray:
    u, v = uv
    h, w = tex.shape[:2]
    return (u > -margin) & (u < w - 1 + margin) & (v > -margin) & (v < h - 1 + margin)


def _blend(dst: np.ndarray, dst_rect: tuple[int, int, int, int], layer: TargetLayer) -> None:
    """Composite ``layer`` over ``dst`` (the image cut at ``dst_rect``) where they overlap."""
    ax0, ay0, ax1, ay1 = dst_rect
    bx0, by0, bx1, by1 = layer.rect
    x0, y0, x1, y1 = max(ax0, bx0), max(ay0, by0), min(ax1, bx1), min(ay1, by1)
    if x0 >= x1 or y0 >= y1:
        return
    alpha = layer.alpha[y0 - by0 : y1 - by0, x0 - bx0 : x1 - bx0]
    grey = layer.premult[y0 - by0 : y1 - by0, x0 - bx0 : x1 - bx0]
    view = dst[y0 - ay0 : y1 - ay0, x0 - ax0 : x1 - ax0]
    keep = cv2.cvtColor(cv2.bitwise_not(alpha), cv2.COLOR_GRAY2BGR)
    behind = cv2.multiply(view, keep, scale=1.0 / 255.0)
    paper = cv2.multiply(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR),
                         (*(float(c) for c in layer.colour), 0.0))
    view[:] = cv2.add(behind, paper)


_CACHE: list[FrameRenderer] = []


def renderer_for(timeline: Timeline) -> FrameRenderer:
    """A renderer for ``timeline``, reused while the same timeline object is asked for."""
    for r in _CACHE:
        if r.timeline is timeline:
            return r
    r = FrameRenderer(timeline)
    _CACHE[:] = [*_CACHE[-1:], r]
    return r


def render_frame(timeline: Timeline, camera_index: int, t_true_ns: int) -> np.ndarray:
    """Camera ``camera_index``'s BGR uint8 frame exposed around true time ``t_true_ns``."""
    return renderer_for(timeline).render(camera_index, t_true_ns)
