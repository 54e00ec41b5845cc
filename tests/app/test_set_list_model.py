"""The frame-set list's model: one row per set, what each cell shows by data role, and
which rows it announces as changed (the view repaints only those)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from PySide6.QtCore import Qt

from app.set_table import COLUMNS, MISSING, PENDING, PENDING_TIP, SetListModel, clock_text, column
from app.style import DECISION_TEXT_COLOURS, WARNING_TEXT_COLOUR
from speechcal_core.session.model import FrameSet
from speechcal_core.session.store import load_session

DISPLAY, TOOLTIP = Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.ToolTipRole
FOREGROUND, ALIGNMENT = Qt.ItemDataRole.ForegroundRole, Qt.ItemDataRole.TextAlignmentRole
LAST = len(COLUMNS) - 1


@pytest.fixture
def sets(qapp, searched_session_file: Path) -> list[FrameSet]:
    """The tiny session's sets as ``process`` makes them: best still frames, figures."""
    return load_session(searched_session_file).sets


class Announced:
    """The rows a model announced: changed (first, last), inserted, removed."""

    def __init__(self, model: SetListModel) -> None:
        self.changed: list[tuple[int, int]] = []
        self.inserted: list[tuple[int, int]] = []
        self.removed: list[tuple[int, int]] = []
        model.dataChanged.connect(self._changed)
        model.rowsInserted.connect(lambda _parent, a, b: self.inserted.append((a, b)))
        model.rowsRemoved.connect(lambda _parent, a, b: self.removed.append((a, b)))

    def _changed(self, first, last, _roles) -> None:
        # every column of a changed row: the view repaints the rows, not single cells
        assert (first.column(), last.column()) == (0, LAST)
        self.changed.append((first.row(), last.row()))


def text(model: SetListModel, row: int, name: str) -> str:
    return model.index(row, column(name)).data(DISPLAY)


def test_row_n_shows_set_n(sets: list[FrameSet]) -> None:
    model = SetListModel()
    model.set_sets(sets, sets[0].t_ns)
    assert model.rowCount() == len(sets) and model.columnCount() == len(COLUMNS)
    for row, s in enumerate(sets):
        assert text(model, row, "#") == str(s.id)
        assert text(model, row, "time") == clock_text((s.t_ns - sets[0].t_ns) / 1e9)
        assert text(model, row, "word") == "capture"
        assert text(model, row, "frames") == f"{len(s.frames)}/{len(s.frames)}"
        assert text(model, row, "decision") == "? undecided"
    assert [model.headerData(c, Qt.Orientation.Horizontal) for c in range(len(COLUMNS))] == \
        [header for header, _tip in COLUMNS]


def test_each_role_gives_what_the_cell_shows(sets: list[FrameSet]) -> None:
    """Text, its colour (the list's own, the decision's, amber for a warning), the
    figures right-aligned, and per row a tooltip naming each camera's figures."""
    first = sets[0]
    blurred = replace(first, decision="rejected", frames=(
        replace(first.frames[0], sharpness=0.31, flags=("blurred",)), *first.frames[1:]))
    model = SetListModel()
    model.set_sets([blurred, *sets[1:]], first.t_ns)
    sharp = model.index(0, column("worst sharp"))
    assert sharp.data(DISPLAY) == "▲ 0.31"
    assert sharp.data(FOREGROUND).color() == WARNING_TEXT_COLOUR
    assert model.index(1, column("worst sharp")).data(FOREGROUND) is None
    decision = model.index(0, column("decision"))
    assert decision.data(DISPLAY) == "✘ rejected"
    assert decision.data(FOREGROUND).color() == DECISION_TEXT_COLOURS["rejected"]
    right = Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter
    assert sharp.data(ALIGNMENT) == right
    assert model.index(0, column("word")).data(ALIGNMENT) is None
    tip = model.index(0, column("#")).data(TOOLTIP)
    assert tip.startswith("trigger 'capture'")
    assert f"{first.frames[0].stream}: sharpness 0.31" in tip and "▲ blurred" in tip
    assert all(model.index(0, c).data(TOOLTIP) == tip for c in range(len(COLUMNS)))
    assert sharp.data(Qt.ItemDataRole.DecorationRole) is None


