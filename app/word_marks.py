"""The frame sets' word marks on the waveform, every set in two graphics items.

A mark is a band over the spoken word's extent, tinted and edged in its set's decision
colour, and a label along the top (decision symbol and set id). One item paints every
band under the playhead and one every label over it. A pyqtgraph region and text item
per set cost 2 ms each to make and move: 0.95 s on the window's thread to open 400 sets
and 0.18 s on each step of a held ``]``. A decision or a change of the current set
repaints only the columns of the band and labels that change: a whole view's repaint cost
10 ms of the window's thread at 300 sets.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import pyqtgraph as pg
from PySide6.QtCore import QLineF, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QFont, QFontMetrics, QPainter, QPen, QTransform

from app.style import BACKGROUND, DECISION_COLOURS, DECISION_SYMBOLS

if TYPE_CHECKING:
    from collections.abc import Callable

    from PySide6.QtWidgets import QStyleOptionGraphicsItem, QWidget

#: the least room between two sets' labels, pixels: a label that would come closer to
#: the one before it goes to the next row down, or, with every row taken there, is hidden
#: (its band stays) until zooming in makes room
LABEL_GAP_PX = 4
#: rows of labels along the top: a word said just after another (a set added with T
#: beside a heard one) has its label under the other's, not left out
LABEL_ROWS = 2
#: a label's padding around its text, pixels (its background hides the playhead behind it)
LABEL_PAD_PX = (4, 2)
#: the data height the labels hang from (the waveform's y range is -1..1)
LABEL_TOP_Y = 1.0
#: the room between two rows of labels, pixels
LABEL_ROW_GAP_PX = 1
BAND_ALPHA = 70
#: a band's or label's repaint reaches this far beyond it, pixels (its edge lines, and
#: the view's rounding of the area to whole pixels)
REPAINT_PAD_PX = 3
#: the order bands are painted in, by decision (where two bands overlap, the later one's
#: tint lies on top: a rejected set's), the same for a repaint of one band and of the
#: whole view (it was the order of each decision's first set in view)
BAND_ORDER = ("accepted", "undecided", "rejected")


@dataclass
class Mark:
    """One set's word on the waveform: its extent (x, seconds) and decision."""

    set_id: int
    start: float
    end: float
    decision: str

    @property
    def middle(self) -> float:
        return (self.start + self.end) / 2

    @property
    def text(self) -> str:
        return f"{DECISION_SYMBOLS[self.decision]}{self.set_id}"


