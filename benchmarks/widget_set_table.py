"""The frame-set list as it was before the model/view list: a QTableWidget whose rows are
rewritten item by item (kept verbatim from commit c44fce3 as the named baseline of
``bench_set_table.py``; not used by the app). Its columns, texts and colours are the app's
list's own, unchanged since."""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QEvent, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QPalette
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QTableWidget,
    QTableWidgetItem,
)

from app.set_table import (
    COLUMNS,
    CORNERS,
    DECISION,
    FRAMES,
    MISSING,
    PENDING,
    PENDING_TIP,
    SELECTED_ROW,
    SHARP,
    SKEW,
    WORD,
    clock_text,
)
from app.style import DECISION_SYMBOLS, DECISION_TEXT_COLOURS, WARNING_SYMBOL, WARNING_TEXT_COLOUR
from speechcal_core.review.summary import (
    camera_lines,
    listed_ids,
    same_frames_line,
    summarize,
    trigger_line,
    word_text,
)
from speechcal_core.session.model import FrameSet
from speechcal_core.session.same_frames import same_frames


class OwnColoursDelegate(QStyledItemDelegate):
    """Draws a selected cell's text in its own colour (decision, warning), not the
    highlight's, so the current set still shows whether it is accepted or rejected."""

    def initStyleOption(self, option: QStyleOptionViewItem, index) -> None:
        super().initStyleOption(option, index)
        brush = index.data(Qt.ItemDataRole.ForegroundRole)
        if brush is not None:
            option.palette.setBrush(QPalette.ColorRole.HighlightedText, brush)


