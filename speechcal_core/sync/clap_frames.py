"""A camera's frames for the clap search, a JPEG frame read as its luma alone.

Both passes look at the gray of a frame: a JPEG frame's luma is decoded alone (libjpeg
leaves out the colour, its upsampling and conversion), where decoding it in full colour
took most of a sync's time. The coarse pass then area-resizes that luma to about
``WORK_WIDTH`` wide in float32, as :func:`clap_video.to_gray_small` does a full decoding's
gray; the fine pass takes it as it is. Other frames (raw encodings, PNG, video) are
decoded in full and converted as :func:`clap_video.to_gray_small` and
:func:`clap_video.gray_full` do.

The coarse pass does not ask libjpeg for a reduced decoding (1/2, 1/4, 1/8): its pixels
are whole levels, where an area average of the full frame keeps fractions of one, and
that alone moved a weak clap's coarse V fit 40 ms (a 15 fps camera of the demo session):
the full-resolution fit, now more than half a frame from it, was refused and the clap
timed 46 ms late.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.sources.base import COMPRESSED_MSGTYPE
from speechcal_core.sources.decode import compressed_payload, decode_jpeg_gray
from speechcal_core.sources.errors import SourceError
from speechcal_core.sync.clap_video import gray_full, to_gray_small

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource, StreamInfo


def may_hold_jpeg(info: StreamInfo) -> bool:
    """Whether a stream's frames may be JPEG payloads (compressed messages, image files)."""
    return info.msgtype in (COMPRESSED_MSGTYPE, "file")


def small_gray(source: FrameSource, info: StreamInfo, i: int,
               depth: int | None) -> tuple[np.ndarray, float]:
    """Frame ``i`` as :func:`to_gray_small` gives it (gray float32 about WORK_WIDTH wide,
    and its scale); a JPEG frame's luma, area-resized as a full decoding's gray is."""
    img = _jpeg(source, info, i) if may_hold_jpeg(info) else None
    return to_gray_small(source.frame(info.name, i) if img is None else img, depth=depth)


def full_gray(source: FrameSource, info: StreamInfo, i: int, depth: int | None) -> np.ndarray:
    """Frame ``i`` as :func:`gray_full` gives it; a JPEG frame's luma decoded alone."""
    if may_hold_jpeg(info):
        img = _jpeg(source, info, i)
        if img is not None:
            return img
    return gray_full(source.frame(info.name, i), depth)


def _jpeg(source: FrameSource, info: StreamInfo, i: int) -> np.ndarray | None:
    """Frame ``i``'s luma (uint8, full size), or None when it is not a whole JPEG (a PNG, a
    damaged frame: the caller reads it as :meth:`FrameSource.frame` does, which marks a
    damaged frame bad and says why), or from a source that gives no raw frames (a wrapper
    offering ``frame`` alone: AttributeError)."""
    try:
        payload = compressed_payload(source.raw(info.name, i))
    except (SourceError, NotImplementedError, AttributeError):  # the full reading says why
        return None
    return None if payload is None else decode_jpeg_gray(payload)
