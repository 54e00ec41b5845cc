"""Small rendered views of calibration targets with known pose and intrinsics, for tests."""

from __future__ import annotations

import cv2
import numpy as np

from speechcal_core.frames.detect import CharucoSpec
from speechcal_core.target import TargetSpec

MARGIN = 0.02  # white border around the pattern, metres


def board_texture(target: TargetSpec | CharucoSpec, ppm: float,
                  mirrored: bool = False) -> np.ndarray:
    """The printed board (uint8), row 0 at the top of the print (largest y, Kalibr y up).

    ``mirrored`` draws AprilGrid tags upright with y pointing down instead.
    """
    if isinstance(target, CharucoSpec):
        w = target.squares_x * target.square
        h = target.squares_y * target.square
        size = (round((w + 2 * MARGIN) * ppm), round((h + 2 * MARGIN) * ppm))
        img = target.board().generateImage(size, marginSize=round(MARGIN * ppm))
        return img
    w, h = target.extent
    ox, oy = pattern_origin(target)
    tw, th = round((w + 2 * MARGIN) * ppm), round((h + 2 * MARGIN) * ppm)
    tex = np.full((th, tw), 255, np.uint8)

    def fill(x: float, y: float, sw: float, sh: float, value: np.ndarray | int = 0) -> None:
        x, y = x - ox + MARGIN, y - oy + MARGIN
        c0, c1 = round(x * ppm), round((x + sw) * ppm)
        r0, r1 = th - round((y + sh) * ppm), th - round(y * ppm)
        if isinstance(value, np.ndarray):
            value = cv2.resize(value, (c1 - c0, r1 - r0), interpolation=cv2.INTER_NEAREST)
        tex[r0:r1, c0:c1] = value

    if target.kind == "checkerboard":
        # inner corner (0, 0) at the origin: squares start one square before it
        s = target.size
        for r in range(target.rows + 1):
            for c in range(target.cols + 1):
                if (r + c) % 2 == 0:
                    fill((c - 1) * s, (r - 1) * s, s, s)
        return tex
    d = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
    s, p, q = target.size, target.pitch, target.size * target.spacing
    for r in range(target.rows):
        for c in range(target.cols):
            tag = cv2.aruco.generateImageMarker(d, r * target.cols + c, 100, borderBits=2)
            # the printed AprilTag is OpenCV's marker image turned by 180 degrees
            tag = tag[:, ::-1] if mirrored else tag[::-1, ::-1]
            x, y = c * p, r * p
            fill(x, y, s, s, tag)
            for cx, cy in ((x - q, y - q), (x + s, y - q), (x + s, y + s), (x - q, y + s)):
                fill(cx, cy, q, q)
    return tex


def pattern_origin(target: TargetSpec | CharucoSpec) -> tuple[float, float]:
    """Board coordinates of the printed pattern's lower-left corner."""
    if isinstance(target, TargetSpec) and target.kind == "checkerboard":
        return -target.size, -target.size
    return 0.0, 0.0


def render_view(
    target: TargetSpec | CharucoSpec,
    camera_matrix: np.ndarray,
    rvec: np.ndarray,
    tvec: np.ndarray,
    size: tuple[int, int],
    *,
    noise: float = 2.0,
    blur: float = 0.6,
    seed: int = 0,
    mirrored: bool = False,
    background: int = 90,
) -> np.ndarray:
    """A gray image of the board seen by an undistorted pinhole camera at (rvec, tvec)."""
    ppm = 4000.0
    tex = board_texture(target, ppm, mirrored)
    th = tex.shape[0]
    # texture pixel centre -> board metres (y up for Kalibr prints; CharUco texture is y down)
    if isinstance(target, CharucoSpec):
        a = np.array([[1 / ppm, 0, -MARGIN + 0.5 / ppm], [0, 1 / ppm, -MARGIN + 0.5 / ppm],
                      [0, 0, 1]])
    else:
        ox, oy = pattern_origin(target)
        a = np.array([[1 / ppm, 0, ox - MARGIN + 0.5 / ppm],
                      [0, -1 / ppm, oy + th / ppm - MARGIN - 0.5 / ppm], [0, 0, 1]])
    r, _ = cv2.Rodrigues(np.asarray(rvec, np.float64))
    h = camera_matrix @ np.column_stack([r[:, 0], r[:, 1], np.asarray(tvec, np.float64)])
    # render at 2x and shrink with area averaging to avoid aliasing
    up = np.diag([2.0, 2.0, 1.0])
    up[:2, 2] = 0.5
    big = cv2.warpPerspective(tex, up @ h @ a, (size[0] * 2, size[1] * 2),
                              flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                              borderValue=-1)
    mask = cv2.warpPerspective(np.full_like(tex, 255), up @ h @ a, (size[0] * 2, size[1] * 2),
                               flags=cv2.INTER_NEAREST)
    img = np.where(mask > 0, big.astype(np.float64) * 0.8 + 20, float(background))
    img = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
    if blur:
        img = cv2.GaussianBlur(img, (0, 0), blur)
    rng = np.random.default_rng(seed)
    img = img + rng.normal(0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


def facing_pose(
    target: TargetSpec | CharucoSpec,
    distance: float,
    tilt: tuple[float, float] = (0, 0),
    shift: tuple[float, float] = (0, 0),
    roll: float = 0.0,
    flip_y: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """rvec, tvec of the board centred ``distance`` m ahead, its printed side to the camera."""
    if isinstance(target, CharucoSpec):
        w, h = target.squares_x * target.square, target.squares_y * target.square
        flip = np.eye(3)  # CharUco: y down on the print
    else:
        w, h = target.extent
        # Kalibr: y up on the print, z towards the viewer (flip_y False: a y-down drawing)
        flip = np.diag([1.0, -1.0, -1.0]) if flip_y else np.eye(3)
    rx, _ = cv2.Rodrigues(np.array([tilt[0], 0.0, 0.0]))
    ry, _ = cv2.Rodrigues(np.array([0.0, tilt[1], 0.0]))
    rz, _ = cv2.Rodrigues(np.array([0.0, 0.0, roll]))
    rot = rz @ ry @ rx @ flip
    centre = np.array([shift[0], shift[1], distance])
    ox, oy = pattern_origin(target)
    tvec = centre - rot @ np.array([ox + w / 2, oy + h / 2, 0.0])
    rvec, _ = cv2.Rodrigues(rot)
    return rvec.ravel(), tvec
