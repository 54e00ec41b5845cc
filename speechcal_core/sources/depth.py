"""The sensor depth of a 16-bit stream, found once per source and stream.

A 16-bit image may hold a 10-, 12- or 14-bit sensor's values (right-aligned). Converted
to 8 bits each frame on its own, a frame whose brightest pixel happens to need one bit
less would come out twice as bright as its neighbours, which the frame-to-frame motion
measure takes for movement; one depth per stream keeps its frames on one scale.
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.sources.decode import sensor_depth
from speechcal_core.sources.errors import SourceError

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource

#: frames read across a stream to find its depth
SAMPLES = 5

_DEPTHS: weakref.WeakKeyDictionary[object, dict[str, int | None]] = \
    weakref.WeakKeyDictionary()


def stream_depth(source: FrameSource, stream: str) -> int | None:
    """The depth (bits) a 16-bit ``stream`` holds, from the largest value of SAMPLES
    frames spread over it; None for a stream of 8-bit frames (or none readable)."""
    try:
        known = _DEPTHS.setdefault(source, {})
    except TypeError:  # a source that cannot be weakly referenced: asked every time
        known = {}
    if stream in known:
        return known[stream]
    count = next((s.count for s in source.streams if s.name == stream), 0)
    spread = {round(k * (count - 1) / (SAMPLES - 1)) for k in range(SAMPLES)} if count else ()
    largest: int | None = None
    for i in sorted(spread):
        try:
            frame = source.frame(stream, i)
        except SourceError:  # a bad frame is skipped
            continue
        if frame.dtype != np.uint16:
            break
        largest = max(largest or 0, int(frame.max()) if frame.size else 0)
    known[stream] = None if largest is None else sensor_depth(largest)
    return known[stream]
