"""Printable texture of a calibration target (Kalibr AprilGrid or checkerboard) on a white card.

The texture is laid out in *target coordinates*: texel column ``u`` grows with target ``x``
and texel row ``v`` with target ``y`` (``TargetSpec.object_points`` frame). Seen from the
printed side (target ``z`` pointing at the viewer, ``x`` right, ``y`` up) it is the sheet
``kalibr_create_target_pdf`` prints: tag 0 in the lower-left corner, ids row-major, each
tag upright in the AprilTag convention, and the small black squares that Kalibr puts at
every tag corner inside the spacing gaps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from speechcal_core.target import TargetSpec

#: grey levels of the printed card (not pure black/white, like paper under room light)
INK = 28
PAPER = 226
#: white margin around the pattern, in tag (or square) edges
MARGIN_EDGES = 1.0
TAG_BITS = 6  # 36h11: 6x6 data bits
BORDER_BITS = 2  # Kalibr prints a 2-bit black border


@dataclass(frozen=True)
class TargetTexture:
    """A card texture and its placement in target coordinates.

    ``levels[k]`` is a 4-channel ``uint8`` image (printed grey, card coverage, 0, 0) at
    ``1 / 2**k`` of the full resolution (four channels: ``cv2.remap``'s fast path);
    coverage is 255 on the card and sampling outside the texture is transparent.
    Texel ``(u, v)`` of level 0 has its centre at target
    ``x = x0 + (u + 0.5) / px_per_m``, ``y = y0 + (v + 0.5) / px_per_m`` where
    ``(x0, y0)`` is the card's corner ``origin_m``.
    """

    levels: tuple[np.ndarray, ...]
    px_per_m: float
    origin_m: tuple[float, float]

    def target_to_texel(self, level: int = 0) -> np.ndarray:
        """3x3 matrix mapping homogeneous target ``(x, y, 1)`` to texel ``(u, v, 1)``."""
        # cv2.pyrDown centres texel i of a level on texel 2i of the level below
        scale = self.px_per_m / 2**level
        x0, y0 = self.origin_m
        half = 0.5 / 2**level
        return np.array([[scale, 0.0, -x0 * scale - half],
                         [0.0, scale, -y0 * scale - half],
                         [0.0, 0.0, 1.0]])

    @property
    def card_extent_m(self) -> tuple[float, float, float, float]:
        """``(x0, y0, x1, y1)`` of the white card in target coordinates."""
        h, w = self.levels[0].shape[:2]
        x0, y0 = self.origin_m
        return (x0, y0, x0 + w / self.px_per_m, y0 + h / self.px_per_m)


def make_target_texture(target: TargetSpec, min_px_per_m: float = 1500.0) -> TargetTexture:
    """Draw ``target`` at no less than ``min_px_per_m`` texels per metre (whole texels per bit)."""
    # one tag bit, or one checkerboard square
    unit = target.size / (TAG_BITS + 2 * BORDER_BITS) if target.kind == "aprilgrid" else target.size
    px_per_unit = max(4, math.ceil(min_px_per_m * unit))
    px_per_m = px_per_unit / unit
    ext_w, ext_h = target.extent
    if target.kind == "aprilgrid":  # corner squares stick out by one gap
        gap = target.spacing * target.size
        lo, hi_x, hi_y = -gap, ext_w + gap, ext_h + gap
    else:  # squares run from -size to cols * size
        lo, hi_x, hi_y = -target.size, ext_w - target.size, ext_h - target.size
    margin = MARGIN_EDGES * target.size
    # whole texels from the card corner to the pattern, so edges fall on texel borders
    margin_px = math.ceil(margin * px_per_m)
    origin = lo - margin_px / px_per_m
    width = round((hi_x - lo) * px_per_m) + 2 * margin_px
    height = round((hi_y - lo) * px_per_m) + 2 * margin_px
    grey = np.full((height, width), PAPER, np.uint8)

    def to_px(x: float) -> int:
        return round((x - origin) * px_per_m)

    if target.kind == "aprilgrid":
        _draw_aprilgrid(grey, target, to_px, px_per_unit)
    else:
        _draw_checkerboard(grey, target, to_px)
    zero = np.zeros_like(grey)
    levels = [cv2.merge([grey, np.full_like(grey, 255), zero, zero])]
    while min(levels[-1].shape[:2]) > 64 and len(levels) < 5:
        levels.append(cv2.pyrDown(levels[-1]))
    return TargetTexture(tuple(levels), float(px_per_m), (float(origin), float(origin)))


def apriltag_texels(tag_id: int, px_per_bit: int) -> np.ndarray:
    """One 36h11 tag with a 2-bit border, oriented for the texture (rows along +y).

    OpenCV's marker image is the AprilTag rotated by 180 degrees; the printed tag seen from
    the front is the AprilTag itself, and texture rows run bottom-up on the printed sheet,
    so the texture block is OpenCV's marker mirrored left-right.
    """
    dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    side = TAG_BITS + 2 * BORDER_BITS
    marker = cv2.aruco.generateImageMarker(dictionary, tag_id, side, borderBits=BORDER_BITS)
    marker = np.where(marker > 127, PAPER, INK).astype(np.uint8)
    big = cv2.resize(marker, (side * px_per_bit, side * px_per_bit),
                     interpolation=cv2.INTER_NEAREST)
    return np.ascontiguousarray(big[:, ::-1])


def _draw_aprilgrid(grey: np.ndarray, target: TargetSpec, to_px: Callable[[float], int],
                    px_per_bit: int) -> None:
    s, p = target.size, target.pitch
    gap = target.spacing * s
    for r in range(target.rows):
        for c in range(target.cols):
            x, y = c * p, r * p
            block = apriltag_texels(r * target.cols + c, px_per_bit)
            u0, v0 = to_px(x), to_px(y)
            grey[v0 : v0 + block.shape[0], u0 : u0 + block.shape[1]] = block
            for cx, cy in ((x - gap, y - gap), (x + s, y - gap), (x + s, y + s), (x - gap, y + s)):
                grey[to_px(cy) : to_px(cy + gap), to_px(cx) : to_px(cx + gap)] = INK


def _draw_checkerboard(grey: np.ndarray, target: TargetSpec,
                       to_px: Callable[[float], int]) -> None:
    s = target.size
    # squares i in 0..cols (x), j in 0..rows (y); square (0, 0) holds the origin corner at
    # its far side and is black, as kalibr_create_target_pdf draws it
    for j in range(target.rows + 1):
        for i in range(target.cols + 1):
            if (i + j) % 2 == 0:
                x0, y0 = (i - 1) * s, (j - 1) * s
                grey[to_px(y0) : to_px(y0 + s), to_px(x0) : to_px(x0 + s)] = INK