def test_sets_being_rescored_show_pending_figures(sets: list[FrameSet]) -> None:
    """A set waiting for re-scoring shows "…" where its figures will come (not "–",
    which says there are none), and its tooltip says why."""
    nearest = replace(sets[1], frames=tuple(replace(f, sharpness=None, corners=None, flags=())
                                            for f in sets[1].frames))
    model = SetListModel()
    model.set_sets([sets[0], nearest, *sets[2:]], sets[0].t_ns, {nearest.id})
    assert text(model, 1, "worst sharp") == text(model, 1, "fewest corners") == PENDING
    assert model.index(1, 0).data(TOOLTIP).startswith(PENDING_TIP)
    model.set_sets([sets[0], nearest, *sets[2:]], sets[0].t_ns)  # re-scoring cancelled
    assert text(model, 1, "worst sharp") == MISSING


def test_a_decision_announces_its_row_alone(sets: list[FrameSet]) -> None:
    model = SetListModel()
    model.set_sets(sets, sets[0].t_ns)
    announced = Announced(model)
    model.update_row(2, sets[2].with_decision("accepted"))
    assert announced.changed == [(2, 2)]
    assert text(model, 2, "decision") == "✔ accepted"
    model.update_row(2, model.row(2).set)  # the same set again: nothing to say
    assert announced.changed == [(2, 2)]


def test_a_rewrite_announces_the_runs_of_rows_that_changed(sets: list[FrameSet]) -> None:
    """Re-scoring rewrites the whole list after each batch: the sets it left alone (the
    same objects) keep their rows; an offset edit (every time from the first frame
    moves) changes every row, announced at once."""
    model = SetListModel()
    model.set_sets(sets, sets[0].t_ns)
    announced = Announced(model)
    rescored = [s.with_decision("rejected") if i in (0, 1, 3) else s for i, s in enumerate(sets)]
    model.set_sets(rescored, sets[0].t_ns)
    assert announced.changed == [(0, 1), (3, 3)]
    model.set_sets(rescored, sets[0].t_ns)
    assert announced.changed == [(0, 1), (3, 3)]
    model.set_sets(rescored, sets[0].t_ns - 10**9)
    assert announced.changed[2:] == [(0, len(sets) - 1)]
    assert announced.inserted == announced.removed == []


def test_sets_added_and_removed_grow_and_shrink_the_list_at_its_end(
        sets: list[FrameSet]) -> None:
    """Row n stays set n: a set added between others shifts the rows after it (they are
    announced as changed) and adds a row at the end; removing it takes that row away."""
    model = SetListModel()
    model.set_sets(sets, sets[0].t_ns)
    announced = Announced(model)
    added = replace(sets[1], id=99, t_ns=sets[1].t_ns + 1,  # its frames not yet read
                    frames=tuple(replace(f, index=-1) for f in sets[1].frames))
    more = [*sets[:2], added, *sets[2:]]
    model.set_sets(more, sets[0].t_ns)
    n = len(sets)
    assert announced.inserted == [(n, n)] and announced.changed == [(2, n - 1)]
    assert [text(model, r, "#") for r in range(n + 1)] == [str(s.id) for s in more]
    model.set_sets(sets, sets[0].t_ns)
    assert announced.removed == [(n, n)] and announced.changed[1:] == [(2, n - 1)]
    assert model.rowCount() == n


def test_sets_showing_the_same_frames_name_each_other(sets: list[FrameSet]) -> None:
    """The partner's row changes too when a set comes to show its frames."""
    model = SetListModel()
    model.set_sets(sets, sets[0].t_ns)
    announced = Announced(model)
    twin = replace(sets[3], frames=sets[1].frames)
    model.set_sets([*sets[:3], twin, *sets[4:]], sets[0].t_ns)
    assert announced.changed == [(1, 1), (3, 3)]
    assert text(model, 1, "word") == f"▲ capture · same as #{twin.id}"
    assert model.index(3, column("word")).data(FOREGROUND).color() == WARNING_TEXT_COLOUR
