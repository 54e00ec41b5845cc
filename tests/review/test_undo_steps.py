"""How the Edit menu names each undo step, on the undo stack (the step taken back) and on
the redo stack (the step done again, held there as its inverse)."""

from __future__ import annotations

import pytest

from speechcal_core.review.undo_steps import (
    Added,
    AddedMany,
    Decided,
    EarlierOffsetChange,
    OffsetChanged,
    Removed,
    RemovedMany,
    UndoStep,
    step_label,
)
from speechcal_core.session.model import FrameSet, Trigger
from speechcal_core.sync.model import SyncModel

SET_7 = FrameSet(7, 1_000_000_000, Trigger("capture", 1.0, 1.4), ())


@pytest.mark.parametrize(("step", "undo", "redo"), [
    (Decided(3, "undecided"), "decision on set 3", "decision on set 3"),
    (OffsetChanged(SyncModel(0, 0.0), (), {}, None), "audio offset change",
     "audio offset change"),
    (EarlierOffsetChange(SyncModel(0, 0.0), None), "audio offset change",
     "audio offset change"),
    # on the redo stack an Added step is there because a removal was undone: redo
    # removes the set again
    (Added(7), "adding set 7", "removing set 7"),
    (Removed(SET_7, 0, None), "removing set 7", "adding set 7"),
    (AddedMany((1, 2)), "adding 2 sets", "removing 2 sets"),
    (RemovedMany(((SET_7, 0, None),)), "removing 1 set", "adding 1 set"),
])
def test_each_step_is_named_for_what_undo_takes_back_and_redo_does_again(
        step: UndoStep, undo: str, redo: str) -> None:
    assert step_label(step) == undo
    assert step_label(step, redo=True) == redo