class WordMarks:
    """Every set's mark, drawn by two items added to ``plot`` (a pyqtgraph PlotWidget);
    ``shift_s`` draws them all that much later (a clap drag's preview)."""

    def __init__(self, plot: pg.PlotWidget) -> None:
        self.plot = plot
        self._marks: dict[int, Mark] = {}
        self._by_middle: list[Mark] = []
        self.shift_s = 0.0
        self.current: int | None = None  # the set under the playhead: its label always shows
        self._version = 0  # counts changes of the marks' places, texts and decisions
        self._shown_key: tuple | None = None  # what the labels shown were thinned for
        self._shown: list[Mark] = []
        self._rows: dict[int, int] = {}  # the row of each label shown, by set id
        self._widths: dict[tuple[str, bool], float] = {}  # a label's width by text, bold
        self.font = QFont()
        self._metrics = QFontMetrics(self.font)
        self.current_font = QFont(self.font)
        self.current_font.setBold(True)
        self._current_metrics = QFontMetrics(self.current_font)
        self.bands = _Layer(self, labels=False)
        self.bands.setZValue(5)
        # over the playhead and claps, on the plot's own colour: the playhead stands at a
        # set's time, right through the middle of its label
        self.labels = _Layer(self, labels=True)
        self.labels.setZValue(30)
        for item in (self.bands, self.labels):
            # the view's range is the audio's, never the marks'
            plot.addItem(item, ignoreBounds=True)

    def __len__(self) -> int:
        return len(self._marks)

    def ids(self) -> list[int]:
        """The sets marked, in the order given."""
        return list(self._marks)

    def set_marks(self, marks: list[Mark]) -> None:
        """Mark exactly these sets."""
        self._marks = {m.set_id: m for m in marks}
        self._by_middle = sorted(marks, key=lambda m: m.middle)
        self._changed()

    def set_decision(self, set_id: int, decision: str) -> None:
        """Colour a set's mark for its new decision (its band and the labels that change
        are repainted)."""
        mark = self._marks.get(set_id)
        if mark is None or mark.decision == decision:
            return
        labels = self._label_places()
        mark.decision = decision
        self._version += 1  # its label's width may change, and so the labels shown
        self.bands.update_columns([self.extent(set_id)])
        self._update_labels(labels)

    def set_current(self, set_id: int | None) -> None:
        """The set under the playhead: its label is drawn bold and never thinned out (the
        labels that change are repainted)."""
        if set_id != self.current:
            labels = self._label_places()
            self.current = set_id
            self._update_labels(labels)

    def set_shift(self, shift_s: float) -> None:
        """Draw every mark ``shift_s`` later than its extent (0: where it is)."""
        if shift_s != self.shift_s:
            self.shift_s = shift_s
            self._changed()

    def region(self, set_id: int) -> tuple[float, float]:
        """A set's word extent (x, seconds) as the sync places it, without the shift."""
        mark = self._marks[set_id]
        return mark.start, mark.end

    def extent(self, set_id: int) -> tuple[float, float]:
        """Where a set's mark is drawn (x, seconds), the shift included."""
        mark = self._marks[set_id]
        return mark.start + self.shift_s, mark.end + self.shift_s

    def x_range(self) -> tuple[float, float] | None:
        """From the first mark's start to the last one's end (unshifted); None if none."""
        if not self._marks:
            return None
        return (min(m.start for m in self._marks.values()),
                max(m.end for m in self._marks.values()))

    def at(self, x: float) -> int | None:
        """The id of the set whose drawn mark covers ``x`` (the one whose middle is
        nearest, where marks overlap); None off every mark."""
        hits = [(abs(m.middle + self.shift_s - x), m.set_id) for m in self._marks.values()
                if m.start + self.shift_s <= x <= m.end + self.shift_s]
        return min(hits)[1] if hits else None

    def label_text(self, set_id: int) -> str:
        return self._marks[set_id].text

    def decision(self, set_id: int) -> str:
        return self._marks[set_id].decision

    def shown_labels(self) -> list[Mark]:
        """The marks whose labels show in the view as it is now, from the left. The
        current set's label always shows, in the top row; any other goes in the highest
        of the LABEL_ROWS rows where it touches neither the label before it nor the
        current one ("?3" under a "?13" added just after it, where one row printed
        "?3?13" or left "?3" out), and is left out where every row is taken there.
        Worked out again only when the view or the marks changed."""
        box = self.plot.getViewBox()
        (x0, x1), _y = box.viewRange()
        width = box.width()
        key = (x0, x1, width, self.shift_s, self.current, self._version)
        if key != self._shown_key:
            self._shown, self._rows = self._stack_labels(x0, x1, width)
            self._shown_key = key
        return list(self._shown)

    def label_row(self, set_id: int) -> int:
        """The row (0: the top one) a shown label is drawn in."""
        self.shown_labels()
        return self._rows.get(set_id, 0)

    def _stack_labels(self, x0: float, x1: float, width: float
                      ) -> tuple[list[Mark], dict[int, int]]:
        """:meth:`shown_labels` and their rows worked out for the view ``x0``..``x1``,
        ``width`` pixels."""
        if x1 <= x0 or width <= 0:
            return [], {}
        per_x = width / (x1 - x0)

        def span(mark: Mark) -> tuple[float, float]:
            left = (mark.middle + self.shift_s - x0) * per_x - self.label_width(mark) / 2
            return left, left + self.label_width(mark)

        current = self._marks.get(self.current) if self.current is not None else None
        kept = span(current) if current is not None else None
        rights = [float("-inf")] * LABEL_ROWS  # where each row's last label ends
        shown, rows = [], {}
        for mark in self._by_middle:
            left, end = span(mark)
            if mark is current:
                row = 0
            else:
                row = next((r for r in range(LABEL_ROWS) if left >= rights[r] + LABEL_GAP_PX
                            and (r or kept is None or end + LABEL_GAP_PX <= kept[0]
                                 or left >= kept[1] + LABEL_GAP_PX)), None)
                if row is None:
                    continue
            shown.append(mark)
            rows[mark.set_id] = row
            rights[row] = max(rights[row], end)
        return shown, rows

    def label_width(self, mark: Mark) -> float:
        """A label's width on screen, pixels, its padding included (bold when current)."""
        key = (mark.text, mark.set_id == self.current)
        width = self._widths.get(key)
        if width is None:
            metrics = self._current_metrics if key[1] else self._metrics
            width = self._widths[key] = metrics.horizontalAdvance(key[0]) + 2 * LABEL_PAD_PX[0]
        return width

    def label_height(self) -> float:
        """A label's height on screen, pixels, its padding included."""
        return self._metrics.height() + 2 * LABEL_PAD_PX[1]

    def _changed(self) -> None:
        self._version += 1
        for item in (self.bands, self.labels):
            item.prepareGeometryChange()
            item.update()

    def _label_places(self) -> dict[int, tuple]:
        """Per label shown, what its drawing depends on: where (x of its middle, width in
        pixels), its text, decision (colour), boldness and row."""
        return {m.set_id: (m.middle + self.shift_s, self.label_width(m), m.text, m.decision,
                           m.set_id == self.current, self._rows.get(m.set_id, 0))
                for m in self.shown_labels()}

    def _update_labels(self, before: dict[int, tuple]) -> None:
        """Repaint the labels whose place or look changed since ``before`` (as
        :meth:`_label_places` gave it), where they were and where they are."""
        box = self.plot.getViewBox()
        (x0, x1), _y = box.viewRange()
        width = box.width()
        if x1 <= x0 or width <= 0:
            return
        per_px = (x1 - x0) / width
        after = self._label_places()
        spans = []
        for set_id in before.keys() | after.keys():
            was, now = before.get(set_id), after.get(set_id)
            if was == now:
                continue
            for place in (was, now):
                if place is not None:
                    middle, label_px = place[:2]
                    half = label_px / 2 * per_px
                    spans.append((middle - half, middle + half))
        self.labels.update_columns(spans)

    def visible(self, x0: float | None = None, x1: float | None = None) -> list[Mark]:
        """The marks that overlap the view (drawn shifted), or the span ``x0``..``x1``."""
        (v0, v1), _y = self.plot.getViewBox().viewRange()
        x0 = v0 if x0 is None else x0
        x1 = v1 if x1 is None else x1
        s = self.shift_s
        return [m for m in self._marks.values() if m.end + s >= x0 and m.start + s <= x1]


