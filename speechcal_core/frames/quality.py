"""Per-frame quality figures on the target region: sharpness and motion against neighbours."""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np


def region_mask(shape: tuple[int, int], hulls: Sequence[np.ndarray], grow_px: int) -> np.ndarray:
    """uint8 mask (255 inside) of the union of convex hulls, grown by ``grow_px``.

    With no hull the whole image counts.
    """
    if not hulls:
        return np.full(shape, 255, np.uint8)
    mask = np.zeros(shape, np.uint8)
    for hull in hulls:
        cv2.fillConvexPoly(mask, np.round(hull).astype(np.int32).reshape(-1, 2), 255)
    if grow_px > 0:
        k = 2 * grow_px + 1
        mask = cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_RECT, (k, k)))
    return mask


def mask_box(mask: np.ndarray) -> tuple[slice, slice]:
    """Row and column slices of the mask's bounding box (whole image if empty)."""
    x, y, w, h = cv2.boundingRect(mask)
    if w == 0 or h == 0:
        return slice(None), slice(None)
    return slice(y, y + h), slice(x, x + w)


def sharpness(gray: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Variance of the Laplacian, over ``mask`` when given (higher is sharper)."""
    lap = cv2.Laplacian(gray, cv2.CV_32F, ksize=3)
    _, std = cv2.meanStdDev(lap, mask=mask)
    return float(std[0, 0] ** 2)


def difference(a: np.ndarray, b: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Mean absolute grey difference of two frames over ``mask``."""
    diff = cv2.absdiff(a, b)
    return float(cv2.mean(diff, mask=mask)[0])


def motion_against_neighbours(diffs: np.ndarray) -> np.ndarray:
    """Per frame, the larger of its differences to the previous and next frame.

    ``diffs[k]`` is the difference between frames ``k`` and ``k + 1`` (n - 1 values for n
    frames); the first and last frame only have one neighbour.
    """
    n = diffs.size + 1
    out = np.zeros(n)
    if n < 2:
        return out
    out[:-1] = diffs
    out[1:] = np.maximum(out[1:], diffs)
    return out


def normalized(values: np.ndarray, reference: float) -> np.ndarray:
    """``values / reference`` (zeros when the reference is not positive)."""
    if reference <= 0:
        return np.zeros_like(values, dtype=np.float64)
    return np.asarray(values, np.float64) / reference
