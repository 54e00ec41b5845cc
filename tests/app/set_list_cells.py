"""The frame-set list's cells as an operator reads them: text, tooltip, text colour."""

from __future__ import annotations

from dataclasses import dataclass

from PySide6.QtCore import QRect, Qt
from PySide6.QtGui import QColor


@dataclass(frozen=True)
class Cell:
    text: str
    tooltip: str
    colour: QColor | None  # the text's own colour; None: the list's


def cell(table, row: int, col: int) -> Cell:
    """What the list shows in ``row``, ``col``."""
    index = table.model().index(row, col)
    brush = index.data(Qt.ItemDataRole.ForegroundRole)
    return Cell(index.data(), index.data(Qt.ItemDataRole.ToolTipRole),
                None if brush is None else brush.color())


def cells(table) -> list[list[Cell]]:
    """Every row's cells."""
    model = table.model()
    return [[cell(table, r, c) for c in range(model.columnCount())]
            for r in range(model.rowCount())]


def cell_rect(table, row: int, col: int = 0) -> QRect:
    """Where the cell lies in the list's viewport."""
    return table.visualRect(table.model().index(row, col))
