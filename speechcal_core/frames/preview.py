"""Fast reduced-size grey decoding of frames for window scans (JPEG decodes at 1/2 or 1/4)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import cv2
import numpy as np

from speechcal_core.frames.detect import to_gray
from speechcal_core.sources.decode import REDUCED_GRAY, compressed_payload
from speechcal_core.sources.depth import stream_depth
from speechcal_core.sources.errors import BadFrameError

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource


def preview_factor(width: int, height: int, target_side: int = 640) -> int:
    """Reduction (1, 2, 4 or 8) that brings the longer side near ``target_side`` pixels."""
    factor = 1
    while factor < 8 and max(width, height) / (factor * 2) >= target_side * 0.75:
        factor *= 2
    return factor


def preview_gray(source: FrameSource, stream: str, i: int, factor: int,
                 compressed: bool | None = None) -> np.ndarray:
    """Frame ``i`` as mono uint8 at ``1/factor`` size; compressed payloads skip full decoding.

    ``compressed`` says the stream holds CompressedImage messages (None: ask the source).
    Raises ``BadFrameError`` for an undecodable frame.
    """
    if compressed is None or compressed:
        try:
            raw = source.raw(stream, i)
        except (AttributeError, NotImplementedError):
            raw = None
        payload = compressed_payload(raw) if raw is not None else None
        if payload is not None:
            if len(payload) == 0:  # OpenCV asserts on an empty buffer
                raise BadFrameError(f"{stream}: frame {i} is empty (no JPEG/PNG payload)")
            img = cv2.imdecode(np.frombuffer(payload, np.uint8), REDUCED_GRAY[factor])
            if img is None:
                raise BadFrameError(f"{stream}: frame {i} cannot be decoded")
            return img
    gray = to_gray(source.frame(stream, i), stream_depth(source, stream))
    if factor == 1:
        return gray
    h, w = gray.shape[:2]
    return cv2.resize(gray, (max(1, w // factor), max(1, h // factor)),
                      interpolation=cv2.INTER_AREA)