class _Layer(pg.GraphicsObject):
    """The bands or the labels of :class:`WordMarks`, painted in screen pixels."""

    def __init__(self, marks: WordMarks, labels: bool) -> None:
        super().__init__()
        self.marks = marks
        self.is_labels = labels
        # paint() is told the area to repaint (option.exposedRect): a decision repaints
        # one band's column, not every band
        self.setFlag(self.GraphicsItemFlag.ItemUsesExtendedStyleOption)

    def boundingRect(self) -> QRectF:
        """The view: marks are painted where they show, in screen pixels."""
        box = self.getViewBox()
        if box is None or not len(self.marks):
            return QRectF()
        return box.viewRect()

    def viewRangeChanged(self) -> None:
        """Zoom or pan: the painted area and the labels' thinning change."""
        self.prepareGeometryChange()
        self.update()

    def update_columns(self, spans: list[tuple[float, float]]) -> None:
        """Repaint the view's whole height over these spans of x (seconds), a few pixels
        wider; the rest of the view is not painted again."""
        box = self.getViewBox()
        if box is None or not spans:
            return
        (x0, x1), (y0, y1) = box.viewRange()
        width = box.width()
        if x1 <= x0 or width <= 0:
            return
        pad = REPAINT_PAD_PX * (x1 - x0) / width
        for a, b in spans:
            self.update(QRectF(a - pad, y0, b - a + 2 * pad, y1 - y0))

    def paint(self, painter: QPainter, option: QStyleOptionGraphicsItem,
              _widget: QWidget | None = None) -> None:
        box = self.getViewBox()
        if box is None:
            return
        to_screen = painter.transform()
        (_x0, _x1), (y0, y1) = box.viewRange()
        exposed = option.exposedRect  # what is repainted (seconds): marks beyond it are not
        painter.save()
        painter.resetTransform()
        if self.is_labels:
            screen = to_screen.mapRect(exposed)
            self._paint_labels(painter, to_screen, screen.left() - REPAINT_PAD_PX,
                               screen.right() + REPAINT_PAD_PX)
        else:
            top, bottom = to_screen.map(QPointF(0, y1)).y(), to_screen.map(QPointF(0, y0)).y()
            pad = REPAINT_PAD_PX / max(abs(to_screen.m11()), 1e-12)
            self._paint_bands(painter, to_screen, top, bottom,
                              self.marks.visible(exposed.left() - pad, exposed.right() + pad))
        painter.restore()

    def _paint_bands(self, painter: QPainter, to_screen: QTransform, top: float,
                     bottom: float, marks: list[Mark]) -> None:
        shift = self.marks.shift_s
        to_x = screen_x(to_screen)
        height = bottom - top
        bands: dict[str, list[tuple[float, float]]] = {decision: [] for decision in BAND_ORDER}
        for mark in marks:  # (left, width), pixels
            left = to_x(mark.start + shift)
            bands[mark.decision].append((left, to_x(mark.end + shift) - left))
        for decision, spans in bands.items():  # one brush and pen per decision
            if not spans:
                continue
            colour = DECISION_COLOURS[decision]
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QColor(colour.red(), colour.green(), colour.blue(), BAND_ALPHA))
            painter.drawRects([QRectF(left, top, width, height) for left, width in spans])
            painter.setPen(QPen(colour, 1))
            painter.drawLines([QLineF(x, top, x, bottom) for left, width in spans
                               for x in (left, left + width)])  # as QRectF.right() has it

    def _paint_labels(self, painter: QPainter, to_screen: QTransform, left: float,
                      right: float) -> None:
        """The labels shown that reach into ``left``..``right`` (screen pixels)."""
        marks = self.marks
        pad_x, pad_y = LABEL_PAD_PX
        height = marks.label_height()
        top = to_screen.map(QPointF(0, LABEL_TOP_Y)).y()
        for mark in marks.shown_labels():
            middle = to_screen.map(QPointF(mark.middle + marks.shift_s, 0)).x()
            width = marks.label_width(mark)
            if middle + width / 2 < left or middle - width / 2 > right:
                continue
            row = marks.label_row(mark.set_id)
            rect = QRectF(middle - width / 2, top + row * (height + LABEL_ROW_GAP_PX), width,
                          height)
            painter.fillRect(rect, BACKGROUND)
            painter.setFont(marks.current_font if mark.set_id == marks.current else marks.font)
            painter.setPen(DECISION_COLOURS[mark.decision].lighter(140))
            painter.drawText(rect.adjusted(pad_x, pad_y, -pad_x, -pad_y), 0, mark.text)


def screen_x(to_screen: QTransform) -> Callable[[float], float]:
    """Where ``to_screen`` puts an x (seconds) on the screen, pixels. A scale and shift
    (the view's, always) is worked out here as QTransform.map does it, to the same bits,
    without a QPointF made and mapped per mark."""
    if to_screen.type().value > QTransform.TransformationType.TxScale.value:
        return lambda x: to_screen.map(QPointF(x, 0.0)).x()
    m11, dx = to_screen.m11(), to_screen.dx()
    return lambda x: m11 * x + dx
