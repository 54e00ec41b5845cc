"""The frame-set list: one row per set, decision and warnings shown by colour and symbol.

Row ``n`` is always the session's set ``n``; a filter hides rows, it never reorders them.
:class:`SetListModel` holds the sets and works out what a row shows when its set changes
(its tooltip when asked for), telling the view which rows changed; :class:`SetTable`
draws the rows in view, hides those the filter hides and fits the columns to their texts.
An offset edit changes every row: the list then describes each set once (no Qt call per
cell) and repaints the rows in view; a decision changes one row.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from PySide6.QtCore import QAbstractTableModel, QEvent, QModelIndex, QSize, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QPalette
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QStyle,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QTableView,
)

from app.style import DECISION_SYMBOLS, DECISION_TEXT_COLOURS, WARNING_SYMBOL, WARNING_TEXT_COLOUR
from speechcal_core.frames.sets import BLURRED_BELOW, BLURRED_BELOW_SESSION, MIN_CORNERS
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

#: (header, header tooltip) per column
COLUMNS = (
    ("#", "the set's number (as on the waveform markers)"),
    ("time", "when the trigger word was said, from the first frame (min:s); the chosen "
             "frames are the stillest moment near it, often a little later"),
    ("word", "the trigger word heard; \"added\": added by hand (T), \"similar\": found "
             "like another set (S)"),
    ("worst\nsharp", "the least sharp of the set's chosen frames. Each camera's sharpness is "
                     "relative to its frames of the board held still around the trigger: "
                     "1.00 is as sharp as the still board there; below "
                     f"{BLURRED_BELOW:.2f} a frame is flagged blurred (where the board "
                     "never stops: relative to its sharp frames in this session, flagged "
                     f"below {BLURRED_BELOW_SESSION:.2f})"),
    ("fewest\ncorners", "the fewest target corners found in any camera's chosen frame; "
                        f"under {MIN_CORNERS} the camera is flagged as not seeing the target"),
    ("skew\nms", "the largest stamp difference between the set's frames"),
    ("frames", "cameras with a frame for this set / cameras"),
    ("decision", "accepted, rejected or undecided"),
)
HEADERS = tuple(h for h, _tip in COLUMNS)
WORD, SHARP, CORNERS, SKEW, FRAMES, DECISION = 2, 3, 4, 5, 6, 7
MISSING = "–"  # a figure no camera has
PENDING = "…"  # a figure the re-scoring of the set (after an offset edit) will bring
PENDING_TIP = ("re-scoring: the frames nearest the trigger are shown until the best still "
               "frames are chosen and measured")


#: the selected row's background: light, so the decision and warning colours stay legible
SELECTED_ROW = QColor(196, 222, 250)


def column(name: str) -> int:
    """The column whose header is ``name`` (line breaks read as spaces)."""
    return [h.replace("\n", " ") for h in HEADERS].index(name)


def clock_text(seconds: float) -> str:
    """A time from the first frame as the set list's time column shows it (min:s, to
    the hundredth: 59.996 s is "01:00.00", a time before the first frame "-00:00.40")."""
    hundredths = round(abs(seconds) * 100)
    minutes, rest = divmod(hundredths, 6000)
    return f"{'-' if seconds < 0 and hundredths else ''}{minutes:02d}:{rest / 100:05.2f}"


#: the item data roles the list answers (Qt passes them as numbers)
DISPLAY = int(Qt.ItemDataRole.DisplayRole)
TOOLTIP = int(Qt.ItemDataRole.ToolTipRole)
FOREGROUND = int(Qt.ItemDataRole.ForegroundRole)
ALIGNMENT = int(Qt.ItemDataRole.TextAlignmentRole)
#: the figures' cells are right-aligned
RIGHT_ALIGNED = Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter
RIGHT = int(RIGHT_ALIGNED)
#: a cell's features as the list draws it: a text, wrapped as QTableView wraps words (set
#: whole, not read and added to: each Qt flag read or combined in Python costs
#: microseconds, 8 columns by 20 rows a paint)
HAS_TEXT = (QStyleOptionViewItem.ViewItemFeature.HasDisplay
            | QStyleOptionViewItem.ViewItemFeature.WrapText)
WARNING_BRUSH = QBrush(WARNING_TEXT_COLOUR)
DECISION_BRUSHES = {d: QBrush(c) for d, c in DECISION_TEXT_COLOURS.items()}
#: a text's shape: its UTF-8 with every digit a 0 (a column is as wide as its widest
#: shape, measured once with the font's widest digit: 300 times "mm:ss.hh" are one
#: shape; bytes, as str.translate maps the list's "▲ 0.52" a character at a time)
SHAPE = bytes.maketrans(b"123456789", b"000000000")


class RowView:
    """What one set's row shows: texts, text colours (None: the list's own), and its
    tooltip (worked out when first asked for: the camera lines are the dear part)."""

    __slots__ = ("_tooltip", "brushes", "pending", "same", "set", "shapes", "texts")

    def __init__(self, s: FrameSet, origin_ns: int, pending: bool,
                 same: tuple[int, ...]) -> None:
        self.set, self.pending, self.same = s, pending, same
        q = summarize(s)
        missing = PENDING if pending else MISSING
        sharp = missing if q.worst_sharpness is None else f"{q.worst_sharpness:.2f}"
        corners = missing if q.fewest_corners is None else str(q.fewest_corners)
        # one camera (or one frame found): no two frames to lie apart
        skew = f"{s.skew_ns / 1e6:.1f}" if q.frames_found > 1 else MISSING
        frames = f"{q.frames_found}/{q.frames_total}"
        word = word_text(s) + (f" · same as {listed_ids(same)}" if same else "")
        warned = (bool(same), q.sharpness_warned, q.corners_warned, q.skew_warned,
                  q.frames_warned)  # the columns WORD to FRAMES
        texts = [str(s.id), clock_text((s.t_ns - origin_ns) / 1e9)]
        brushes: list[QBrush | None] = [None, None]
        for text, w in zip((word, sharp, corners, skew, frames), warned, strict=True):
            texts.append(f"{WARNING_SYMBOL} {text}" if w else text)
            brushes.append(WARNING_BRUSH if w else None)
        texts.append(f"{DECISION_SYMBOLS[s.decision]} {s.decision}")
        brushes.append(DECISION_BRUSHES[s.decision])
        self.texts, self.brushes = tuple(texts), tuple(brushes)
        self.shapes = tuple([t.encode().translate(SHAPE) for t in texts])
        self._tooltip: str | None = None

    def shows(self, s: FrameSet, pending: bool, same: tuple[int, ...]) -> bool:
        """Whether this row is what ``s`` (sets are immutable) shows with these marks."""
        return self.set is s and self.pending == pending and self.same == same

    @property
    def tooltip(self) -> str:
        if self._tooltip is None:
            s = self.set
            details = f"{trigger_line(s)}\n{camera_lines(s)}"
            if self.same:
                details = f"{same_frames_line(self.same)}\n{details}"
            if self.pending:
                details = f"{PENDING_TIP}\n{details}"
            self._tooltip = details
        return self._tooltip


class SetListModel(QAbstractTableModel):
    """The session's frame sets as rows (row ``n``: set ``n``) and :data:`COLUMNS`.

    :meth:`set_sets` and :meth:`update_row` take the sets as they are now; rows whose set
    (an immutable object), re-scoring mark and same-frames partners stay the same are left
    as they are, the others are described again and announced with ``dataChanged`` (one
    signal per run of neighbouring rows); rows beyond the new count are removed, new ones
    appended, as a list of rows grows and shrinks at its end.
    """

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self._rows: list[RowView] = []
        self._origin_ns = 0
        self._same: dict[int, tuple[int, ...]] = {}  # set id -> sets showing its frames
        #: per column, how many rows show each text shape (see :data:`SHAPE`)
        self._shapes: list[dict[bytes, int]] = [{} for _ in COLUMNS]

    # -- Qt's model interface -----------------------------------------------------------
    def rowCount(self, parent: QModelIndex = QModelIndex()) -> int:  # noqa: B008 (Qt's)
        return 0 if parent.isValid() else len(self._rows)

    def columnCount(self, parent: QModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(COLUMNS)

    def data(self, index: QModelIndex, role: int = DISPLAY):
        if role == DISPLAY:
            return self._rows[index.row()].texts[index.column()]
        if role == FOREGROUND:
            return self._rows[index.row()].brushes[index.column()]
        if role == ALIGNMENT:
            return RIGHT if SHARP <= index.column() <= FRAMES else None
        if role == TOOLTIP:
            return self._rows[index.row()].tooltip
        return None

    def headerData(self, section: int, orientation: Qt.Orientation, role: int = DISPLAY):
        if orientation == Qt.Orientation.Horizontal and 0 <= section < len(COLUMNS):
            if role == DISPLAY:
                return COLUMNS[section][0]
            if role == TOOLTIP:
                return COLUMNS[section][1]
        return None

    # -- the sets -----------------------------------------------------------------------
    def row(self, row: int) -> RowView:
        """What row ``row`` shows."""
        return self._rows[row]

    def shapes(self, col: int) -> Iterable[bytes]:
        """The shapes of the texts column ``col`` shows (see :data:`SHAPE`)."""
        return self._shapes[col].keys()

    def set_sets(self, sets: Sequence[FrameSet], origin_ns: int,
                 pending: frozenset[int] | set[int] = frozenset()) -> set[int]:
        """One row per set (times from ``origin_ns``); sets whose ids are in ``pending``
        are being re-scored. Returns the columns whose texts changed shape."""
        same = same_frames(sets)
        moved = origin_ns != self._origin_ns  # every time changes
        self._origin_ns, self._same = origin_ns, same
        # a set inserted shifts the rows after it: their descriptions are kept
        kept = {} if moved else {id(r.set): r for r in self._rows}
        rows = []
        for s in sets:
            mark, partners = s.id in pending, same.get(s.id, ())
            r = kept.get(id(s))
            rows.append(r if r is not None and r.shows(s, mark, partners)
                        else RowView(s, origin_ns, mark, partners))
        changed: set[int] = set()
        old = len(self._rows)
        if len(rows) < old:
            self.beginRemoveRows(QModelIndex(), len(rows), old - 1)
            for r in self._rows[len(rows):]:
                self._count(r, -1, changed)
            del self._rows[len(rows):]
            self.endRemoveRows()
        first = None  # the first row of a run of changed rows
        for i in range(len(self._rows)):
            if self._rows[i] is rows[i]:
                if first is not None:
                    self._changed(first, i - 1)
                    first = None
                continue
            self._recount(self._rows[i], rows[i], changed)
            self._rows[i] = rows[i]
            if first is None:
                first = i
        if first is not None:
            self._changed(first, len(self._rows) - 1)
        if len(rows) > old:
            self.beginInsertRows(QModelIndex(), old, len(rows) - 1)
            for r in rows[old:]:
                self._count(r, 1, changed)
            self._rows.extend(rows[old:])
            self.endInsertRows()
        return changed

    def update_row(self, row: int, s: FrameSet, pending: bool = False) -> set[int]:
        """Show ``s`` in ``row`` (its set decided); the columns whose texts changed shape."""
        partners = self._same.get(s.id, ())
        before = self._rows[row]
        if before.shows(s, pending, partners):
            return set()
        changed: set[int] = set()
        self._rows[row] = RowView(s, self._origin_ns, pending, partners)
        self._recount(before, self._rows[row], changed)
        self._changed(row, row)
        return changed

    def _changed(self, first: int, last: int) -> None:
        self.dataChanged.emit(self.index(first, 0), self.index(last, len(COLUMNS) - 1))

    def _recount(self, old: RowView, new: RowView, changed: set[int]) -> None:
        """Count ``old``'s shapes out and ``new``'s in, where they differ (an offset
        edit changes every time, rarely a shape); ``changed`` gets the columns where a
        shape appeared or went."""
        if old.shapes == new.shapes:
            return
        for col, (was, now) in enumerate(zip(old.shapes, new.shapes, strict=True)):
            if was != now:
                self._count_shape(col, was, -1, changed)
                self._count_shape(col, now, 1, changed)

    def _count(self, r: RowView, step: int, changed: set[int]) -> None:
        """Count ``r``'s shapes in (``step`` 1) or out (-1)."""
        for col, shape in enumerate(r.shapes):
            self._count_shape(col, shape, step, changed)

    def _count_shape(self, col: int, shape: bytes, step: int, changed: set[int]) -> None:
        counts = self._shapes[col]
        n = counts.get(shape, 0) + step
        if n:
            counts[shape] = n
        else:
            del counts[shape]
        if n == 0 or (step > 0 and n == 1):
            changed.add(col)


