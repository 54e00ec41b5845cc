"""The audio-to-session clock model of DESIGN.md §1."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import overload

import numpy as np

from speechcal_core.sources.stats import MAX_STAMP_NS


@dataclass(frozen=True)
class SyncModel:
    """Maps audio seconds to session (camera header-stamp) nanoseconds.

    ``t_session_ns = offset_ns + round(t_audio_s * (1 + drift) * 1e9)``.
    ``source`` says where the model came from: ``"auto"``, ``"manual"``, ``"stamped"``,
    ``"assumed"`` (no clap: the audio taken to start with the first frame) or
    ``"truth"``; GUI edits produce a new model via :meth:`with_offset`.
    """

    offset_ns: int
    drift: float = 0.0
    source: str = "auto"

    @overload
    def to_session(self, t_audio_s: float) -> int: ...

    @overload
    def to_session(self, t_audio_s: np.ndarray) -> np.ndarray: ...

    @overload
    def to_session(self, t_audio_s: float | np.ndarray) -> int | np.ndarray: ...

    def to_session(self, t_audio_s: float | np.ndarray) -> int | np.ndarray:
        """Audio seconds -> session ns (int, or int64 array for array input)."""
        scaled = np.round(np.asarray(t_audio_s, dtype=np.float64) * (1.0 + self.drift) * 1e9)
        result = self.offset_ns + scaled.astype(np.int64)
        return int(result) if np.ndim(result) == 0 else result

    @overload
    def to_audio(self, t_session_ns: int) -> float: ...

    @overload
    def to_audio(self, t_session_ns: np.ndarray) -> np.ndarray: ...

    @overload
    def to_audio(self, t_session_ns: int | np.ndarray) -> float | np.ndarray: ...

    def to_audio(self, t_session_ns: int | np.ndarray) -> float | np.ndarray:
        """Session ns -> audio seconds (float, or float64 array for array input)."""
        delta = np.asarray(t_session_ns, dtype=np.int64) - self.offset_ns
        result = delta.astype(np.float64) / 1e9 / (1.0 + self.drift)
        return float(result) if np.ndim(result) == 0 else result

    def with_offset(self, offset_ns: int, source: str = "manual") -> SyncModel:
        """A copy with another offset (e.g. after a manual clap edit)."""
        return replace(self, offset_ns=int(offset_ns), source=source)

    def to_dict(self) -> dict:
        """JSON-ready form: ``{"offset_ns", "drift", "source"}``."""
        return {"offset_ns": self.offset_ns, "drift": self.drift, "source": self.source}

    @classmethod
    def from_dict(cls, data: dict) -> SyncModel:
        """Inverse of :meth:`to_dict`; ValueError for an offset or drift that is no number
        (a hand-edited ``NaN``)."""
        source = str(data.get("source", "auto"))
        drift = float(data.get("drift", 0.0))
        if not np.isfinite(drift) or drift <= -1.0:
            raise ValueError(f"the sync's drift is {drift}, not a clock rate error")
        offset = int(data["offset_ns"])
        # as far out as a stamp no header holds: a hand edit that overflowed every time
        # computed from it
        if isinstance(data["offset_ns"], bool) or abs(offset) >= MAX_STAMP_NS:
            raise ValueError(f"the sync's offset_ns {data['offset_ns']!r:.40} is no "
                             "camera-clock time in nanoseconds")
        return cls(offset, drift, source)
