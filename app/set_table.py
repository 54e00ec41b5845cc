"""The frame-set list: one row per set, decision shown by colour and symbol."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QBrush
from PySide6.QtWidgets import QAbstractItemView, QHeaderView, QTableWidget, QTableWidgetItem

from app.style import DECISION_COLOURS, DECISION_SYMBOLS, WARNING_COLOUR
from speechcal_core.session.model import FrameSet

COLUMNS = ("#", "time", "word", "skew ms", "frames", "decision")


class SetTable(QTableWidget):
    """Lists frame sets; selecting a row asks to go to that set."""

    set_chosen = Signal(int)  # row index into the session's sets

    def __init__(self, parent=None) -> None:
        super().__init__(0, len(COLUMNS), parent)
        self.setHorizontalHeaderLabels(COLUMNS)
        self.verticalHeader().hide()
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        header = self.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setStretchLastSection(True)
        self._origin_ns = 0
        self._updating = False
        self.itemSelectionChanged.connect(self._selection_changed)

    def set_sets(self, sets: list[FrameSet], origin_ns: int) -> None:
        self._updating = True
        self._origin_ns = origin_ns
        self.setRowCount(len(sets))
        for row, s in enumerate(sets):
            self.update_row(row, s)
        self._updating = False

    def update_row(self, row: int, s: FrameSet) -> None:
        rel = (s.t_ns - self._origin_ns) / 1e9
        found = sum(1 for f in s.frames if f.index >= 0)
        values = (str(s.id), f"{int(rel // 60):02d}:{rel % 60:05.2f}", s.trigger.word,
                  f"{s.skew_ns / 1e6:.1f}", f"{found}/{len(s.frames)}",
                  f"{DECISION_SYMBOLS[s.decision]} {s.decision}")
        for col, value in enumerate(values):
            item = QTableWidgetItem(value)
            if col == len(values) - 1:
                item.setForeground(QBrush(DECISION_COLOURS[s.decision]))
            if col == 4 and found < len(s.frames):
                item.setForeground(QBrush(WARNING_COLOUR))
            self.setItem(row, col, item)

    def select_row(self, row: int) -> None:
        self._updating = True
        self.selectRow(row)
        if self.item(row, 0) is not None:
            self.scrollToItem(self.item(row, 0))
        self._updating = False

    def _selection_changed(self) -> None:
        if self._updating:
            return
        rows = {i.row() for i in self.selectedIndexes()}
        if rows:
            self.set_chosen.emit(min(rows))