class OwnColoursDelegate(QStyledItemDelegate):
    """Draws a cell from its row's description (:meth:`SetListModel.row`) in one call,
    as Qt's delegate draws it from the model's data roles (eight calls into Python per
    cell), and a selected cell's text in its own colour (decision, warning), not the
    highlight's, so the current set still shows whether it is accepted or rejected."""

    def __init__(self, model: SetListModel, parent=None) -> None:
        super().__init__(parent)
        self._model = model

    def initStyleOption(self, option: QStyleOptionViewItem, index) -> None:
        row, col = self._model.row(index.row()), index.column()
        option.index = index
        option.text = row.texts[col]
        option.features = HAS_TEXT  # the view's (see SetTable) and a text
        if SHARP <= col <= FRAMES:
            option.displayAlignment = RIGHT_ALIGNED
        brush = row.brushes[col]
        if brush is not None:
            palette = option.palette
            palette.setBrush(QPalette.ColorRole.Text, brush)
            palette.setBrush(QPalette.ColorRole.HighlightedText, brush)


class SetTable(QTableView):
    """Lists frame sets (see :class:`SetListModel`); selecting a row asks to go to that set."""

    set_chosen = Signal(int)  # row index == index into the session's sets
    #: :meth:`least_width` changed (the columns were fitted to other texts or a new font)
    least_width_changed = Signal(int)

    def __init__(self, parent=None) -> None:
        super().__init__(parent)
        self.sets_model = SetListModel(self)
        self.setModel(self.sets_model)
        self.verticalHeader().hide()
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.setWordWrap(True)  # as Qt's default (see HAS_TEXT); no alternating colours
        palette = self.palette()
        palette.setColor(QPalette.ColorRole.Highlight, SELECTED_ROW)
        palette.setColor(QPalette.ColorRole.HighlightedText, QColor(0, 0, 0))
        self.setPalette(palette)
        self._delegate = OwnColoursDelegate(self.sets_model, self)
        self.setItemDelegate(self._delegate)
        header = self.horizontalHeader()
        # fitted to the texts' shapes once per change (fit_columns), without measuring
        # rows: ResizeToContents measured the whole list on every change
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        header.setStretchLastSection(True)
        self._widths: dict[bytes, int] = {}  # a text shape's cell width at the list's font
        self._widest_digit = ""
        self._word_width = 0  # the word column's width for its widest text
        self._decision_width = 0  # the decision column's, for its texts
        self._least_width = 0  # the last least_width told of
        self._updating = False
        self.selectionModel().selectionChanged.connect(self._selection_changed)
        #: whether the last mouse press changed the selection (and so chose a set)
        self._press_chose = False
        self.clicked.connect(self._clicked)
        # to the headings before any row: a list that stays empty (no trigger word
        # found) kept Qt's 100 px columns and scrolled sideways, "decision" out of view
        self.fit_columns()

    def set_sets(self, sets: list[FrameSet], origin_ns: int,
                 pending: frozenset[int] | set[int] = frozenset()) -> None:
        """One row per set; sets whose ids are in ``pending`` are being re-scored."""
        self._updating = True
        try:
            changed = self.sets_model.set_sets(sets, origin_ns, pending)
            self.fit_columns(changed)
        finally:
            self._updating = False

    def update_row(self, row: int, s: FrameSet, pending: bool = False) -> None:
        """Show ``s`` in ``row`` (the columns whose texts changed shape refitted)."""
        changed = self.sets_model.update_row(row, s, pending)
        if changed:
            self.fit_columns(changed)

    # -- column widths ------------------------------------------------------------------
    def fit_columns(self, columns: Iterable[int] | None = None) -> None:
        """Every column (of ``columns``, by default all) as wide as its widest text, as
        Qt's own fitting makes it, without measuring a row: each text shape's width is
        measured once. The last one takes the rest; the word column gives way where the
        list is too narrow for it (see :meth:`_fit_word`)."""
        wanted = set(range(len(COLUMNS)) if columns is None else columns)
        header = self.horizontalHeader()
        for col in sorted(wanted):
            width = max((self._cell_width(shape) for shape in self.sets_model.shapes(col)),
                        default=0)
            width = max(width, header.sectionSizeHint(col))
            if col == DECISION:  # it stretches, never below its texts
                self._decision_width = width
            elif col == WORD:  # _fit_word sets it
                self._word_width = width
            elif header.sectionSize(col) != width:
                header.resizeSection(col, width)
        if WORD in wanted and not self.isVisible():
            header.resizeSection(WORD, self._word_width)
        self._fit_word()
        least = self.least_width()
        if least != self._least_width:
            self._least_width = least
            self.least_width_changed.emit(least)

    def least_width(self) -> int:
        """The narrowest the list shows every column at, pixels: each as wide as its
        texts, the word column as its header (its long texts end in "…"), and room for
        the frame and a scrollbar."""
        header = self.horizontalHeader()
        others = sum(header.sectionSize(c) for c in range(DECISION) if c != WORD)
        return (others + header.sectionSizeHint(WORD) + self._decision_width
                + self.verticalScrollBar().sizeHint().width() + 2 * self.frameWidth())

    def _cell_width(self, shape: bytes) -> int:
        """The width Qt's fitting gives a cell of this shape (see :data:`SHAPE`)."""
        width = self._widths.get(shape)
        if width is None:
            if not self._widest_digit:
                metrics = self.fontMetrics()
                self._widest_digit = max("0123456789", key=metrics.horizontalAdvance)
            option = QStyleOptionViewItem()
            self.initViewItemOption(option)
            option.text = shape.decode().replace("0", self._widest_digit)
            option.features |= QStyleOptionViewItem.ViewItemFeature.HasDisplay
            width = self.style().sizeFromContents(
                QStyle.ContentsType.CT_ItemViewItem, option, QSize(), self).width()
            width += 1 if self.showGrid() else 0  # as QTableView::sizeHintForColumn
            self._widths[shape] = width
        return width

    def _fit_word(self) -> None:
        """Narrow the word column, its long texts ending in "…" (the row's tooltip says
        them whole), where the list is too narrow for every column: "▲ capture · similar
        · same as #1, #3" pushed the decision column out of view behind a scrollbar."""
        if not self.isVisible() or not self._word_width:
            return
        header = self.horizontalHeader()
        # the last column stretches, but never below its own width (100 px at first)
        if header.sectionSize(DECISION) != self._decision_width:
            header.resizeSection(DECISION, self._decision_width)
        others = sum(header.sectionSize(c) for c in range(DECISION) if c != WORD)
        room = self.viewport().width() - others - self._decision_width
        least = header.sectionSizeHint(WORD)
        width = max(least, min(self._word_width, room))
        if width != header.sectionSize(WORD):
            header.resizeSection(WORD, width)

    def changeEvent(self, event) -> None:
        """Another font or style: every text shape is measured again."""
        super().changeEvent(event)
        if event.type() in (QEvent.Type.FontChange, QEvent.Type.StyleChange):
            self._widths.clear()
            self._widest_digit = ""
            self.fit_columns()

    def viewportEvent(self, event) -> bool:
        if event.type() == QEvent.Type.Resize:  # the list's width, or its scrollbar, changed
            self._fit_word()
        return super().viewportEvent(event)

    # -- rows shown and chosen ----------------------------------------------------------
    def show_rows(self, rows: list[int], current: int) -> None:
        """Hide every row not in ``rows``; select ``current`` if it is shown, else none.
        Only the rows whose state changes are told (a decision hides one at most)."""
        self._updating = True
        try:
            keep = set(rows)
            for row in range(self.sets_model.rowCount()):
                hide = row not in keep
                if self.isRowHidden(row) != hide:
                    self.setRowHidden(row, hide)
        finally:
            self._updating = False
        self.select_row(current)

    def select_row(self, row: int) -> None:
        self._updating = True
        try:
            if 0 <= row < self.sets_model.rowCount() and not self.isRowHidden(row):
                self.selectRow(row)
                self.scrollTo(self.sets_model.index(row, 0))
            else:
                self.clearSelection()
        finally:
            self._updating = False

    def resizeEvent(self, event) -> None:
        """Keep the current set's row in view when the list gets shorter."""
        super().resizeEvent(event)
        rows = self.selectionModel().selectedRows()
        if rows:
            self.scrollTo(rows[0])

    def mousePressEvent(self, event) -> None:
        self._press_chose = False
        super().mousePressEvent(event)

    def _selection_changed(self, *_args: object) -> None:
        if self._updating:
            return
        rows = {i.row() for i in self.selectedIndexes() if not self.isRowHidden(i.row())}
        if rows:
            self._press_chose = True
            self.set_chosen.emit(min(rows))

    def _clicked(self, index: QModelIndex) -> None:
        """A click on the row already selected goes back to its set (the playhead may
        have moved off it); a click that changed the selection chose it already."""
        if not self._press_chose and not self.isRowHidden(index.row()):
            self.set_chosen.emit(index.row())
