"""The waveform's word marks as they were before a decision repainted only its mark's
column (kept verbatim from commit c098894 as the named baseline of ``bench_set_table.py``;
not used by the app): every change repaints the whole view.

The frame sets' word marks on the waveform, every set in two graphics items.

A mark is a band over the spoken word's extent, tinted and edged in its set's decision
colour, and a label along the top (decision symbol and set id). One item paints every
band under the playhead and one every label over it. A pyqtgraph region and text item
per set cost 2 ms each to make and move: 0.95 s on the window's thread to open 400 sets
and 0.18 s on each step of a held ``]``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import pyqtgraph as pg
from PySide6.QtCore import QLineF, QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QFont, QFontMetrics, QPainter, QPen

from app.style import BACKGROUND, DECISION_COLOURS, DECISION_SYMBOLS

if TYPE_CHECKING:
    from PySide6.QtGui import QTransform
    from PySide6.QtWidgets import QStyleOptionGraphicsItem, QWidget

#: the least room between two sets' labels, pixels: a label that would come closer to
#: the one before it is hidden (its band stays) until zooming in makes room
LABEL_GAP_PX = 4
#: a label's padding around its text, pixels (its background hides the playhead behind it)
LABEL_PAD_PX = (4, 2)
#: the data height the labels hang from (the waveform's y range is -1..1)
LABEL_TOP_Y = 1.0
BAND_ALPHA = 70


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
        """Colour a set's mark for its new decision."""
        mark = self._marks.get(set_id)
        if mark is not None and mark.decision != decision:
            mark.decision = decision
            self.bands.update()
            self.labels.update()

    def set_current(self, set_id: int | None) -> None:
        """The set under the playhead: its label is drawn bold and never thinned out."""
        if set_id != self.current:
            self.current = set_id
            self.labels.update()

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
        """The marks whose labels show in the view as it is now, from the left: one that
        would touch the last shown is left out ("?20?21" when two words lie close in the
        whole session's view), and so is one that would touch the current set's label,
        which always shows."""
        box = self.plot.getViewBox()
        (x0, x1), _y = box.viewRange()
        width = box.width()
        if x1 <= x0 or width <= 0:
            return []
        per_x = width / (x1 - x0)

        def span(mark: Mark) -> tuple[float, float]:
            left = (mark.middle + self.shift_s - x0) * per_x - self.label_width(mark) / 2
            return left, left + self.label_width(mark)

        current = self._marks.get(self.current) if self.current is not None else None
        kept = span(current) if current is not None else None
        right = float("-inf")
        shown = []
        for mark in self._by_middle:
            left, end = span(mark)
            if mark is current:
                shown.append(mark)
                right = max(right, end)
            elif left >= right + LABEL_GAP_PX and (
                    kept is None or end + LABEL_GAP_PX <= kept[0]
                    or left >= kept[1] + LABEL_GAP_PX):
                shown.append(mark)
                right = end
        return shown

    def label_width(self, mark: Mark) -> float:
        """A label's width on screen, pixels, its padding included (bold when current)."""
        metrics = self._current_metrics if mark.set_id == self.current else self._metrics
        return metrics.horizontalAdvance(mark.text) + 2 * LABEL_PAD_PX[0]

    def label_height(self) -> float:
        """A label's height on screen, pixels, its padding included."""
        return self._metrics.height() + 2 * LABEL_PAD_PX[1]

    def _changed(self) -> None:
        for item in (self.bands, self.labels):
            item.prepareGeometryChange()
            item.update()

    def visible(self) -> list[Mark]:
        """The marks that overlap the view (drawn shifted)."""
        (x0, x1), _y = self.plot.getViewBox().viewRange()
        s = self.shift_s
        return [m for m in self._marks.values() if m.end + s >= x0 and m.start + s <= x1]


class _Layer(pg.GraphicsObject):
    """The bands or the labels of :class:`WordMarks`, painted in screen pixels."""

    def __init__(self, marks: WordMarks, labels: bool) -> None:
        super().__init__()
        self.marks = marks
        self.is_labels = labels

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

    def paint(self, painter: QPainter, _option: QStyleOptionGraphicsItem,
              _widget: QWidget | None = None) -> None:
        box = self.getViewBox()
        if box is None:
            return
        to_screen = painter.transform()
        (_x0, _x1), (y0, y1) = box.viewRange()
        painter.save()
        painter.resetTransform()
        if self.is_labels:
            self._paint_labels(painter, to_screen)
        else:
            top, bottom = to_screen.map(QPointF(0, y1)).y(), to_screen.map(QPointF(0, y0)).y()
            self._paint_bands(painter, to_screen, top, bottom)
        painter.restore()

    def _paint_bands(self, painter: QPainter, to_screen: QTransform, top: float,
                     bottom: float) -> None:
        shift = self.marks.shift_s
        bands: dict[str, list[QRectF]] = {}
        for mark in self.marks.visible():
            left = to_screen.map(QPointF(mark.start + shift, 0)).x()
            right = to_screen.map(QPointF(mark.end + shift, 0)).x()
            bands.setdefault(mark.decision, []).append(
                QRectF(left, top, right - left, bottom - top))
        for decision, rects in bands.items():  # one brush and pen per decision
            colour = DECISION_COLOURS[decision]
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QColor(colour.red(), colour.green(), colour.blue(), BAND_ALPHA))
            painter.drawRects(rects)
            painter.setPen(QPen(colour, 1))
            painter.drawLines([QLineF(x, top, x, bottom) for rect in rects
                               for x in (rect.left(), rect.right())])

    def _paint_labels(self, painter: QPainter, to_screen: QTransform) -> None:
        marks = self.marks
        pad_x, pad_y = LABEL_PAD_PX
        height = marks.label_height()
        top = to_screen.map(QPointF(0, LABEL_TOP_Y)).y()
        for mark in marks.shown_labels():
            middle = to_screen.map(QPointF(mark.middle + marks.shift_s, 0)).x()
            width = marks.label_width(mark)
            rect = QRectF(middle - width / 2, top, width, height)
            painter.fillRect(rect, BACKGROUND)
            painter.setFont(marks.current_font if mark.set_id == marks.current else marks.font)
            painter.setPen(DECISION_COLOURS[mark.decision].lighter(140))
            painter.drawText(rect.adjusted(pad_x, pad_y, -pad_x, -pad_y), 0, mark.text)
