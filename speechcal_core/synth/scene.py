"""Image-space scenery of the synthetic cameras: background, blinking light, fan, clap hands.

Everything here is drawn in pixel coordinates of one camera and integrated over the
exposure by sampling a few instants, so moving parts show motion blur. The clap hands
follow :data:`CLAP_APPROACH_S` / :data:`CLAP_SEPARATE_S`: their gap closes linearly and is
zero exactly at the clap, then opens again; frames exposed during
``[clap, clap + FLASH_S]`` also show a flash over :func:`hands_region`.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

CLAP_APPROACH_S = 0.45  # hands appear this long before the clap and close linearly
CLAP_SEPARATE_S = 0.30  # after the clap they open again over this time, then leave
FLASH_S = 0.025  # the flash lasts this long from the clap
FLASH_LEVEL = 110.0  # grey levels added at full exposure overlap
HAND_W = 0.075  # hand width, fraction of image width
HAND_H = 0.095  # hand height, fraction of image width
HAND_GAP = 0.12  # largest gap between the hands, fraction of image width
HANDS_CENTRE = (0.20, 0.80)  # where the hands meet, fractions of width and height
SKIN_BGR = (112.0, 150.0, 214.0)
FAN_CENTRE = (0.88, 0.15)
FAN_RADIUS = 0.055  # fraction of image width
FAN_REV_PER_S = 1.7
FAN_PHASES = 90  # precomputed blade positions per 120 degrees
FAN_BGR = (40, 45, 200)
LIGHT_CENTRE = (0.07, 0.09)
LIGHT_RADIUS = 0.02
LIGHT_PERIOD_S = 0.8
SHUTTER_SAMPLES = 6  # instants per exposure for the fan and the hands

Rect = tuple[int, int, int, int]  # x0, y0, x1, y1 (exclusive)


def make_background(width: int, height: int, rng: np.random.Generator) -> np.ndarray:
    """A seeded, textured room-like background (BGR uint8) with a few shapes."""
    # muted colours: a grey level per cell plus a little tint
    low = rng.uniform(70, 165, (4, 5, 1)) + rng.normal(0, 14, (4, 5, 3))
    img = cv2.resize(low.astype(np.float32), (width, height), interpolation=cv2.INTER_CUBIC)
    for cells, amp in ((12, 12.0), (48, 7.0)):
        shape = (max(2, height * cells // width), cells)
        noise = rng.normal(0, amp, (*shape, 1)) + rng.normal(0, amp / 4, (*shape, 3))
        img += cv2.resize(noise.astype(np.float32), (width, height),
                          interpolation=cv2.INTER_CUBIC)
    img = np.clip(img, 0, 255).astype(np.uint8)
    scale = width / 640
    for _ in range(22):
        colour = tuple(float(c) for c in rng.uniform(40, 200) + rng.normal(0, 25, 3))
        kind = rng.integers(0, 3)
        x, y = int(rng.uniform(0, width)), int(rng.uniform(0, height))
        size = int(rng.uniform(10, 70) * scale)
        if kind == 0:
            w, h = size, int(size * rng.uniform(0.4, 2.0))
            cv2.rectangle(img, (x, y), (x + w, y + h), colour, -1, cv2.LINE_AA)
        elif kind == 1:
            cv2.circle(img, (x, y), size // 2, colour, -1, cv2.LINE_AA)
        else:
            end = (x + int(rng.uniform(-2, 2) * size), y + int(rng.uniform(-2, 2) * size))
            cv2.line(img, (x, y), end, colour, max(1, int(3 * scale)), cv2.LINE_AA)
    # housings of the fan and the light
    fc, fr = _fan_geometry(width, height)
    cv2.circle(img, fc, int(fr * 1.15), (60, 60, 64), -1, cv2.LINE_AA)
    cv2.circle(img, fc, int(fr * 1.05), (150, 150, 150), -1, cv2.LINE_AA)
    lc, lr = _light_geometry(width, height)
    cv2.circle(img, lc, int(lr * 1.6), (40, 40, 40), -1, cv2.LINE_AA)
    return cv2.GaussianBlur(img, (0, 0), 0.8)


def _fan_geometry(width: int, height: int) -> tuple[tuple[int, int], int]:
    return (int(FAN_CENTRE[0] * width), int(FAN_CENTRE[1] * height)), int(FAN_RADIUS * width)


def _light_geometry(width: int, height: int) -> tuple[tuple[int, int], int]:
    r = max(2, int(LIGHT_RADIUS * width))
    return (int(LIGHT_CENTRE[0] * width), int(LIGHT_CENTRE[1] * height)), r


def fan_region(width: int, height: int) -> Rect:
    """Pixel rectangle the fan blades can touch."""
    (cx, cy), r = _fan_geometry(width, height)
    return _clip_rect((cx - r - 2, cy - r - 2, cx + r + 3, cy + r + 3), width, height)


def light_region(width: int, height: int) -> Rect:
    """Pixel rectangle of the blinking light."""
    (cx, cy), r = _light_geometry(width, height)
    return _clip_rect((cx - r - 2, cy - r - 2, cx + r + 3, cy + r + 3), width, height)


def hands_region(width: int, height: int) -> Rect:
    """Pixel rectangle the clap hands (and the flash) cover."""
    mx, my = HANDS_CENTRE[0] * width, HANDS_CENTRE[1] * height
    half_w = (HAND_GAP / 2 + HAND_W) * width + 4
    half_h = HAND_H * width / 2 + 4
    return _clip_rect((int(mx - half_w), int(my - half_h), math.ceil(mx + half_w),
                       math.ceil(my + half_h)), width, height)


def _clip_rect(rect: Rect, width: int, height: int) -> Rect:
    x0, y0, x1, y1 = rect
    return max(0, x0), max(0, y0), min(width, x1), min(height, y1)


class Fan:
    """The rotating fan of one camera, with blade masks precomputed for its exposure time.

    The three blades repeat every 120 degrees, so :data:`FAN_PHASES` masks, each already
    integrated over the exposure, cover every instant.
    """

    def __init__(self, width: int, height: int, exposure_s: float) -> None:
        self.width, self.height = width, height
        self.rect = fan_region(width, height)
        x0, y0, x1, y1 = self.rect
        (cx, cy), r = _fan_geometry(width, height)
        self._hub = (cx - x0, cy - y0, max(2, r // 6))
        sweep = 360.0 * FAN_REV_PER_S * exposure_s
        masks = []
        cover = np.zeros((y1 - y0, x1 - x0), np.float32)
        mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
        for step in range(FAN_PHASES):
            cover[:] = 0
            for k in range(SHUTTER_SAMPLES):
                angle = 120.0 * step / FAN_PHASES + sweep * (k + 0.5) / SHUTTER_SAMPLES
                mask[:] = 0
                for blade in range(3):
                    a = angle + 120.0 * blade
                    bx = cx - x0 + 0.5 * r * math.cos(math.radians(a))
                    by = cy - y0 + 0.5 * r * math.sin(math.radians(a))
                    cv2.ellipse(mask, (int(bx * 16), int(by * 16)), (int(r * 8), int(r * 3.2)),
                                a, 0, 360, 255, -1, cv2.LINE_AA, 4)
                cover += mask
            masks.append(cv2.cvtColor((cover / SHUTTER_SAMPLES).astype(np.uint8),
                                      cv2.COLOR_GRAY2BGR))
        self._masks = masks
        self._blades = np.empty_like(masks[0])
        self._blades[:] = FAN_BGR

    def draw(self, patch: np.ndarray, t0_s: float) -> None:
        """Draw the blades into ``patch`` (the image cut at ``rect``) for an exposure from t0."""
        turns = (t0_s * FAN_REV_PER_S * 3.0) % 1.0  # in units of 120 degrees
        a = self._masks[int(turns * FAN_PHASES) % FAN_PHASES]
        behind = cv2.multiply(patch, cv2.bitwise_not(a), scale=1.0 / 255.0)
        front = cv2.multiply(self._blades, a, scale=1.0 / 255.0)
        patch[:] = cv2.add(behind, front)
        cx, cy, r = self._hub
        cv2.circle(patch, (cx, cy), r, (30, 30, 30), -1, cv2.LINE_AA)


def draw_light(patch: np.ndarray, rect: Rect, width: int, height: int,
               t0_s: float, t1_s: float) -> None:
    """Draw the blinking light; its brightness is the lit fraction of the exposure."""
    (cx, cy), r = _light_geometry(width, height)
    lit = _on_fraction(t0_s, t1_s, LIGHT_PERIOD_S)
    colour = tuple(float(c) for c in np.array((30, 40, 45)) + lit * np.array((170, 215, 210)))
    cv2.circle(patch, (cx - rect[0], cy - rect[1]), r, colour, -1, cv2.LINE_AA)


def _on_fraction(t0: float, t1: float, period: float) -> float:
    """Fraction of [t0, t1] in the first half of each period (the light is on)."""
    if t1 <= t0:
        return 1.0 if (t0 % period) < period / 2 else 0.0

    def on_time(t: float) -> float:  # lit time in [0, t]
        whole, rest = divmod(t, period)
        return whole * period / 2 + min(rest, period / 2)

    return (on_time(t1) - on_time(t0)) / (t1 - t0)


def hands_gap(t_s: float, clap_s: float) -> float | None:
    """Gap between the hands as a fraction of the largest gap; None when no hands are shown."""
    d = t_s - clap_s
    if -CLAP_APPROACH_S <= d <= 0:
        return -d / CLAP_APPROACH_S
    if 0 < d <= CLAP_SEPARATE_S:
        return d / CLAP_SEPARATE_S
    return None


def draw_hands(frame: np.ndarray, claps_s: tuple[float, ...], t0_s: float, t1_s: float) -> bool:
    """Draw the clap hands and the flash into ``frame`` for the exposure [t0, t1] (seconds).

    Times are any common clock (the renderer uses seconds from the session start).
    Returns whether anything was drawn.
    """
    near = [c for c in claps_s
            if t1_s >= c - CLAP_APPROACH_S and t0_s <= c + CLAP_SEPARATE_S + FLASH_S]
    if not near:
        return False
    height, width = frame.shape[:2]
    rect = hands_region(width, height)
    x0, y0, x1, y1 = rect
    mx, my = HANDS_CENTRE[0] * width - x0, HANDS_CENTRE[1] * height - y0
    hw, hh, g0 = HAND_W * width, HAND_H * width, HAND_GAP * width
    cover = np.zeros((y1 - y0, x1 - x0), np.float32)
    mask = np.zeros_like(cover, dtype=np.uint8)
    for k in range(SHUTTER_SAMPLES):
        t = t0_s + (k + 0.5) / SHUTTER_SAMPLES * (t1_s - t0_s)
        gaps = [g for g in (hands_gap(t, c) for c in near) if g is not None]
        if not gaps:
            continue
        half = gaps[0] * g0 / 2
        mask[:] = 0
        for side in (-1, 1):
            inner = mx + side * half
            cx = inner + side * hw / 2
            _hand(mask, cx, my, hw, hh, side)
        cover += mask
    patch = frame[y0:y1, x0:x1]
    if cover.any():
        alpha = (cover / (255.0 * SHUTTER_SAMPLES))[..., None]
        shade = np.linspace(1.08, 0.88, patch.shape[0], dtype=np.float32)[:, None, None]
        skin = np.array(SKIN_BGR, np.float32) * shade
        patch[:] = (patch * (1 - alpha) + skin * alpha).astype(np.uint8)
    flash = sum(_overlap(t0_s, t1_s, c, c + FLASH_S) for c in near)
    if flash > 0:
        level = FLASH_LEVEL * flash / max(t1_s - t0_s, 1e-6)
        cv2.add(patch, (level, level, level, 0), dst=patch)
    return True


def _hand(mask: np.ndarray, cx: float, cy: float, w: float, h: float, side: int) -> None:
    """A rounded hand blob: palm with a thumb bump on top, fingers towards the other hand."""
    s = 16
    cv2.ellipse(mask, (int(cx * s), int(cy * s)), (int(w / 2 * s), int(h / 2 * s)), 0, 0, 360,
                255, -1, cv2.LINE_AA, 4)
    tx, ty = cx + side * 0.15 * w, cy - 0.45 * h
    cv2.ellipse(mask, (int(tx * s), int(ty * s)), (int(0.22 * w * s), int(0.16 * h * s)),
                -side * 30, 0, 360, 255, -1, cv2.LINE_AA, 4)


def _overlap(a0: float, a1: float, b0: float, b1: float) -> float:
    return max(0.0, min(a1, b1) - max(a0, b0))
