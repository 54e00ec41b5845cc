"""Stream bookkeeping shared by the file-based sources: lookup, stamps, nearest, bad frames."""

from __future__ import annotations

import threading
from dataclasses import replace
from typing import TYPE_CHECKING

from speechcal_core.sources.base import ClosingContext, stream_order
from speechcal_core.sources.errors import SourceError
from speechcal_core.sources.stats import nearest_index

if TYPE_CHECKING:

    import numpy as np

    from speechcal_core.sources.base import StreamInfo


class StreamTable(ClosingContext):
    """Holds ``StreamInfo`` and sorted stamps per stream; subclasses add frame/raw/close."""

    def __init__(self) -> None:
        self._infos: dict[str, StreamInfo] = {}
        self._stamps: dict[str, np.ndarray] = {}
        self._bad: dict[str, set[int]] = {}
        self._table_lock = threading.Lock()
        self.notes: list[str] = []  # what was recovered or guessed while opening

    def _add_stream(self, info: StreamInfo, stamps: np.ndarray) -> None:
        self._infos[info.name] = info
        self._stamps[info.name] = stamps
        self._bad.setdefault(info.name, set(info.bad_frames))

    @property
    def streams(self) -> list[StreamInfo]:
        """One entry per stream, in name order (``stream_order``), with the frames found
        bad so far."""
        with self._table_lock:
            return [
                replace(info, bad_frames=tuple(sorted(self._bad.get(name, ()))))
                for name, info in sorted(self._infos.items(),
                                         key=lambda item: stream_order(item[0]))
            ]

    def _mark_bad(self, stream: str, i: int) -> None:
        with self._table_lock:
            self._bad.setdefault(stream, set()).add(i)

    def _check(self, stream: str, i: int | None = None) -> np.ndarray:
        stamps = self._stamps.get(stream)
        if stamps is None:
            known = ", ".join(sorted(self._infos))
            raise SourceError(f"no stream {stream!r} in this recording (streams: {known})")
        if i is not None and not 0 <= i < stamps.size:
            raise IndexError(f"{stream}: frame {i} out of range 0..{stamps.size - 1}")
        return stamps

    def stamps(self, stream: str) -> np.ndarray:
        """Sorted int64 header stamps."""
        return self._check(stream)

    def nearest(self, stream: str, t_ns: int) -> int:
        """Index of the nearest stamp."""
        return nearest_index(self._check(stream), t_ns)

    def close(self) -> None:
        """Release files (nothing by default)."""
