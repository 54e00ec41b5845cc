"""Frame sets chosen and measured again after an offset edit or an added set.

The review model says what needs it (:meth:`ReviewModel.rescore_request`) and takes the
results (:meth:`ReviewModel.apply_rescored`); :meth:`RescoreRequest.run` does the work in
between, on any thread: it reads only its own snapshot and the (thread-safe) recording.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from speechcal_core.frames.sets import FrameReferences, FrameSetOptions, rescore_frame_sets
from speechcal_core.session.model import FrameSet
from speechcal_core.sync.model import SyncModel
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource

Progress = Callable[[str, float], None]

#: share of the progress bar for each stage of the frame search
_STAGES = {"windows": (0.0, 0.75), "corners": (0.75, 0.25)}


@dataclass(frozen=True)
class RescoreResult:
    """Re-scored sets for ``sync`` with their frame details (keyed by set id as text).

    ``references`` is set when they were measured over the whole session (and then
    replace the session's).
    """

    sync: SyncModel
    sets: tuple[FrameSet, ...]
    details: dict[str, Any] = field(default_factory=dict)
    references: FrameReferences | None = None


@dataclass(frozen=True)
class RescoreRequest:
    """Sets to choose and measure again for ``sync``: a snapshot, review goes on meanwhile.

    ``references`` None means the request holds every set of the session and the
    references are measured over them, exactly as ``speechcal process`` does.
    """

    sync: SyncModel
    sets: tuple[FrameSet, ...]
    target: TargetSpec
    references: FrameReferences | None = None
    options: FrameSetOptions = field(default_factory=FrameSetOptions)

    @property
    def text(self) -> str:
        """What the status line says while this runs."""
        n = len(self.sets)
        return f"re-scoring {n} frame set{'' if n == 1 else 's'}…"

    def run(self, source: FrameSource, progress: Progress | None = None) -> RescoreResult:
        """The best-still search and measurements (about 0.1 s per set of four VGA cameras).

        ``progress(text, fraction)`` may raise to cancel; it is called from worker threads.
        """
        report = progress or (lambda _t, _f: None)
        text = self.text

        def stage(name: str, fraction: float) -> None:
            start, span = _STAGES.get(name, (0.0, 1.0))
            report(text, start + span * fraction)

        report(text, 0.0)
        result = rescore_frame_sets(source, self.sync, self.sets, self.target, self.options,
                                    self.references, stage)
        return RescoreResult(self.sync, tuple(result.sets), result.details,
                             result.references if self.references is None else None)
