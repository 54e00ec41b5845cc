"""Coverage per camera over kept sets: X, Y, size, skew (as ROS camera_calibration), an image."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from speechcal_core.frames.detect import Detection

#: ranges that count as full coverage of X, Y, size and skew (ROS camera_calibration)
PARAM_RANGES = (0.7, 0.7, 0.4, 0.5)
PARAM_NAMES = ("x", "y", "size", "skew")


@dataclass(frozen=True)
class Coverage:
    """Per-view parameters (N x 4: x, y, size, skew in [0, 1]) and progress per parameter."""

    params: np.ndarray
    progress: dict[str, float]

    def to_dict(self) -> dict:
        """JSON-ready: ``{"views": n, "progress": {...}, "ranges": {name: [lo, hi]}}``."""
        ranges = {n: [round(float(self.params[:, k].min()), 4),
                      round(float(self.params[:, k].max()), 4)] if len(self.params) else None
                  for k, n in enumerate(PARAM_NAMES)}
        return {"views": len(self.params),
                "progress": {k: round(v, 4) for k, v in self.progress.items()},
                "ranges": ranges}


def outside_corners(det: Detection, object_points: np.ndarray) -> np.ndarray:
    """Image positions (4 x 2) of the corners of the detected part of the board.

    Order: the board's (min x, min y), (max x, min y), (max x, max y), (min x, max y).
    """
    obj = object_points[det.ids, :2]
    lo, hi = obj.min(axis=0), obj.max(axis=0)
    quad = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    if len(obj) >= 4:
        h, _ = cv2.findHomography(obj, det.points, 0)
        if h is not None:
            return cv2.perspectiveTransform(quad.reshape(-1, 1, 2), h).reshape(4, 2)
    idx = [int(np.argmin(np.linalg.norm(obj - q, axis=1))) for q in quad]
    return det.points[idx]


def view_parameters(det: Detection, object_points: np.ndarray,
                    size: tuple[int, int]) -> np.ndarray:
    """x, y, size, skew of one view, each in [0, 1] (ROS camera_calibration's definitions)."""
    width, height = size
    quad = outside_corners(det, object_points)
    area = _quad_area(quad)
    border = math.sqrt(max(area, 0.0))
    mean = det.points.mean(axis=0)
    p_x = min(1.0, max(0.0, (mean[0] - border / 2) / max(1e-9, width - border)))
    p_y = min(1.0, max(0.0, (mean[1] - border / 2) / max(1e-9, height - border)))
    p_size = math.sqrt(area / (width * height))
    return np.array([p_x, p_y, p_size, _skew(quad)])


def coverage(dets: Sequence[Detection], object_points: np.ndarray,
             size: tuple[int, int]) -> Coverage:
    """Coverage of one camera over the given detections."""
    params = np.array([view_parameters(d, object_points, size) for d in dets]).reshape(-1, 4)
    progress = {}
    for k, name in enumerate(PARAM_NAMES):
        span = float(params[:, k].max() - params[:, k].min()) if len(params) else 0.0
        progress[name] = min(span / PARAM_RANGES[k], 1.0)
    return Coverage(params, progress)


def coverage_image(dets: Sequence[Detection], size: tuple[int, int],
                   width: int = 320) -> np.ndarray:
    """uint8 image ``width`` wide: how often each spot was covered by the board (255 = most)."""
    w, h = size
    scale = width / w
    out_h = max(1, round(h * scale))
    acc = np.zeros((out_h, width), np.float32)
    layer = np.zeros_like(acc)
    for d in dets:
        layer[:] = 0
        cv2.fillConvexPoly(layer, np.round(d.hull() * scale).astype(np.int32), 1.0)
        acc += layer
    top = float(acc.max())
    return (acc * (255.0 / top)).astype(np.uint8) if top > 0 else acc.astype(np.uint8)


def _quad_area(q: np.ndarray) -> float:
    a, b, c, d = q
    p, r = b - a, c - a
    s = d - a
    return abs(p[0] * r[1] - p[1] * r[0]) / 2 + abs(r[0] * s[1] - r[1] * s[0]) / 2


def _skew(q: np.ndarray) -> float:
    a, b, c = q[0], q[1], q[2]
    ab, cb = a - b, c - b
    cos = float(np.dot(ab, cb) / max(1e-12, np.linalg.norm(ab) * np.linalg.norm(cb)))
    angle = math.acos(min(1.0, max(-1.0, cos)))
    return min(1.0, 2.0 * abs(math.pi / 2 - angle))