class WidgetSetTable(QTableWidget):
    """Lists frame sets; selecting a row asks to go to that set."""

    set_chosen = Signal(int)  # row index == index into the session's sets

    def __init__(self, parent=None) -> None:
        super().__init__(0, len(COLUMNS), parent)
        for col, (header, tip) in enumerate(COLUMNS):
            item = QTableWidgetItem(header)
            item.setToolTip(tip)
            self.setHorizontalHeaderItem(col, item)
        self.verticalHeader().hide()
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        palette = self.palette()
        palette.setColor(QPalette.ColorRole.Highlight, SELECTED_ROW)
        palette.setColor(QPalette.ColorRole.HighlightedText, QColor(0, 0, 0))
        self.setPalette(palette)
        self._delegate = OwnColoursDelegate(self)
        self.setItemDelegate(self._delegate)
        # measures cells for fit_columns: the same sizes (the delegate above changes a
        # colour only) without a Python call per cell (100 sets: 700 cells a refit)
        self._measure = QStyledItemDelegate(self)
        header = self.horizontalHeader()
        # sized to their contents once per change (fit_columns): in ResizeToContents
        # mode every setItem measured the whole table again, a 66-set rewrite took 1.1 s
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        header.setStretchLastSection(True)
        self._origin_ns = 0
        self._word_width = 0  # the word column's width for its widest text
        # the decision column's width, and the decisions its rows showed when measured
        self._decision_width, self._decisions_measured = 0, frozenset()
        self._updating = False
        self._rows: list[tuple] = []  # what each row shows, to skip rows that stay alike
        self._same: dict[int, tuple[int, ...]] = {}  # set id -> sets showing its frames
        # (id(set), pending, origin, its same-frames sets) -> (set, what its row shows): of
        # the last rewrite (kept), and of the one under way or of the rows written since
        self._shown_kept: dict[tuple, tuple[FrameSet, tuple]] = {}
        self._shown_now: dict[tuple, tuple[FrameSet, tuple]] = {}
        self.itemSelectionChanged.connect(self._selection_changed)
        #: whether the last mouse press changed the selection (and so chose a set)
        self._press_chose = False
        self.cellClicked.connect(self._clicked)

    def set_sets(self, sets: list[FrameSet], origin_ns: int,
                 pending: frozenset[int] | set[int] = frozenset()) -> None:
        """One row per set; sets whose ids are in ``pending`` are being re-scored."""
        self._updating = True
        if origin_ns != self._origin_ns:
            self._rows = []  # every time changes
        self._origin_ns = origin_ns
        self._same = same_frames(sets)
        self.setUpdatesEnabled(False)
        try:
            # rows gone may have been the widest: every column is fitted again then
            changed = set(range(self.columnCount())) if len(sets) < self.rowCount() else set()
            self.setRowCount(len(sets))
            del self._rows[len(sets):]
            # what the rows show is kept for the sets of the last two rewrites
            self._shown_kept, self._shown_now = {**self._shown_kept, **self._shown_now}, {}
            for row, s in enumerate(sets):
                changed |= self._write_row(row, s, s.id in pending)
            self._shown_kept = self._shown_now
            self.fit_columns(changed)
        finally:
            self.setUpdatesEnabled(True)
            self._updating = False

    def fit_columns(self, columns: Iterable[int] | None = None) -> None:
        """Every column (of ``columns``, by default all) as wide as its widest text; the
        last one takes the rest. Measuring a column measures each of its rows: a
        decision, which changes only the last column, refits none. The word column
        gives way where the list is too narrow for it (see :meth:`_fit_word`)."""
        last = self.columnCount() - 1
        wanted = sorted(c for c in set(range(last) if columns is None else columns) if c < last)
        if wanted:
            self.setItemDelegate(self._measure)
            try:
                for col in wanted:
                    self.resizeColumnToContents(col)
            finally:
                self.setItemDelegate(self._delegate)
            if WORD in wanted:
                self._word_width = self.columnWidth(WORD)
        self.horizontalHeader().setStretchLastSection(True)
        self._fit_word()

    def _fit_word(self) -> None:
        """Narrow the word column, its long texts ending in "…" (the row's tooltip says
        them whole), where the list is too narrow for every column: "▲ capture · similar
        · same as #1, #3" pushed the decision column out of view behind a scrollbar."""
        if not self.isVisible() or not self._word_width:
            return
        header = self.horizontalHeader()
        decision = self._decision_column_width()
        # the last column stretches, but never below its own width (100 px at first)
        header.resizeSection(DECISION, decision)
        others = sum(self.columnWidth(c) for c in range(self.columnCount() - 1) if c != WORD)
        room = self.viewport().width() - others - decision
        least = header.sectionSizeHint(WORD)
        width = max(least, min(self._word_width, room))
        if width != self.columnWidth(WORD):
            self.setColumnWidth(WORD, width)

    def _decision_column_width(self) -> int:
        """The decision column's width for its texts, measured again only when the
        decisions its rows show change: measuring reads every row, and a decision on a
        400-set list cost 10 ms more each."""
        decisions = frozenset(shown[2] for shown in self._rows if shown)
        if decisions != self._decisions_measured or not self._decision_width:
            self.setItemDelegate(self._measure)
            try:
                self._decision_width = max(self.sizeHintForColumn(DECISION),
                                           self.horizontalHeader().sectionSizeHint(DECISION))
            finally:
                self.setItemDelegate(self._delegate)
            self._decisions_measured = decisions
        return self._decision_width

    def viewportEvent(self, event) -> bool:
        if event.type() == QEvent.Type.Resize:  # the list's width, or its scrollbar, changed
            self._fit_word()
        return super().viewportEvent(event)

    def update_row(self, row: int, s: FrameSet, pending: bool = False) -> None:
        """Show ``s`` in ``row`` (the columns whose texts changed refitted)."""
        changed = self._write_row(row, s, pending)
        if changed:
            self.fit_columns(changed)

    def _write_row(self, row: int, s: FrameSet, pending: bool) -> set[int]:
        """Put ``s`` in ``row``; the columns whose text changed (none when the row showed
        exactly that already)."""
        shown = self._shown(s, pending)
        before = self._rows[row] if row < len(self._rows) else ()
        if before == shown:
            return set()
        while len(self._rows) <= row:
            self._rows.append(())
        self._rows[row] = shown
        # a column's width follows its texts (the warning symbol is part of one)
        texts = self._texts(shown)
        old = self._texts(before) if before else None
        changed = {col for col, text in enumerate(texts) if old is None or text != old[col]}
        details = shown[3]
        for col, text in enumerate(texts):
            colour = self._colour(shown, col)
            item = self.item(row, col) if before else None
            if item is not None:  # the row's cells as they are: only what changed
                # (an offset edit changes every row: each call here lets go of the GIL,
                # which a busy worker then holds for up to a switch interval)
                if col in changed:
                    item.setText(text)
                if colour != self._colour(before, col):
                    if colour is None:
                        item.setData(Qt.ItemDataRole.ForegroundRole, None)
                    else:
                        item.setForeground(QBrush(colour))
                if details != before[3]:
                    item.setToolTip(details)
                continue
            item = QTableWidgetItem(text)
            if SHARP <= col <= FRAMES:
                item.setTextAlignment(Qt.AlignmentFlag.AlignRight
                                      | Qt.AlignmentFlag.AlignVCenter)
            if colour is not None:
                item.setForeground(QBrush(colour))
            item.setToolTip(details)
            self.setItem(row, col, item)
        return changed

    @staticmethod
    def _colour(shown: tuple, col: int) -> QColor | None:
        """The text colour of a cell of a row as :meth:`_write_row` keeps it (None: the
        list's own)."""
        if dict(shown[1]).get(col):
            return WARNING_TEXT_COLOUR
        return DECISION_TEXT_COLOURS[shown[2]] if col == DECISION else None

    def _shown(self, s: FrameSet, pending: bool) -> tuple:
        """What ``s``'s row shows: texts, warnings, decision, tooltip; kept per set object
        (sets are immutable; re-scoring rewrites the whole list after each batch, most
        rows as they were, and the tooltip's camera lines are the dear part)."""
        key = (id(s), pending, self._origin_ns, self._same.get(s.id, ()))
        kept = self._shown_kept.get(key)
        if kept is not None and kept[0] is s:
            self._shown_now[key] = kept
            return kept[1]
        shown = self._describe(s, pending)
        self._shown_now[key] = (s, shown)
        return shown

    def _describe(self, s: FrameSet, pending: bool) -> tuple:
        """:meth:`_shown`, computed."""
        rel = (s.t_ns - self._origin_ns) / 1e9
        q = summarize(s)
        missing = PENDING if pending else MISSING
        sharp = missing if q.worst_sharpness is None else f"{q.worst_sharpness:.2f}"
        corners = missing if q.fewest_corners is None else str(q.fewest_corners)
        same = self._same.get(s.id, ())
        word = word_text(s) + (f" · same as {listed_ids(same)}" if same else "")
        values = (str(s.id), clock_text(rel), word,
                  sharp, corners,
                  # one camera (or one frame found): no two frames to lie apart
                  f"{s.skew_ns / 1e6:.1f}" if q.frames_found > 1 else MISSING,
                  f"{q.frames_found}/{q.frames_total}",
                  f"{DECISION_SYMBOLS[s.decision]} {s.decision}")
        warned = {WORD: bool(same), SHARP: q.sharpness_warned, CORNERS: q.corners_warned,
                  SKEW: q.skew_warned, FRAMES: q.frames_warned}
        details = f"{trigger_line(s)}\n{camera_lines(s)}"
        if same:
            details = f"{same_frames_line(same)}\n{details}"
        if pending:
            details = f"{PENDING_TIP}\n{details}"
        return (values, tuple(sorted(warned.items())), s.decision, details)

    @staticmethod
    def _texts(shown: tuple) -> list[str]:
        """The cell texts of a row as :meth:`_write_row` kept it."""
        values, warned = shown[0], dict(shown[1])
        return [f"{WARNING_SYMBOL} {v}" if warned.get(col) else v
                for col, v in enumerate(values)]

    def show_rows(self, rows: list[int], current: int) -> None:
        """Hide every row not in ``rows``; select ``current`` if it is shown, else none."""
        self._updating = True
        keep = set(rows)
        for row in range(self.rowCount()):
            self.setRowHidden(row, row not in keep)
        self._updating = False
        self.select_row(current)

    def select_row(self, row: int) -> None:
        self._updating = True
        if 0 <= row < self.rowCount() and not self.isRowHidden(row):
            self.selectRow(row)
            if self.item(row, 0) is not None:
                self.scrollToItem(self.item(row, 0))
        else:
            self.clearSelection()
        self._updating = False

    def resizeEvent(self, event) -> None:
        """Keep the current set's row in view when the list gets shorter."""
        super().resizeEvent(event)
        rows = sorted({i.row() for i in self.selectedIndexes()})
        if rows and self.item(rows[0], 0) is not None:
            self.scrollToItem(self.item(rows[0], 0))

    def mousePressEvent(self, event) -> None:
        self._press_chose = False
        super().mousePressEvent(event)

    def _selection_changed(self) -> None:
        if self._updating:
            return
        rows = {i.row() for i in self.selectedIndexes() if not self.isRowHidden(i.row())}
        if rows:
            self._press_chose = True
            self.set_chosen.emit(min(rows))

    def _clicked(self, row: int, _column: int) -> None:
        """A click on the row already selected goes back to its set (the playhead may
        have moved off it); a click that changed the selection chose it already."""
        if not self._press_chose and not self.isRowHidden(row):
            self.set_chosen.emit(row)
