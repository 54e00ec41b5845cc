"""Several ``FrameSource`` objects with distinct stream names seen as one."""

from __future__ import annotations

from typing import TYPE_CHECKING

from speechcal_core.sources.base import ClosingContext, stream_order
from speechcal_core.sources.errors import SourceError

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy as np

    from speechcal_core.sources.base import FrameSource, RawFrame, StreamInfo


class CombinedSource(ClosingContext):
    """Streams of several sources (e.g. one video per camera); names must not clash."""

    def __init__(self, sources: Sequence[FrameSource]) -> None:
        self._sources = list(sources)
        self._owner: dict[str, FrameSource] = {}
        self.notes: list[str] = [n for s in self._sources for n in getattr(s, "notes", [])]
        for src in self._sources:
            for info in src.streams:
                if info.name in self._owner:
                    self.close()
                    raise SourceError(
                        f"two inputs both have a stream named {info.name!r}; rename one file"
                    )
                self._owner[info.name] = src

    @property
    def streams(self) -> list[StreamInfo]:
        """All streams, in name order (numbers in numeric order: ``stream_order``)."""
        return sorted((i for s in self._sources for i in s.streams),
                      key=lambda i: stream_order(i.name))

    def _src(self, stream: str) -> FrameSource:
        try:
            return self._owner[stream]
        except KeyError:
            known = ", ".join(sorted(self._owner))
            msg = f"no stream {stream!r} in this recording (streams: {known})"
            raise SourceError(msg) from None

    def stamps(self, stream: str) -> np.ndarray:
        """Sorted int64 header stamps."""
        return self._src(stream).stamps(stream)

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded frame i."""
        return self._src(stream).frame(stream, i)

    def nearest(self, stream: str, t_ns: int) -> int:
        """Index of the nearest stamp."""
        return self._src(stream).nearest(stream, t_ns)

    def raw(self, stream: str, i: int) -> RawFrame:
        """Undecoded payload of frame i."""
        return self._src(stream).raw(stream, i)

    def close(self) -> None:
        """Close every source."""
        for src in self._sources:
            src.close()
