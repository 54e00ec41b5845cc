"""The review's undo and redo steps: each says what the operator did and holds what
taking it back needs. Taking a step back gives the step that does it again (on the redo
stack), and that one taken back gives the first again."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from speechcal_core.session.model import FrameSet
    from speechcal_core.sync.model import SyncModel

#: detection settings (``detect_again.settings_of``) to put back when a step is taken back,
#: and the ones then in place (put back when that is taken back in turn)
SettingsSwap = tuple[Any, Any]


@dataclass(frozen=True)
class Decided:
    """A decision on set ``set_id``, which had ``previous`` before."""

    set_id: int
    previous: str


@dataclass(frozen=True)
class OffsetChanged:
    """An offset edit away from ``sync``: the sets (their frames and figures were
    measured for it), what their figures were judged against (``MEASURED_FOR_SYNC`` of
    the session's extras) and the clap evidence, all as they were."""

    sync: SyncModel
    sets: tuple[FrameSet, ...]
    measured: dict[str, dict]
    evidence: Any


@dataclass(frozen=True)
class EarlierOffsetChange:
    """An offset edit away from ``sync`` made before the session was last opened, as the
    session file keeps it (``undo_history``): the sync and the claps heard then
    (``claps``, None when the sync evidence had none), not the sets' frames and figures
    (megabytes per edit with a dozen cameras). Taken back, the sets take the frames
    nearest their time under ``sync`` and are re-scored."""

    sync: SyncModel
    claps: tuple[dict[str, Any], ...] | None


@dataclass(frozen=True)
class Added:
    """Set ``set_id`` added."""

    set_id: int


@dataclass(frozen=True)
class Removed:
    """``frame_set`` removed from place ``index`` of the list, with its frame details
    (None when the session kept none)."""

    frame_set: FrameSet
    index: int
    details: object


@dataclass(frozen=True)
class AddedMany:
    """The sets one search added, ``set_ids``; ``settings`` when it changed the
    session's detection settings."""

    set_ids: tuple[int, ...]
    settings: SettingsSwap | None = None


@dataclass(frozen=True)
class RemovedMany:
    """Sets taken out together (a search's, undone): (set, index, details) each."""

    items: tuple[tuple[FrameSet, int, object], ...]
    settings: SettingsSwap | None = None


UndoStep = (Decided | OffsetChanged | EarlierOffsetChange | Added | Removed | AddedMany
            | RemovedMany)


def step_label(step: UndoStep, redo: bool = False) -> str:
    """A step in words: on the undo stack the step it takes back ("adding set 3"), on
    the redo stack (``redo``) the step it does again."""
    if isinstance(step, OffsetChanged | EarlierOffsetChange):
        return "audio offset change"
    if isinstance(step, Decided):
        return f"decision on set {step.set_id}"
    if isinstance(step, Added | Removed):
        set_id = step.set_id if isinstance(step, Added) else step.frame_set.id
        adding = isinstance(step, Added) != redo  # redo holds the inverse step
        return f"{'adding' if adding else 'removing'} set {set_id}"
    n = len(step.set_ids) if isinstance(step, AddedMany) else len(step.items)
    sets = f"{n} set{'' if n == 1 else 's'}"
    adding = isinstance(step, AddedMany) != redo
    return f"adding {sets}" if adding else f"removing {sets}"
