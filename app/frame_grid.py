"""The camera grid: one tile per stream, aspect kept, decision border, the heard word."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from PySide6.QtCore import QEvent, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import (
    QColor,
    QFont,
    QFontMetrics,
    QHelpEvent,
    QImage,
    QPainter,
    QPen,
    QPolygonF,
)
from PySide6.QtWidgets import (
    QGridLayout,
    QLayout,
    QSizePolicy,
    QToolTip,
    QVBoxLayout,
    QWidget,
)

from app.focus_ring import FOCUS_RING_PX, FocusRing
from app.style import (
    BACKGROUND,
    CLAP_LABEL_COLOUR,
    DECISION_COLOURS,
    DECISION_SYMBOLS,
    WARNING_COLOUR,
    WARNING_SYMBOL,
)
from speechcal_core.review.summary import FLAG_SHORT_WORDS
from speechcal_core.text import counted

if TYPE_CHECKING:
    from PySide6.QtGui import QMouseEvent, QPaintEvent, QResizeEvent, QShowEvent

MARKER_COLOUR = QColor(60, 220, 120)
#: how a tile's caption begins while it shows the frame nearest a set's time
NEAREST_CAPTION = "nearest frame"
DROPPED_CAPTION = "dropped frame"
DIM_ALPHA = 110  # the dark veil over a frame held over a dropped one
#: the least room between a tile's title and the caption or warning at its right, pixels
HEADER_GAP = 12
#: the longest warning in a word or two: a tile's header keeps the whole stream name only
#: where it leaves room for this beside it
LONGEST_SHORT_WARNING = f"{WARNING_SYMBOL} " + max(FLAG_SHORT_WORDS.values(), key=len)
#: a tile's least width, pixels: TILE_MIN_WIDTH_PX[1], or less in a grid of three
#: columns or more, so that all of them with the space between them need no more than
#: GRID_MIN_WIDTH_PX, but never less than TILE_MIN_WIDTH_PX[0]; a window of up to 12
#: cameras then fits half a 1920 px screen (at 480 px, three columns of 160 px held it
#: 990 px wide, four of 120 px 994 px)
TILE_MIN_WIDTH_PX = (100, 160)
GRID_MIN_WIDTH_PX = 456
#: corner markers' radius on screen, pixels: at least, at most
MARKER_RADIUS_PX = (1.5, 4.5)
#: corners closer than this on screen (pixels) are drawn as the board's outline: their
#: markers would merge into a green block hiding the board one checks for blur
OUTLINE_BELOW_PX = 6.0
#: a tile's header height and its image's margins at the sides and foot, pixels
TILE_HEADER_PX, TILE_MARGIN_PX = 22, 3
#: the room between a tile's sides and the boxes of text at its foot, pixels
FOOT_INSET_PX = 6
#: the space between tiles, pixels
TILE_SPACING_PX = 4
#: the grid's margin around its tiles and band, pixels: room for the focus frame, which
#: then hides no decision border
GRID_MARGIN_PX = FOCUS_RING_PX + 1
#: how much larger (as a share) another column count must show the frames than the
#: near-square grid's before the grid takes it
BETTER_BY = 0.05


def square_columns(cameras: int) -> int:
    """The near-square grid's columns: its tiles' least size and the grid's follow them."""
    return max(1, math.ceil(math.sqrt(cameras)))


