"""A camera's frames for the clap search, read at the size each pass needs.

The coarse pass looks at gray frames about ``WORK_WIDTH`` wide: a JPEG frame is decoded
straight to reduced gray (libjpeg scales while decoding, and leaves out the colour), where
decoding it in full colour took most of a sync's time. The fine pass reads full-resolution
gray: a JPEG's luma. Other frames (raw encodings, PNG, video) are decoded in full and
converted as :func:`clap_video.to_gray_small` and :func:`clap_video.gray_full` do.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import cv2
import numpy as np

from speechcal_core.sources.base import COMPRESSED_MSGTYPE
from speechcal_core.sources.decode import REDUCED_GRAY, compressed_payload, decode_jpeg_gray
from speechcal_core.sources.errors import SourceError
from speechcal_core.sync.clap_video import WORK_WIDTH, gray_full, to_gray_small

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource, StreamInfo


def may_hold_jpeg(info: StreamInfo) -> bool:
    """Whether a stream's frames may be JPEG payloads (compressed messages, image files)."""
    return info.msgtype in (COMPRESSED_MSGTYPE, "file")


def work_size(width: int, height: int, work_width: int = WORK_WIDTH
              ) -> tuple[tuple[int, int], float]:
    """The (width, height) :func:`to_gray_small` brings a frame to, and its scale."""
    scale = min(1.0, work_width / width)
    return (max(1, round(width * scale)), max(1, round(height * scale))), scale


def reduction(width: int, height: int, size: tuple[int, int]) -> int:
    """The largest libjpeg reduction (1, 2, 4 or 8) that keeps a frame at least ``size``."""
    return max(f for f in REDUCED_GRAY
               if math.ceil(width / f) >= size[0] and math.ceil(height / f) >= size[1])


def small_gray(source: FrameSource, info: StreamInfo, i: int,
               depth: int | None) -> tuple[np.ndarray, float]:
    """Frame ``i`` as :func:`to_gray_small` gives it (gray float32 about WORK_WIDTH wide,
    and its scale); a JPEG frame of the stream's size decoded at a reduced size."""
    if may_hold_jpeg(info) and info.width > 0 and info.height > 0:
        size, scale = work_size(info.width, info.height)
        factor = reduction(info.width, info.height, size)
        img = _jpeg(source, info, i, factor)
        if img is not None and img.shape == (math.ceil(info.height / factor),
                                             math.ceil(info.width / factor)):
            small = img.astype(np.float32)
            if small.shape[::-1] != size:
                small = cv2.resize(small, size, interpolation=cv2.INTER_AREA)
            return small, scale
    return to_gray_small(source.frame(info.name, i), depth=depth)


def full_gray(source: FrameSource, info: StreamInfo, i: int, depth: int | None) -> np.ndarray:
    """Frame ``i`` as :func:`gray_full` gives it; a JPEG frame's luma decoded alone."""
    if may_hold_jpeg(info):
        img = _jpeg(source, info, i, 1)
        if img is not None:
            return img
    return gray_full(source.frame(info.name, i), depth)


def _jpeg(source: FrameSource, info: StreamInfo, i: int, factor: int) -> np.ndarray | None:
    """Frame ``i`` decoded to gray at ``1/factor``, or None when it is not a whole JPEG
    (a PNG, a damaged frame: the caller reads it as :meth:`FrameSource.frame` does, which
    marks a damaged frame bad and says why), or from a source that gives no raw frames (a
    wrapper offering ``frame`` alone: AttributeError)."""
    try:
        payload = compressed_payload(source.raw(info.name, i))
    except (SourceError, NotImplementedError, AttributeError):  # the full reading says why
        return None
    return None if payload is None else decode_jpeg_gray(payload, factor)
