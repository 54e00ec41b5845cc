"""Small synthetic camera clips with a clap, a blinking light, a fan and a still board."""

from __future__ import annotations

import numpy as np


def clap_clip(*, fps: float = 30.0, seconds: float = 4.0, clap_s: float = 1.5,
              width: int = 160, height: int = 120, exposure_s: float = 0.012,
              seed: int = 0, hands_at: tuple[float, float] = (0.25, 0.8),
              flash: bool = True, board_move_s: float | None = 3.0,
              stamp_jitter_s: float = 0.0) -> tuple[list[np.ndarray], np.ndarray]:
    """Gray uint8 frames and their stamps (ns, mid-exposure) around a hand clap at clap_s."""
    rng = np.random.default_rng(seed)
    bg = rng.uniform(60, 120, (height // 8 + 1, width // 8 + 1))
    bg = np.kron(bg, np.ones((8, 8)))[:height, :width]
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float64)
    n = int(seconds * fps)
    starts = np.arange(n) / fps + rng.uniform(0, 1 / fps)
    frames = []
    for t0 in starts:
        acc = np.zeros((height, width))
        subs = np.linspace(t0, t0 + exposure_s, 5)
        for t in subs:
            acc += _render(t, bg, xx, yy, clap_s, hands_at, flash, board_move_s)
        img = acc / subs.size + rng.normal(0, 2.0, acc.shape)
        frames.append(np.clip(img, 0, 255).astype(np.uint8))
    jitter = rng.normal(0, stamp_jitter_s, n) if stamp_jitter_s else 0.0
    stamps = np.round((starts + exposure_s / 2 + jitter) * 1e9).astype(np.int64)
    return frames, stamps


def _render(t: float, bg: np.ndarray, xx: np.ndarray, yy: np.ndarray, clap_s: float,
            hands_at: tuple[float, float], flash: bool, board_move_s: float | None) -> np.ndarray:
    h, w = bg.shape
    img = bg.copy()
    # still board in the middle, moving after board_move_s
    dx = 0.0
    if board_move_s is not None and t > board_move_s:
        dx = min(t - board_move_s, 1.0) * 0.25 * w
    board = (np.abs(xx - w * 0.55 - dx) < w * 0.18) & (np.abs(yy - h * 0.4) < h * 0.22)
    checker = ((xx // 6 + yy // 6) % 2) * 200 + 20
    img = np.where(board, checker, img)
    # blinking light top-right, 2 Hz
    if int(t * 4) % 2 == 0:
        img[(xx - w * 0.9) ** 2 + (yy - h * 0.12) ** 2 < (w * 0.04) ** 2] = 250
    # fan top-left: a bar rotating at 3 rev/s
    ang = 2 * np.pi * 3 * t
    cx, cy, r = w * 0.12, h * 0.2, w * 0.08
    u = (xx - cx) * np.cos(ang) + (yy - cy) * np.sin(ang)
    v = -(xx - cx) * np.sin(ang) + (yy - cy) * np.cos(ang)
    img[(np.abs(u) < r) & (np.abs(v) < 2)] = 30
    # hands: two blobs approaching over 0.45 s, touching at clap_s, separating 0.3 s
    dt = t - clap_s
    if -0.45 <= dt <= 0.45:
        if dt <= 0:
            gap = -dt / 0.45 * w * 0.12
        elif dt <= 0.3:
            gap = dt / 0.3 * w * 0.08
        else:
            gap = w * 0.08 + (dt - 0.3) / 0.15 * w * 0.3  # leave quickly
        hx, hy = w * hands_at[0], h * hands_at[1]
        half = w * 0.04
        for side in (-1, 1):
            cxh = hx + side * (gap / 2 + half)
            img[(np.abs(xx - cxh) < half) & (np.abs(yy - hy) < h * 0.07)] = 200
        if flash and 0 <= dt <= 0.025:
            region = (np.abs(xx - hx) < w * 0.12) & (np.abs(yy - hy) < h * 0.1)
            img[region] = np.minimum(img[region] + 50, 255)
    return img