def least_tile_width(columns: int) -> int:
    """A tile's least width in a grid of ``columns`` (see TILE_MIN_WIDTH_PX)."""
    lo, hi = TILE_MIN_WIDTH_PX
    return max(lo, min(hi, (GRID_MIN_WIDTH_PX - (columns - 1) * TILE_SPACING_PX) // columns))


def frame_scale(cameras: int, columns: int, width: float, height: float,
                aspect: float) -> float:
    """The height in pixels at which ``cameras`` frames of ``aspect`` (width / height)
    show in ``columns`` tiles across an area of ``width`` x ``height``; 0 where the
    tiles would be smaller than their least size."""
    rows = math.ceil(cameras / columns)
    tile_w = (width - (columns - 1) * TILE_SPACING_PX) / columns
    tile_h = (height - (rows - 1) * TILE_SPACING_PX) / rows
    least = least_tile_width(columns)
    if tile_w < least or tile_h < least * 3 // 4:
        return 0.0
    return max(0.0, min((tile_w - 2 * TILE_MARGIN_PX) / aspect,
                        tile_h - TILE_HEADER_PX - TILE_MARGIN_PX))


def best_columns(cameras: int, width: float, height: float, aspect: float = 4 / 3) -> int:
    """How many columns show ``cameras`` frames largest in a ``width`` x ``height`` area:
    the near-square grid unless another shows them larger by BETTER_BY (seven 4:3 cameras
    beside the list on a laptop: two rows of four, not three rows of three, 40 % taller)."""
    square = square_columns(cameras)
    best, best_scale = square, frame_scale(cameras, square, width, height, aspect)
    for columns in range(1, cameras + 1):
        scale = frame_scale(cameras, columns, width, height, aspect)
        if scale > max(best_scale, 1e-9) * (1 + BETTER_BY):
            best, best_scale = columns, scale
    return best


def compact_names(streams: Sequence[str]) -> dict[str, str]:
    """Each stream's name without the path parts that end every stream's name, where the
    rest still tells them apart ("/cam10/image_raw" -> "/cam10" beside "/cam0/image_raw"):
    what a narrow tile's header shows of it before cutting its end. One stream, or names
    that share no ending, keep their names."""
    parts = [s.rstrip("/").split("/") for s in streams]
    if len(parts) < 2:
        return {s: s for s in streams}
    common = 0
    while all(len(p) > common + 1 and p[-1 - common] == parts[0][-1 - common]
              for p in parts):
        common += 1
    while common:
        short = ["/".join(p[:-common]) for p in parts]
        if len(set(short)) == len(short) and all(short):
            return dict(zip(streams, short, strict=True))
        common -= 1
    return {s: s for s in streams}


def header_texts(bold: QFontMetrics, plain: QFontMetrics, width: int, stream: str,
                 decision: str | None, note: str, warning: bool, short_note: str = "",
                 short_stream: str = "") -> tuple[str, str]:
    """The title (stream and decision, in ``bold``) and the note at the right (``plain``:
    the warning, else the caption) a tile's header of ``width`` pixels shows, shortened so
    they never overlap.

    The stream's name is its ``short_stream`` (the part that tells the grid's cameras
    apart) wherever the whole name would leave no room for a warning in a word or two: by
    the width alone, so that a name does not change from set to set with the warnings,
    nor between tiles of a grid. Then what a reviewer needs least goes first: the
    caption, then the decision's word (its symbol, the border's colour and the set list
    still say it), then the warning's words give way to their ``short_note`` ("▲ no
    board"), and that to the warning's symbol alone (the tile then says the words at its
    foot, see :meth:`CameraTile.warning_at_foot`: "▲ no bo…" told nothing), and at last
    the end of the stream's name."""
    symbol = f"  {DECISION_SYMBOLS[decision]}" if decision else ""
    if short_stream and bold.horizontalAdvance(f"{stream}  ?") + HEADER_GAP + \
            plain.horizontalAdvance(LONGEST_SHORT_WARNING) > width:
        stream = short_stream
    full, short = (f"{stream}{symbol} {decision}", f"{stream}{symbol}") if decision \
        else (stream, stream)
    short_note = short_note or note

    def room(title: str) -> int:
        return width - bold.horizontalAdvance(title) - HEADER_GAP

    if note and plain.horizontalAdvance(note) <= room(full):
        return full, note
    least = ""
    if warning:
        for text in (note, short_note):
            if plain.horizontalAdvance(text) <= room(short):
                return short, text
        least = WARNING_SYMBOL
    reserve = plain.horizontalAdvance(least) + HEADER_GAP if least else 0
    for title in (full, short):
        if bold.horizontalAdvance(title) <= width - reserve:
            return title, least
    name = bold.elidedText(stream, Qt.TextElideMode.ElideRight,
                           width - reserve - bold.horizontalAdvance(symbol))
    return name + symbol, least


def corner_spacing(corners: Sequence[tuple[float, float]]) -> float:
    """The median distance from each corner to its nearest neighbour (image pixels; 0
    with fewer than two corners)."""
    if len(corners) < 2:
        return 0.0
    from scipy.spatial import cKDTree

    pts = np.asarray(corners, dtype=np.float64)
    # a tree, not all pairs: a set step redraws every tile (1 ms -> 0.2 ms for 144 corners)
    nearest, _ = cKDTree(pts).query(pts, k=2)
    return float(np.median(nearest[:, 1]))


def corner_outline(corners: Sequence[tuple[float, float]]) -> np.ndarray:
    """The corners' convex hull, (N, 2) image pixels in drawing order (empty with fewer
    than three corners)."""
    if len(corners) < 3:
        return np.zeros((0, 2))
    import cv2

    hull = cv2.convexHull(np.asarray(corners, dtype=np.float32))
    return hull.reshape(-1, 2).astype(np.float64)


#: boards whose spacing and outline are kept (a dozen cameras, some hundred sets)
CORNER_SHAPES_KEPT = 4096


@functools.lru_cache(maxsize=CORNER_SHAPES_KEPT)
def kept_corner_spacing(corners: tuple[tuple[float, float], ...]) -> float:
    """:func:`corner_spacing`, computed once per board: a set step gives every tile its
    corners again, and a tree build and query that let go of the GIL cost up to a
    switch interval each to get it back while a worker computes (re-scoring)."""
    return corner_spacing(corners)


@functools.lru_cache(maxsize=CORNER_SHAPES_KEPT)
def kept_corner_outline(corners: tuple[tuple[float, float], ...]) -> np.ndarray:
    """:func:`corner_outline`, computed once per board (do not change the array)."""
    return corner_outline(corners)


def marker_radius(spacing_px: float) -> float:
    """Radius on screen of a corner marker when corners lie ``spacing_px`` apart on screen:
    a third of that, within MARKER_RADIUS_PX (dense boards stay readable, a large image
    shown big gets markers one can see)."""
    lo, hi = MARKER_RADIUS_PX
    return max(lo, min(hi, spacing_px / 3.0))


class CameraTile(QWidget):
    """Shows one camera's frame scaled to fit, or says why there is none."""

    double_clicked = Signal(str)
    #: the frame shown now has another width / height than the one before (or none was)
    shape_changed = Signal()

    def __init__(self, stream: str, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.stream = stream
        self.image: QImage | None = None
        self.message = "loading…"
        self.caption = ""
        self.decision: str | None = None
        self.warning = ""
        self.short_warning = ""  # the warning in a word or two, for a narrow header
        #: the stream's name as a narrow header shows it (set by the grid: the part that
        #: tells its cameras apart)
        self.short_name = stream
        self.footnote = ""  # drawn at the tile's foot (an enlarged camera: how to return)
        self.dimmed = False  # the image is an earlier frame held over a dropped one
        #: the caption of the frame asked for while the image held dimmed is still shown:
        #: it comes with that frame's image (the dimmed image kept "dropped frame")
        self.next_caption: str | None = None
        self.key = ""  # the number key that shows this camera alone (1-9, grid order)
        self._corners: tuple[tuple[float, float], ...] = ()
        self._corner_spacing = 0.0
        self.setMinimumSize(TILE_MIN_WIDTH_PX[1], TILE_MIN_WIDTH_PX[1] * 3 // 4)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)

    @property
    def corners(self) -> tuple[tuple[float, float], ...]:
        """The found target corners drawn over the image (image pixels)."""
        return self._corners

    @corners.setter
    def corners(self, corners: tuple[tuple[float, float], ...]) -> None:
        corners = tuple(corners)
        if corners == self._corners:
            return  # set again on every playhead refresh: spacing and outline stand
        self._corners = corners
        self._corner_spacing = kept_corner_spacing(self._corners)
        self.update()

    def show_image(self, image: QImage, caption: str | None = None) -> None:
        """Show ``image`` with ``caption`` (default: the one :meth:`expect_frame` kept
        for it, else the caption shown)."""
        if caption is None:
            caption = self.caption if self.next_caption is None else self.next_caption
        reshaped = self.image is None or self.image.size() != image.size()
        self.image, self.message, self.caption = image, "", caption
        self.next_caption = None
        if reshaped:
            self.shape_changed.emit()
        self.dimmed = False
        self.update()

    def show_message(self, message: str) -> None:
        self.image, self.message = None, message
        self.dimmed, self.next_caption = False, None
        self.update()

    def hold_dimmed(self, caption: str) -> None:
        """Keep the image shown, dimmed, with ``caption`` (during playback, where the
        camera dropped a frame: a blank tile flashed at every gap)."""
        if self.image is None:
            return
        self.caption, self.dimmed, self.next_caption = caption, True, None
        self.update()

    def expect_frame(self, caption: str) -> None:
        """A frame captioned ``caption`` was asked for: the caption shows at once, or,
        over a held dimmed image, with the frame's image (the new frame's time over the
        old dimmed image misled until it was decoded)."""
        if self.dimmed:
            self.next_caption = caption
            return
        self.caption, self.next_caption = caption, None
        self.update()

    def set_state(self, decision: str | None, warning: str = "",
                  short_warning: str = "") -> None:
        """The set's ``decision`` and this camera's ``warning`` in words ("" for none),
        and in a word or two (``short_warning``; default: the same words)."""
        self.decision, self.warning = decision, warning
        self.short_warning = short_warning or warning
        self.update()

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        self.double_clicked.emit(self.stream)

    def event(self, event: QEvent) -> bool:
        """The header in full as the tooltip (a narrow tile shortens it)."""
        if event.type() == QEvent.Type.ToolTip and isinstance(event, QHelpEvent):
            lines = [self.stream]
            if self.decision:
                lines.append(f"{DECISION_SYMBOLS[self.decision]} {self.decision}")
            if self.warning:
                lines.append(f"{WARNING_SYMBOL} {self.warning}")
            elif self.caption:
                lines.append(self.caption)
            if self.key:  # camera names count from 0, the keys from 1
                lines.append(f"key {self.key} or double-click: this camera alone")
            QToolTip.showText(event.globalPos(), "\n".join(lines), self)
            return True
        return super().event(event)

    def _draw_corners(self, p: QPainter, target: QRectF, scale: float) -> None:
        """The found corners over the image shown in ``target`` at ``scale``: a marker
        each, or, where they lie too close on screen, the board's outline."""
        p.setPen(QPen(MARKER_COLOUR, 1.5))
        spacing = self._corner_spacing * scale
        # the outline only where it is drawn (markers are the usual case)
        outline = kept_corner_outline(self._corners) if spacing < OUTLINE_BELOW_PX else ()
        if len(outline) >= 3:
            p.drawPolygon(QPolygonF([QPointF(target.x() + (x + 0.5) * scale,
                                             target.y() + (y + 0.5) * scale)
                                     for x, y in outline]))
            return
        r = marker_radius(spacing)
        for x, y in self._corners:
            p.drawEllipse(QPointF(target.x() + (x + 0.5) * scale,
                                  target.y() + (y + 0.5) * scale), r, r)

    def paintEvent(self, event: QPaintEvent) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform)
        p.fillRect(self.rect(), BACKGROUND)
        header, margin = TILE_HEADER_PX, TILE_MARGIN_PX
        area = QRectF(self.rect()).adjusted(margin, header, -margin, -margin)
        if self.image is not None and not self.image.isNull():
            iw, ih = self.image.width(), self.image.height()
            scale = min(area.width() / iw, area.height() / ih)
            w, h = iw * scale, ih * scale
            target = QRectF(area.x() + (area.width() - w) / 2, area.y() + (area.height() - h) / 2,
                            w, h)
            p.drawImage(target, self.image)
            if self.dimmed:
                p.fillRect(target, QColor(0, 0, 0, DIM_ALPHA))
            elif self._corners:
                self._draw_corners(p, target, scale)
        else:
            p.setPen(QColor(200, 200, 200))
            # clear of the decision and warning borders (1.5-5 px in): in a narrow tile
            # the message's widest line ran under them
            p.drawText(area.adjusted(FOOT_INSET_PX, 0, -FOOT_INSET_PX, 0),
                       Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap, self.message)
        if self.decision:
            pen = QPen(DECISION_COLOURS[self.decision], 3)
            p.setPen(pen)
            p.drawRect(QRectF(self.rect()).adjusted(1.5, 1.5, -1.5, -1.5))
        if self.warning:  # amber inside the decision's colour, as UX.md asks of warnings
            p.setPen(QPen(WARNING_COLOUR, 2))
            p.drawRect(QRectF(self.rect()).adjusted(4, 4, -4, -4))
        bold = QFont(self.font())
        bold.setBold(True)
        note = f"{WARNING_SYMBOL} {self.warning}" if self.warning else self.caption
        short_note = f"{WARNING_SYMBOL} {self.short_warning}" if self.warning else ""
        line = QRectF(6, 2, self.width() - 12, header - 4)
        title, note = header_texts(QFontMetrics(bold), QFontMetrics(self.font()),
                                   int(line.width()), self.stream, self.decision, note,
                                   bool(self.warning), short_note, self.short_name)
        p.setPen(QColor(235, 235, 235))
        p.setFont(bold)
        p.drawText(line, Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter, title)
        if note:
            p.setPen(WARNING_COLOUR if self.warning else QColor(170, 170, 170))
            p.setFont(self.font())
            p.drawText(line, Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter, note)
        if self.footnote:
            feet = [(self.footnote, QColor(235, 235, 235))]
        else:
            feet = [(text, colour) for text, colour in (
                (self.warning_at_foot(note), WARNING_COLOUR),
                (self.caption_at_foot(note), QColor(235, 235, 235))) if text]
        self._draw_feet(p, feet)
        p.end()

    def _draw_feet(self, p: QPainter, feet: list[tuple[str, QColor]]) -> None:
        """Draw ``feet`` (text, colour) in boxes at the tile's foot, the first highest;
        a text too wide for the tile wraps."""
        p.setFont(self.font())
        metrics = QFontMetrics(self.font())
        flags = Qt.AlignmentFlag.AlignCenter | Qt.TextFlag.TextWordWrap
        bottom = self.height() - 4
        for text, colour in reversed(feet):
            room = max(1, self.width() - 2 * FOOT_INSET_PX - 12)
            size = metrics.boundingRect(0, 0, room, 10 * metrics.height(), int(flags), text)
            box = QRectF(FOOT_INSET_PX, bottom - size.height() - 6, min(size.width(), room) + 12,
                         size.height() + 6)
            p.fillRect(box, QColor(0, 0, 0, 170))
            p.setPen(colour)
            p.drawText(box, flags, text)
            bottom = box.top() - 2

    def warning_at_foot(self, shown_in_header: str) -> str:
        """The warning in words, when the header had room for its symbol only: in full
        where the tile's foot has room for it, else in a word or two (``short_warning``)."""
        if not self.warning:
            return ""
        note = f"{WARNING_SYMBOL} {self.warning}"
        short_note = f"{WARNING_SYMBOL} {self.short_warning}"
        if shown_in_header in (note, short_note):
            return ""
        room = self.width() - 2 * FOOT_INSET_PX - 12
        return note if QFontMetrics(self.font()).horizontalAdvance(note) <= room \
            else short_note

    def caption_at_foot(self, shown_in_header: str) -> str:
        """The caption, when it says the tile shows a nearest frame (not the set's chosen
        one) and the header had no room for it: a grid of many cameras gave no sign."""
        if self.caption.startswith(NEAREST_CAPTION) and shown_in_header != self.caption:
            return self.caption
        return ""


class FrameGrid(QWidget):
    """All camera tiles in a grid, with the heard word large in a band below them (it
    covers no camera's image). The grid takes the columns that show the frames largest
    in its area (see :func:`best_columns`); its least size is the near-square grid's
    whatever the columns, so that it never holds the window wider or taller."""

    def __init__(self, streams: list[str], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.tiles: dict[str, CameraTile] = {}
        outer = QVBoxLayout(self)
        outer.setContentsMargins(*(GRID_MARGIN_PX,) * 4)
        outer.setSpacing(4)
        self._tile_area = QWidget(self)
        self._layout = QGridLayout(self._tile_area)
        self._layout.setContentsMargins(0, 0, 0, 0)
        self._layout.setSpacing(TILE_SPACING_PX)
        # the area's least size is set in _arrange, not taken from the columns in use
        self._layout.setSizeConstraint(QLayout.SizeConstraint.SetNoConstraint)
        outer.addWidget(self._tile_area, 1)
        self.word_band = WordBand(self)
        outer.addWidget(self.word_band)
        self._enlarged: str | None = None
        self._columns = 0  # the columns the tiles are laid out in now
        self.set_streams(streams)
        self.focus_ring = FocusRing(self)

    @property
    def word(self) -> str:
        return self.word_band.word

    def set_streams(self, streams: list[str]) -> None:
        for tile in self.tiles.values():
            tile.setParent(None)
        self.tiles = {s: CameraTile(s, self._tile_area) for s in streams}
        for name, short in compact_names(streams).items():
            self.tiles[name].short_name = short
        for number, tile in enumerate(self.tiles.values(), start=1):
            tile.double_clicked.connect(self.toggle_enlarged)
            tile.shape_changed.connect(self._fit_columns)
            tile.key = str(number) if number <= 9 else ""
        self._arrange()

    @property
    def columns(self) -> int:
        """How many columns the tiles shown are laid out in."""
        return self._columns

    def _visible(self) -> list[str]:
        return [self._enlarged] if self._enlarged else list(self.tiles)

    def _columns_for_area(self) -> int:
        count = len(self._visible())
        area = self._tile_area.size()
        if count <= 1 or not self.isVisible() or area.isEmpty():
            return square_columns(count)
        shapes = [t.image.width() / t.image.height() for t in self.tiles.values()
                  if t.image is not None and not t.image.isNull() and t.image.height()]
        aspect = sum(shapes) / len(shapes) if shapes else 4 / 3
        return best_columns(count, area.width(), area.height(), aspect)

    def _fit_columns(self) -> None:
        """Lay the tiles out again if other columns now show them larger."""
        if self._columns_for_area() != self._columns:
            self._arrange()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._fit_columns()

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self._fit_columns()

    def _arrange(self) -> None:
        visible = self._visible()
        square = square_columns(len(visible))
        cols = self._columns_for_area()
        self._columns = cols
        for tile in self.tiles.values():
            self._layout.removeWidget(tile)
            tile.hide()
        least = least_tile_width(cols)
        floor = least_tile_width(square)  # the near-square grid's least size
        rows = max(1, math.ceil(len(visible) / square))
        self._tile_area.setMinimumSize(
            square * floor + (square - 1) * TILE_SPACING_PX,
            rows * (floor * 3 // 4) + (rows - 1) * TILE_SPACING_PX)
        for n, name in enumerate(visible):
            self.tiles[name].setMinimumSize(least, least * 3 // 4)
            self._layout.addWidget(self.tiles[name], n // cols, n % cols)
            self.tiles[name].show()
        for name, tile in self.tiles.items():
            tile.footnote = enlarged_note(len(self.tiles)) if name == self._enlarged else ""
            tile.update()

    def toggle_enlarged(self, stream: str | None = None) -> None:
        """Show one camera alone (double-click); again or Escape returns to the grid."""
        self._enlarged = None if self._enlarged or stream is None else stream
        self._arrange()

    def toggle_camera(self, number: int) -> bool:
        """Show camera ``number`` (1-based, in grid order) alone, or back to the grid if it
        is shown alone already (keys 1-9); another camera alone gives way to it. False:
        there is no such camera."""
        names = list(self.tiles)
        if not 1 <= number <= len(names):
            return False
        stream = names[number - 1]
        self._enlarged = None if self._enlarged == stream else stream
        self._arrange()
        return True

    def step_camera(self, step: int) -> str:
        """PgDown / PgUp: the next (``step`` 1) or previous (-1) camera alone, round the
        grid's order; from the grid, the first (or last). The camera shown alone."""
        names = list(self.tiles)
        if not names:
            return ""
        if self._enlarged in names:
            at = (names.index(self._enlarged) + step) % len(names)
        else:
            at = 0 if step > 0 else len(names) - 1
        self._enlarged = names[at]
        self._arrange()
        return self._enlarged

    def set_word(self, word: str, state: str | None, source: str = "",
                 decides: int | None = None) -> None:
        """Show the trigger word of the set under the playhead (none: a hint to go to
        one, naming the set the keys act on, ``decides``); ``source``: the trigger's
        (``"manual"``: added by hand, no word heard)."""
        band = self.word_band
        band.word, band.state, band.source, band.decides = word, state, source, decides
        band.update()

    def set_drag_note(self, text: str) -> None:
        """Say ``text`` in the band instead of the word while the clap handle is dragged
        (how far the audio would move); "" gives the word back."""
        if text != self.word_band.drag_note:
            self.word_band.drag_note = text
            self.word_band.update()


class WordBand(QWidget):
    """A band under the tiles that writes the heard word in large letters, with the
    set's decision as symbol and colour."""

    HEIGHT = 40
    #: the least room at either end of the text, and its least letter size, pixels
    PAD_PX, LEAST_PX = 6, 12

    def __init__(self, parent: QWidget) -> None:
        super().__init__(parent)
        self.word = ""
        self.state: str | None = None
        self.source = ""
        self.decides: int | None = None
        #: said instead of the word while the clap handle is dragged ("" otherwise)
        self.drag_note = ""
        self.setFixedHeight(self.HEIGHT)
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)

    def fitted(self, font: QFont, text: str) -> tuple[QFont, str]:
        """``font`` and ``text`` as drawn across the band: smaller letters (down to
        LEAST_PX), then an ending "…", where the band is too narrow; a narrow grid cut
        "? CAPTURE · added by hand" at both ends, its decision symbol with it."""
        room = self.width() - 2 * self.PAD_PX
        wide = QFontMetrics(font).horizontalAdvance(text)
        if wide <= room or room <= 0:
            return font, text
        font = QFont(font)
        font.setPixelSize(max(self.LEAST_PX, int(font.pixelSize() * room / wide)))
        return font, QFontMetrics(font).elidedText(text, Qt.TextElideMode.ElideRight, room)

    def text(self) -> str:
        """What the band says now."""
        return self.drag_note or band_text(self.word, self.state, self.source, self.decides)

    def paintEvent(self, event: QPaintEvent) -> None:
        p = QPainter(self)
        p.fillRect(self.rect(), BACKGROUND)
        font = QFont(self.font())
        if self.drag_note:  # in the clap handle's colour, the word's size
            font.setPixelSize(self.HEIGHT - 16)
            font.setBold(True)
            colour = CLAP_LABEL_COLOUR
        elif self.word:
            font.setPixelSize(self.HEIGHT - 10)
            font.setBold(True)
            colour = DECISION_COLOURS.get(self.state or "", QColor(255, 255, 255)).lighter(130)
        else:
            font.setPixelSize(14)
            colour = QColor(150, 150, 150)
        font, text = self.fitted(font, self.text())
        p.setFont(font)
        p.setPen(colour)
        p.drawText(QRectF(self.rect()), Qt.AlignmentFlag.AlignCenter, text)
        p.end()


def enlarged_note(cameras: int) -> str:
    """What an enlarged camera's tile says at its foot: that others are hidden, and how
    to see them again."""
    return (f"{counted(cameras - 1, 'other camera')} hidden · Esc or double-click: "
            "all cameras")


def band_text(word: str, state: str | None, source: str = "",
              decides: int | None = None) -> str:
    """What the word band says: the heard word in quotes with the decision's symbol; a
    set added by hand without quotes (nothing was heard there); between sets, which set
    A / R / Del still act on (``decides``, the current set's id) and how to go to one."""
    if not word:
        if decides is None:  # no set at all
            return "no frame sets · T adds one at the playhead"
        return f"between frame sets · A / R / Del act on set #{decides} · J / K go to one"
    text = f"{word.upper()} · added by hand" if source == "manual" else f"“{word.upper()}”"
    return f"{DECISION_SYMBOLS[state]} {text}" if state else text
