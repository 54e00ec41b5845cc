"""Audio waveform on the session clock, with clap handle (and later claps), trigger markers and
playhead."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import QLabel, QToolButton

from app.focus_ring import FOCUS_RING_PX, FocusRing
from app.style import BACKGROUND, CLAP_COLOUR, CLAP_LABEL_COLOUR, PLAYHEAD_COLOUR
from app.word_marks import Mark, WordMarks

if TYPE_CHECKING:
    from collections.abc import Sequence

    from pyqtgraph.GraphicsScene.mouseEvents import MouseClickEvent
    from PySide6.QtGui import QResizeEvent
    from PySide6.QtWidgets import QWidget

    from speechcal_core.audio import EnvelopePyramid
    from speechcal_core.session.model import FrameSet
    from speechcal_core.sync.model import SyncModel


#: the whole view's margin beyond the frames and marks, a fraction of its width
PADDING = 0.01
#: when a mark leaves the whole view it widens by this fraction more (small edits after
#: it move nothing)
WIDEN_MARGIN = 0.05
#: the narrowest view the wheel zooms in to, seconds (a few ms of samples on each side of
#: a clap, enough to place it to the millisecond)
MIN_SPAN_S = 0.02
#: an offset edit moves the envelope as drawn; it is drawn anew this long after the last
REDRAW_AFTER_SHIFT_MS = 150
#: the handle's label: the first clap, or the audio's start where no clap was found
CLAP_HANDLE = "◂ clap ▸"
AUDIO_START_HANDLE = "◂ audio start ▸"
#: the "whole session" and playhead buttons' distance from the view's bottom edge, pixels
#: (clear of the focus frame: it crossed their lower edge)
BUTTON_MARGIN_PX = FOCUS_RING_PX


class WaveformView(pg.PlotWidget):
    """Min/max envelope from a pyramid, redrawn for the visible range at screen resolution.

    The x axis is session time in seconds from ``origin_ns`` (the first camera frame).
    The *whole* view (:meth:`show_all`) holds the frames and every clap and trigger mark;
    when an offset edit moves a mark out of it, it widens, and so does the view unless
    the operator has zoomed in (a wheel's zoom out reaches the mark). Zoom and pan stay
    within the whole view, down to :data:`MIN_SPAN_S`; a double-click on the waveform or
    the "whole session" button (shown while zoomed in) goes back to it.
    """

    # nanoseconds are Python ints carried as objects: Signal(int) is a 32-bit C int, which
    # wraps session times (~1.7e18 ns) and clap shifts beyond 2.1 s
    playhead_moved = Signal(object)  # session ns
    word_clicked = Signal(int, object)  # a set's id and the session ns clicked on its mark
    clap_moved = Signal(object)  # how far the clap handle was dragged, ns (on release)
    clap_dragging = Signal(object)  # the same while the handle is being dragged
    #: the audio file could not be read again (moved?): what to tell the operator, once
    audio_unreadable = Signal(str)

    def __init__(self, origin_ns: int, parent: QWidget | None = None) -> None:
        super().__init__(parent, background=BACKGROUND)
        self.origin_ns = origin_ns
        self.pyramid: EnvelopePyramid | None = None
        self._told_unreadable = False
        self.sync: SyncModel | None = None
        self._claps_audio_s: tuple[float, ...] = ()  # audio seconds; the first is the handle
        self._frames_x: tuple[float, float] | None = None  # first and last frame
        self._sets_x: tuple[float, float] | None = None  # the trigger marks' extent
        self.whole: tuple[float, float] | None = None  # the whole view (x), once shown
        #: the whole view as the session opened (show_all): marks back inside it (an
        #: offset edit undone) give it back
        self._opened_whole: tuple[float, float] | None = None
        self.setMouseEnabled(x=True, y=False)
        self.setMenuEnabled(False)
        self.hideButtons()
        self.getPlotItem().hideAxis("left")
        self.setLabel("bottom", "session time", units="s")
        self.showGrid(x=True, y=False, alpha=0.15)
        self._upper = pg.PlotDataItem(pen=pg.mkPen((110, 180, 255), width=1))
        self._lower = pg.PlotDataItem(pen=pg.mkPen((110, 180, 255), width=1))
        self._fill = pg.FillBetweenItem(self._lower, self._upper, brush=(110, 180, 255, 120))
        for item in (self._upper, self._lower, self._fill):
            self.addItem(item)
        self.setYRange(-1, 1, padding=0.05)
        #: every set's word mark (extent and label)
        self.marks = WordMarks(self)
        # hovered, a bolder line of its own colour (pyqtgraph's red is "rejected" here)
        self.playhead = pg.InfiniteLine(0, movable=True,
                                        pen=pg.mkPen(PLAYHEAD_COLOUR, width=2),
                                        hoverPen=pg.mkPen(PLAYHEAD_COLOUR, width=4))
        self.playhead.setZValue(20)
        self.playhead.sigDragged.connect(
            lambda line: self.playhead_moved.emit(self._to_ns(line.value())))
        self.addItem(self.playhead)
        # a handle: the label's arrows, a sideways cursor and a bolder line on hover say
        # it can be dragged; its label low, under the sets' labels along the top
        self.clap = pg.InfiniteLine(0, movable=True, pen=pg.mkPen(CLAP_COLOUR, width=2),
                                    hoverPen=pg.mkPen(CLAP_LABEL_COLOUR, width=4),
                                    label=CLAP_HANDLE, labelOpts={"position": 0.12,
                                                                 "color": CLAP_LABEL_COLOUR})
        self.clap.setCursor(Qt.CursorShape.SizeHorCursor)
        self.clap.setToolTip("the clap: drag it to set the audio offset")
        # above the playhead: a click on the clap puts the playhead on it, and the drag
        # from there must still take the handle (the playhead is dragged anywhere else)
        self.clap.setZValue(25)
        self.clap.sigPositionChangeFinished.connect(lambda _line: self._clap_released())
        self.clap.sigDragged.connect(lambda _line: self._clap_dragged())
        self.clap.hide()
        self.addItem(self.clap)
        #: later claps (the drift's), marked where the sync puts them; not handles
        self.later_claps: list[pg.InfiniteLine] = []
        #: back to the whole view; shown while the view is narrower than that
        self.whole_button = QToolButton(self)
        self.whole_button.setText("whole session")
        self.whole_button.setStyleSheet(
            "QToolButton { background: rgba(60, 64, 72, 220); color: rgb(225, 225, 225);"
            " border: 1px solid rgb(110, 116, 126); border-radius: 3px; padding: 1px 6px; }"
            "QToolButton:hover { background: rgb(80, 86, 96); }")
        self.whole_button.setToolTip("show the whole session (or double-click the waveform)")
        self.whole_button.setCursor(Qt.CursorShape.ArrowCursor)
        self.whole_button.clicked.connect(self.show_whole)
        self.whole_button.hide()
        #: where the playhead is when the view has scrolled away from it: a click goes there
        self.playhead_button = QToolButton(self)
        self.playhead_button.setStyleSheet(self.whole_button.styleSheet())
        self.playhead_button.setToolTip("the playhead is out of view: show it")
        self.playhead_button.setCursor(Qt.CursorShape.ArrowCursor)
        self.playhead_button.clicked.connect(self.show_playhead)
        self.playhead_button.hide()
        #: why no envelope shows (no audio, or it could not be read); hidden otherwise
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.message.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.message.setStyleSheet("QLabel { color: rgb(235, 190, 110); background: rgba(40,"
                                   " 42, 48, 200); padding: 4px 10px; border-radius: 3px; }")
        self.message.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.message.hide()
        self.getViewBox().sigXRangeChanged.connect(lambda *_: self._range_changed())
        # the envelope has a column per pixel: drawn before the layout settles (600 px of
        # a 1400 px view) it looked blocky until the next zoom
        self._drawn_width = 0
        self.getViewBox().sigResized.connect(lambda *_: self._resized())
        self._drawn_sync: SyncModel | None = None  # the sync the envelope was drawn with
        self._hold_drawing = False  # while show_all first sets the view's limits
        self._redraw_timer = QTimer(self)  # the redraw after a run of offset edits
        self._redraw_timer.setSingleShot(True)
        self._redraw_timer.setInterval(REDRAW_AFTER_SHIFT_MS)
        self._redraw_timer.timeout.connect(self.redraw)
        self.scene().sigMouseClicked.connect(self._clicked)
        #: shown while the waveform has the keyboard focus (Tab from the grid)
        self.focus_ring = FocusRing(self)

    def _to_ns(self, x: float) -> int:
        return self.origin_ns + round(x * 1e9)

    def _to_x(self, t_ns: int) -> float:
        return (t_ns - self.origin_ns) / 1e9

    def set_audio(self, pyramid: EnvelopePyramid, sync: SyncModel) -> None:
        """Show this audio on the session clock given by ``sync``."""
        self.pyramid, self.sync = pyramid, sync
        self._told_unreadable = False
        self.show_message("")
        peak = max(1e-6, float(np.max(np.abs(pyramid.levels[-1][1:]))) if pyramid.levels else 1)
        self._scale = 1.0 / peak
        self._limit_to_whole()
        self.redraw()

    def show_message(self, text: str) -> None:
        """Say over the waveform why it is empty ("" hides the message)."""
        self.message.setText(text)
        self.message.setVisible(bool(text))
        self._place_message()

    def _place_message(self) -> None:
        if self.message.isHidden():  # (isVisible is False too while the window opens)
            return
        width = min(self.width() - 24, max(300, self.message.sizeHint().width()))
        height = self.message.heightForWidth(width)
        self.message.setGeometry((self.width() - width) // 2,
                                 max(4, (self.height() - height) // 2), width, height)

    def set_sync(self, sync: SyncModel, claps_audio_s: Sequence[float] | None = None) -> None:
        """Show the audio on the clock of ``sync``, with the claps ``claps_audio_s`` (None:
        the ones shown). An offset edit (same drift) moves the envelope drawn as it is
        and redraws it once the edits pause: recomputing it cost 20 ms of each step of a
        held ``]``."""
        drawn = self._drawn_sync
        self.sync = sync
        self.set_claps(self._claps_audio_s if claps_audio_s is None else claps_audio_s)
        self._limit_to_whole()  # the audio moved
        if drawn is None or sync.drift != drawn.drift:
            self.redraw()
            return
        self._place_envelope(0.0)
        self._redraw_timer.start()

    def _place_envelope(self, extra_s: float) -> None:
        """Put the envelope as drawn where the current sync (same drift) places it, moved
        ``extra_s`` further (a clap drag's preview)."""
        drawn = self._drawn_sync
        assert self.sync is not None
        shift = (self.sync.offset_ns - drawn.offset_ns) / 1e9 if drawn is not None else 0.0
        for item in (self._upper, self._lower, self._fill):
            item.setPos(shift + extra_s, 0.0)

    def set_claps(self, claps_audio_s: Sequence[float]) -> None:
        """Mark where the audio claps land on the session clock: the first as a handle to
        drag (it sets the offset), later ones (the drift's) as plain marks. Without a clap
        the audio's start is the handle (a session opened without one, or timed by stamps
        or a given offset), where there is audio."""
        self._claps_audio_s = tuple(claps_audio_s)
        for line in self.later_claps:
            self.removeItem(line)
        self.later_claps = []
        handle = self._handle_audio_s()
        if self.sync is None or handle is None:
            self.clap.hide()
            self._keep_marks_within_whole()
            return
        self.clap.show()  # first: a hidden line's label takes no new text
        self.clap.label.setFormat(self.handle_label())
        self.clap.setToolTip(f"the {'clap' if self._claps_audio_s else 'start of the audio'}"
                             ": drag it to set the audio offset")
        self.clap.setValue(self._to_x(int(self.sync.to_session(handle))))
        later = self._clap_xs()[1:]
        for n, x in enumerate(later, start=2):
            line = pg.InfiniteLine(x, movable=False,
                                   pen=pg.mkPen(CLAP_COLOUR, width=1,
                                                style=Qt.PenStyle.DashLine),
                                   label=f"clap {n}", labelOpts={"position": 0.12,
                                                                 "color": CLAP_LABEL_COLOUR})
            line.setZValue(15)
            self.addItem(line)
            self.later_claps.append(line)
        self._keep_marks_within_whole()

    def _clap_xs(self) -> list[float]:
        """Where the current sync puts the audio's claps (x, seconds)."""
        assert self.sync is not None
        return [self._to_x(int(self.sync.to_session(a))) for a in self._claps_audio_s]

    def _handle_audio_s(self) -> float | None:
        """The audio time the handle marks: the first clap's, else the audio's start
        where there is audio (None: no handle)."""
        if self._claps_audio_s:
            return self._claps_audio_s[0]
        return 0.0 if self.pyramid is not None and self.pyramid.size else None

    def handle_name(self) -> str:
        """What the handle is, as the status line says it was dragged."""
        return "clap handle" if self._claps_audio_s else "audio start"

    def handle_label(self) -> str:
        """The handle's label: the first clap's, or the audio's start without a clap."""
        return CLAP_HANDLE if self._claps_audio_s else AUDIO_START_HANDLE

    def clap_shift_ns(self) -> int:
        """How far the clap handle was dragged from where the current sync puts it."""
        handle = self._handle_audio_s()
        if handle is None or self.sync is None:
            return 0
        return self._to_ns(self.clap.value()) - int(self.sync.to_session(handle))

    def _clap_dragged(self) -> None:
        """The audio slides with the handle: the envelope, the later claps and the word
        marks are drawn shifted as the new offset would place them (the offset itself
        changes on release)."""
        shift_ns = self.clap_shift_ns()
        self._show_shifted(shift_ns / 1e9)
        self.clap_dragging.emit(shift_ns)

    def _clap_released(self) -> None:
        shift_ns = self.clap_shift_ns()
        self._show_shifted(0.0)  # the offset edit (if any) places everything anew
        self.clap_moved.emit(shift_ns)

    def _show_shifted(self, shift_s: float) -> None:
        """Draw the audio's envelope, later claps and word marks ``shift_s`` later than
        the current sync puts them (0: where it puts them)."""
        if self.sync is None:
            return
        self._place_envelope(shift_s)
        for line, x in zip(self.later_claps, self._clap_xs()[1:], strict=False):
            line.setValue(x + shift_s)
        self.marks.set_shift(shift_s)

    def mark_extent(self, set_id: int) -> tuple[float, float]:
        """Where a set's word mark is drawn (x, seconds), a clap drag's shift included."""
        return self.marks.extent(set_id)

    def show_all(self, start_ns: int, end_ns: int) -> None:
        """Show the whole session: the frames from ``start_ns`` to ``end_ns`` and every
        clap and trigger mark (one an earlier offset edit put beyond them too)."""
        self._frames_x = (self._to_x(start_ns), self._to_x(end_ns))
        lo, hi = self.extent()
        pad = PADDING * (hi - lo)
        first = self.whole is None
        self.whole = self._opened_whole = (lo - pad, hi + pad)
        # the first time, the limits and pyqtgraph's auto-range move its first view on
        # the way to the whole (a few seconds wide: their samples read from the file):
        # drawn once, when it is there
        self._hold_drawing = first
        try:
            self._limit_to_whole()
            self.show_whole()
        finally:
            self._hold_drawing = False
        if first or self._drawn_sync is None:
            self.redraw()

    def show_whole(self) -> None:
        """Zoom out to the whole view (once :meth:`show_all` has set it)."""
        if self.whole is not None:
            self.setXRange(*self.whole, padding=0)

    def zoom_at_playhead(self, factor: float) -> None:
        """Show ``factor`` times the visible span (< 1 zooms in) around the playhead, within
        the whole view (the keys = and -)."""
        if self.whole is None:
            return
        v0, v1 = self.getViewBox().viewRange()[0]
        w0, w1 = self.whole
        span = min(w1 - w0, max(MIN_SPAN_S, (v1 - v0) * factor))
        x = min(max(self.playhead.value(), w0), w1)
        start = min(max(x - span / 2, w0), w1 - span)
        self.setXRange(start, start + span, padding=0)

    def bring_into_view(self, set_id: int) -> None:
        """Zoomed in, centre the view (its width kept) on a set's word mark that is not
        wholly in it: changing set (J/K, the list) takes the view along."""
        if not self.zoomed_in():
            return
        try:
            a, b = self.marks.extent(set_id)
        except KeyError:
            return
        x0, x1 = self.getViewBox().viewRange()[0]
        if x0 <= a and b <= x1:
            return
        half = (x1 - x0) / 2
        self.setXRange((a + b) / 2 - half, (a + b) / 2 + half, padding=0)

    def zoomed_in(self) -> bool:
        """Whether the view shows less than the whole (by more than a rounding error)."""
        if self.whole is None:
            return False
        v0, v1 = self.getViewBox().viewRange()[0]
        w0, w1 = self.whole
        tolerance = 1e-3 * (w1 - w0)
        return v0 > w0 + tolerance or v1 < w1 - tolerance

    def _limit_to_whole(self) -> None:
        """Keep zoom and pan within the whole view and the audio (a clap the wrong sound
        was taken for may put the real one before the first frame: the operator must see
        it to drag the handle onto it), and zooming in to MIN_SPAN_S."""
        if self.whole is None:
            return
        lo, hi = self.whole
        audio = self._audio_x()
        if audio is not None:
            lo, hi = min(lo, audio[0]), max(hi, audio[1])
        if hi - lo < MIN_SPAN_S:  # a session of one instant: room for the narrowest view
            mid = (lo + hi) / 2
            lo, hi = mid - MIN_SPAN_S / 2, mid + MIN_SPAN_S / 2
        self.getViewBox().setLimits(xMin=lo, xMax=hi, minXRange=MIN_SPAN_S,
                                    maxXRange=hi - lo)

    def _audio_x(self) -> tuple[float, float] | None:
        """Where the current sync puts the audio's first and last sample (x, seconds)."""
        if self.pyramid is None or self.sync is None or self.pyramid.size == 0:
            return None
        end_s = self.pyramid.size / self.pyramid.rate
        return (self._to_x(int(self.sync.to_session(0.0))),
                self._to_x(int(self.sync.to_session(end_s))))

    def extent(self) -> tuple[float, float]:
        """The x range from the first to the last of the frames and marks (claps, words)."""
        xs = [*(self._frames_x or ()), *(self._sets_x or ()),
              *(line.value() for line in self.later_claps)]
        if self.sync is not None and self._handle_audio_s() is not None:
            xs.append(self.clap.value())
        return (min(xs), max(xs)) if xs else (0.0, 0.0)

    def _keep_marks_within_whole(self) -> None:
        """A mark moved out of the whole view: widen it (with a margin, so further small
        edits move nothing), and the view with it unless the operator zoomed in. Every
        mark back inside the whole view the session opened with (a large edit undone):
        that view again, not the widened one."""
        if self.whole is None:
            return  # not shown yet: show_all takes every mark in
        lo, hi = self.extent()
        w0, w1 = self.whole
        opened = self._opened_whole
        if opened is not None and opened[0] <= lo and hi <= opened[1]:
            whole = opened
        elif w0 <= lo and hi <= w1:
            return
        else:
            margin = WIDEN_MARGIN * (max(hi, w1) - min(lo, w0))
            whole = (lo - margin if lo < w0 else w0, hi + margin if hi > w1 else w1)
        if whole == self.whole:
            return
        showed_whole = not self.zoomed_in()
        self.whole = whole
        self._limit_to_whole()  # the limits follow, so the wheel zooms out to the mark
        if showed_whole:
            self.show_whole()

    def _resized(self) -> None:
        """Draw again when the view is a tenth wider or narrower than the drawing."""
        width = int(self.getViewBox().width())
        if abs(width - self._drawn_width) > 0.1 * max(self._drawn_width, 1):
            self.redraw()

    def _range_changed(self) -> None:
        self.whole_button.setVisible(self.zoomed_in())
        self._place_playhead_button()
        self.redraw()

    def _place_playhead_button(self) -> None:
        """Show, at the side the playhead lies beyond, a button that goes to it."""
        button = getattr(self, "playhead_button", None)  # pyqtgraph resizes in __init__
        if button is None:
            return
        x0, x1 = self.getViewBox().viewRange()[0]
        side = playhead_side(self.playhead.value(), x0, x1)
        button.setVisible(side != 0)
        if side == 0:
            return
        button.setText("◀ playhead" if side < 0 else "playhead ▶")
        hint = button.sizeHint()
        right = self.width() - 6 - (self.whole_button.sizeHint().width() + 6
                                    if self.whole_button.isVisible() else 0)
        left = 6 if side < 0 else right - hint.width()
        button.setGeometry(left, self._buttons_top(hint.height()), hint.width(), hint.height())

    def _buttons_top(self, height: int) -> int:
        """Where the view's buttons stand (y): in the bottom corners, beside the axis's
        name, under the tick numbers; at the top they covered the sets' labels."""
        return self.height() - height - BUTTON_MARGIN_PX

    def show_playhead(self) -> None:
        """Scroll the view (its width kept) so the playhead stands in its middle."""
        x0, x1 = self.getViewBox().viewRange()[0]
        x, half = self.playhead.value(), (x1 - x0) / 2
        self.setXRange(x - half, x + half, padding=0)

    def resizeEvent(self, event: QResizeEvent) -> None:
        """Keep the "whole session" button in the bottom right corner."""
        super().resizeEvent(event)
        self._place_playhead_button()
        if getattr(self, "message", None) is not None:  # pyqtgraph resizes in __init__
            self._place_message()
        button = getattr(self, "whole_button", None)  # pyqtgraph resizes in __init__
        if button is not None:
            hint = button.sizeHint()
            button.setGeometry(self.width() - hint.width() - 6, self._buttons_top(hint.height()),
                               hint.width(), hint.height())

    def redraw(self) -> None:
        """Draw the envelope of the audio in the visible range (once :meth:`show_all` has
        shown the session: pyqtgraph's first view, a second wide, read that second's
        samples from the audio file on the UI thread while the session opened)."""
        if self.pyramid is None or self.sync is None or self.whole is None \
                or self._hold_drawing:
            return
        self._redraw_timer.stop()
        self._drawn_sync = self.sync
        for item in (self._upper, self._lower, self._fill):
            item.setPos(0.0, 0.0)
        x0, x1 = self.getViewBox().viewRange()[0]
        a0 = float(self.sync.to_audio(self._to_ns(x0)))
        a1 = float(self.sync.to_audio(self._to_ns(x1)))
        width = max(100, int(self.getViewBox().width()))
        self._drawn_width = width
        t, mn, mx = self.pyramid.envelope(max(a0, 0.0), max(a1, 0.0), width)
        if self.pyramid.unreadable and not self._told_unreadable:
            self._told_unreadable = True
            self.audio_unreadable.emit(unreadable_message(self.pyramid))
        if t.size == 0:
            self._upper.setData([], [])
            self._lower.setData([], [])
            return
        xs = (np.asarray(self.sync.to_session(t), dtype=np.int64) - self.origin_ns) / 1e9
        scale = self._scale
        if self.zoomed_in():  # the loudest sound in view fills the height (a clap
            # elsewhere left speech a flat line); quiet stretches are not blown up to it
            shown = float(max(np.max(mx), -np.min(mn), 0.0))
            scale = 1.0 / max(shown, ZOOM_GAIN_FLOOR / self._scale)
        self.drawn_scale = scale  # envelope height per unit of sample value, as drawn
        self._upper.setData(xs, mx * scale)
        self._lower.setData(xs, mn * scale)

    def set_sets(self, sets: list[FrameSet]) -> None:
        """One mark per frame set: the word's extent, coloured, labelled decision + set
        id, where the sync now places it (an offset edit moves them all)."""
        if self.sync is None:
            sets = []
        words_s = np.array([(s.trigger.start_s, s.trigger.end_s) for s in sets],
                           dtype=np.float64).reshape(-1, 2)
        xs = (self.sync.to_session(words_s) - self.origin_ns) / 1e9 if sets else words_s
        self.marks.set_marks([Mark(s.id, float(a), float(b), s.decision)
                              for s, (a, b) in zip(sets, xs, strict=True)])
        self._sets_x = self.marks.x_range()
        self._keep_marks_within_whole()

    def update_set(self, frame_set: FrameSet) -> None:
        """Show a set's new decision on its mark."""
        self.marks.set_decision(frame_set.id, frame_set.decision)

    def set_playhead(self, t_ns: int, keep_in_view: bool = False) -> None:
        """Put the playhead at ``t_ns``; ``keep_in_view``: a playhead in view that this
        moves out of it takes the view along, at the same place on screen (an offset edit
        moved it with its sound)."""
        x = self._to_x(t_ns)
        if keep_in_view:
            x0, x1 = self.getViewBox().viewRange()[0]
            was = self.playhead.value()
            if playhead_side(was, x0, x1) == 0 and playhead_side(x, x0, x1) != 0:
                self.setXRange(x0 + x - was, x1 + x - was, padding=0)
        self.playhead.setValue(x)
        self._place_playhead_button()

    def follow(self, t_ns: int) -> None:
        """Scroll so the playhead stays visible (during playback)."""
        x = self._to_x(t_ns)
        x0, x1 = self.getViewBox().viewRange()[0]
        if not x0 <= x <= x1:
            span = x1 - x0
            self.setXRange(x - span * 0.1, x + span * 0.9, padding=0)

    def _clicked(self, event: MouseClickEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton:
            return
        if event.double():  # its first click moved the playhead already
            self.show_whole()
            return
        pos = self.getViewBox().mapSceneToView(event.scenePos())
        set_id = self.mark_at(pos.x())
        if set_id is not None:
            self.word_clicked.emit(set_id, self._to_ns(pos.x()))
        else:
            self.playhead_moved.emit(self._to_ns(pos.x()))

    def mark_at(self, x: float) -> int | None:
        """The id of the set whose word mark covers ``x`` (the one whose middle is
        nearest, where marks overlap); None off every mark."""
        return self.marks.at(x)


#: zoomed in, the envelope is scaled to the loudest sound in view, but never more than
#: 1 / this times the whole session's scale (a room's quiet stays quiet)
ZOOM_GAIN_FLOOR = 0.05


def playhead_side(x: float, x0: float, x1: float) -> int:
    """Where the playhead at ``x`` lies against the view ``x0``..``x1``: -1 before it, 1
    after it, 0 in it."""
    return -1 if x < x0 else 1 if x > x1 else 0


def unreadable_message(pyramid: EnvelopePyramid) -> str:
    """What the status line says when the waveform's audio file can no longer be read."""
    path = getattr(pyramid.source, "path", None)
    name = f"the audio file {path}" if path is not None else "the audio file"
    return (f"waveform shows coarse levels only: {name} could not be read again "
            "(moved or changed?); put it back there and reopen the session for the "
            "detailed waveform")
