"""The review window: camera grid, frame-set list, waveform, offset controls, status line."""

from __future__ import annotations

import html
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import Qt, QTimer
from PySide6.QtGui import QAction, QIcon, QKeySequence, QShortcut
from PySide6.QtWidgets import (
    QAbstractButton,
    QApplication,
    QButtonGroup,
    QCheckBox,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QMainWindow,
    QMessageBox,
    QProgressBar,
    QPushButton,
    QSplitter,
    QStackedWidget,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.checks_action import ChecksAction
from app.detect_action import DetectAction
from app.elided_label import ElidedLabel, EllipsisLabel
from app.export_action import ExportAction
from app.frame_grid import DROPPED_CAPTION, NEAREST_CAPTION, FrameGrid
from app.frame_loader import FrameLoader
from app.leave_out_action import LeaveOutAction
from app.offset_text import NO_CAMERA_CLAP, clap_drag_text, clap_moved_text, offset_moved_text
from app.open_request import OpenRequest, drop_request
from app.rescore_action import RescoreAction
from app.session_saver import SessionSaver, free_name_beside
from app.set_table import MISSING, SetTable, clock_text
from app.similar_action import SimilarAction
from app.status_line import StatusLine
from app.style import DECISION_SYMBOLS, WARNING_SYMBOL, WARNING_TEXT_COLOUR, hint_text_colour
from app.sync_line import sync_line_forms
from app.tasks import BackgroundTask, start
from app.transport import NO_SET_TO_HEAR, Transport
from app.waveform import WaveformView
from speechcal_core.audio.topic_file import TOPIC_KEY
from speechcal_core.errors import SpeechCalError
from speechcal_core.resources import resource
from speechcal_core.review.checks import check_summary
from speechcal_core.review.loading import ReviewInputs, load_for_review
from speechcal_core.review.model import KEY_BINDINGS, ReviewModel
from speechcal_core.review.relocate import (
    MovedRecording,
    moved_recording,
    relocated_audio,
    relocated_inputs,
)
from speechcal_core.review.summary import (
    FILTERS,
    FIND_WORDS,
    FIND_WORDS_KEY,
    flag_short_words,
    flag_words,
    list_place,
    no_sets_hint,
)
from speechcal_core.session.store import SessionChangedError, SessionFileError
from speechcal_core.sync.errors import SyncError
from speechcal_core.text import counted, shown_name, unbroken_figures

if TYPE_CHECKING:
    from PySide6.QtGui import QCloseEvent, QDragEnterEvent, QDropEvent, QImage

    from speechcal_core.review.loading import Progress
    from speechcal_core.session.model import Session
    from speechcal_core.sources.selection import StreamChoice
    from speechcal_core.speech.matching import TriggerSpec
    from speechcal_core.sync.model import SyncModel
    from speechcal_core.target import TargetSpec

EMPTY_TEXT = (
    "<h2>Open a calibration session</h2>"
    "<p>Drag a recording (ROS bag, bag folder, .mcap, .db3, video files, or folders of<br>"
    "&lt;stamp_ns&gt;.png images per camera) and its audio file here,<br>"
    "or open a session file (SESSION.json).</p>"
)


def opening_text(stage: str, fraction: float) -> str:
    """The first page while a session opens or a recording is processed: the stage
    ("finding the trigger words") and how far it is."""
    done = f" ({fraction:.0%})" if 0.0 < fraction < 1.0 else ""
    return (f"<h2>Opening…</h2><p>{html.escape(stage)}{done}</p>"
            "<p>A recording opened for the first time is processed first (sync, trigger "
            "words, best still frames):<br>a minute or two for a few minutes of recording. "
            "The status line below has Cancel.</p>")


#: the keys that go to another set (J, K, Home, End): when they go nowhere the status
#: line says why
STEP_ACTIONS = ("next_set", "previous_set", "first_set", "last_set")
#: the keys and buttons that move the audio, with what the status line calls the step
OFFSET_ACTIONS = {"offset_minus_ms": "", "offset_plus_ms": "",
                  "offset_minus_frame": "one frame", "offset_plus_frame": "one frame"}
APP_ICON = "speechcal.svg"  # in resources/icons; the desktop entry names it too
#: the Edit menu's keys (a QShortcut on them stands in only while the entry is off: both on
#: would be ambiguous)
UNDO_KEYS, REDO_KEYS = ("Ctrl+Z",), ("Ctrl+Shift+Z", "Ctrl+Y")
#: the waveform is never squeezed below this (pixels): at the window's least height it
#: was 30 px high, its labels cut off
WAVEFORM_MIN_HEIGHT = 100
#: the window's first size (the README's screenshot is taken at it)
WINDOW_SIZE = (1400, 900)
#: what a screen too small for WINDOW_SIZE keeps free around the window for its frame and
#: title bar, pixels (a 1366 x 768 laptop showed the window's bottom 130 px off screen)
SCREEN_MARGIN_PX = (16, 48)
#: the key hints under the waveform: one line at 1400 px (the tooltip says it in full,
#: e.g. Esc back from an enlarged camera, which double-clicking it again does too)
HINTS = ("Space play · W hear word · ←/→ frame · J/K set · F filter · A/R/U decide · "
         "T add · Del remove · S like this · [ ] { } audio ±1 ms/frame · "
         "double-click a camera: enlarge · waveform: wheel zoom, click seek, "
         "double-click: whole session")
HINTS_TIP = (
    "Space play / pause · W hear the trigger word · ←/→ previous / next frame "
    "(Shift: of every camera) · "
    "J/K previous / next set · F next filter · A/R/U accept / reject / undo\n"
    "T add a set at the playhead · Del remove the set · S find more like this\n"
    "[ ] audio ±1 ms, { } audio ±1 frame, or drag the clap handle on the waveform; C: "
    "the clap is the sound at the playhead (another sound was taken for it)\n"
    "double-click a camera (or press its number 1-9; PgDown / PgUp: the next / previous "
    "camera) to show it alone, Esc back to the grid\n"
    "waveform: the wheel (or = and -) zooms, a drag pans, a click moves the playhead (a "
    "click on a set's word goes to that set), a double-click (or the 'whole session' "
    "button) shows the whole session\n"
    "Ctrl+F find trigger words: other words or another sensitivity")


class ReviewWindow(QMainWindow):
    """Main window; all state lives in a :class:`ReviewModel`, the widgets only show it."""

    def __init__(self) -> None:
        super().__init__()
        self.setWindowTitle("SpeechCal")
        self.setWindowIcon(QIcon(str(resource("icons", APP_ICON))))  # dialogs take it too
        self.resize(*WINDOW_SIZE)
        self.model: ReviewModel | None = None
        self.inputs: ReviewInputs | None = None
        self.loader: FrameLoader | None = None
        self.task: BackgroundTask | None = None
        self.saver = SessionSaver(self)
        self.saver.saved.connect(self._on_saved)
        self._save_warned = False  # the status line warns that the last save failed
        #: asks what to do with decisions not saved: "save_as", "discard" or "cancel"
        #: (a dialog; tests put a function here)
        self.ask_unsaved: Callable[[str], str] = self._ask_unsaved
        #: asks where a session's recording went (a file dialog; tests put a function
        #: here): one of its files or folders, or None
        self.ask_recording_place: Callable[[MovedRecording], str | None] = \
            self._ask_recording_place
        #: asks where the session's audio file (its path given) went: a file, or None
        self.ask_audio_place: Callable[[str], str | None] = self._ask_audio_place
        #: the ``open`` arguments of the opening under way (None: the demo's), and of a
        #: recording whose clap was not found (see open_without_clap)
        self._opening: OpenRequest | None = None
        self._failed_recording: OpenRequest | None = None
        self._moved: MovedRecording | None = None  # its recording, gone from where it was
        self.load_error = ""
        #: the "then next set" box: accept and reject go on to the next set
        self.advance_after_decision = True
        self._opened_note = ""  # what the status line said when the session opened
        self._step_refused = ""  # why J / K / Home / End last went nowhere, as said
        #: called with what the status line says when a session opens (the command line
        #: prints it in full: the status line cuts a long note short)
        self.on_opened: Callable[[str], None] | None = None
        self._pending_tiles: set[str] = set()
        #: how far the clap handle is being dragged (None: it is not)
        self._clap_drag_ns: int | None = None
        self.undo_button: QPushButton | None = None  # on the review page, once built
        #: previously opened sessions, closed once no export, re-scoring or decode reads them
        self._retired: list[ReviewInputs] = []
        #: frame loaders of those sessions, until their last decode ends
        self._old_loaders: list[FrameLoader] = []

        self.stack = QStackedWidget()
        self.setCentralWidget(self.stack)
        self.stack.addWidget(self._build_empty_page())
        self.review_page = QWidget()
        self.stack.addWidget(self.review_page)
        self._build_status_line()
        self.exporter = ExportAction(self)
        self.rescorer = RescoreAction(self)
        self.checker = ChecksAction(self)
        self.similar = SimilarAction(self)
        self.detector = DetectAction(self)
        self.transport = Transport(self, say=lambda text: self.status.end("audio", text))
        # paused, a tile held dimmed over a dropped frame says there is no frame instead
        self.transport.state_changed.connect(lambda _playing: self._refresh_playhead())
        self._build_actions()
        self.setAcceptDrops(True)
        self._save_clock = QTimer(self)
        self._save_clock.timeout.connect(self._update_saved_label)
        self._save_clock.start(1000)

    def fit_to_screen(self) -> None:
        """Make the window no larger than the room its screen has (less a margin for its
        frame): WINDOW_SIZE was larger than a laptop screen's."""
        screen = self.screen()
        if screen is None:
            return
        room = screen.availableGeometry()
        self.resize(min(self.width(), room.width() - SCREEN_MARGIN_PX[0]),
                    min(self.height(), room.height() - SCREEN_MARGIN_PX[1]))

    # -- construction -------------------------------------------------------------------
    def _build_empty_page(self) -> QWidget:
        page = QWidget()
        layout = QVBoxLayout(page)
        layout.addStretch(1)
        #: what to open; while an opening runs, what it is doing
        self.empty_text = QLabel(EMPTY_TEXT)
        self.empty_text.setAlignment(Qt.AlignmentFlag.AlignCenter)
        layout.addWidget(self.empty_text)
        #: why the last opening failed, in full (the status line cuts it short)
        self.open_problem = QLabel("")
        self.open_problem.setWordWrap(True)
        self.open_problem.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.open_problem.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.open_problem.setStyleSheet(f"color: {WARNING_TEXT_COLOUR.name()};")
        self.open_problem.hide()
        layout.addWidget(self.open_problem)
        row = QHBoxLayout()
        row.addStretch(1)
        self.open_button = QPushButton("Open session…")
        self.open_button.clicked.connect(self.choose_session)
        row.addWidget(self.open_button)
        self.demo_button = QPushButton("Open the demo session")
        self.demo_button.clicked.connect(self.open_demo)
        row.addWidget(self.demo_button)
        #: shown when no clap was found in a recording opened last
        self.no_clap_button = QPushButton("Open without a clap (set the offset here)")
        self.no_clap_button.setToolTip("Process the recording with its audio taken to start "
                                       "with the first frame; then move the audio with { } "
                                       "and [ ] until the words fall where the board stops")
        self.no_clap_button.clicked.connect(lambda _=False: self.open_without_clap())
        self.no_clap_button.hide()
        row.addWidget(self.no_clap_button)
        #: shown when the session opened last has lost its recording
        self.locate_button = QPushButton("Locate recording…")
        self.locate_button.clicked.connect(lambda _=False: self.locate_recording())
        self.locate_button.hide()
        row.addWidget(self.locate_button)
        row.addStretch(1)
        layout.addLayout(row)
        layout.addStretch(2)
        return page

    def _build_status_line(self) -> None:
        bar = self.statusBar()
        # long job texts end in "…" (the tooltip has them whole), never widen the window
        self.status_text = EllipsisLabel()
        self.progress = QProgressBar()
        self.progress.setMaximumWidth(220)
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(False)  # the status text says what it is doing
        self.progress.hide()
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.hide()
        self.cancel_button.clicked.connect(self.cancel_task)
        self.saved_label = QLabel("")
        # room for "saved 59 min ago" whatever the status line says (it cut it to "s")
        self.saved_label.setMinimumWidth(
            self.saved_label.fontMetrics().horizontalAdvance("saved 59 min ago") + 4)
        bar.addWidget(self.status_text, 1)
        bar.addPermanentWidget(self.progress)
        bar.addPermanentWidget(self.cancel_button)
        bar.addPermanentWidget(self.saved_label)
        self.status = StatusLine(self.status_text, self.progress, self.cancel_button)

    def _build_actions(self) -> None:
        menu = self.menuBar().addMenu("&File")
        open_action = QAction("&Open session…", self)
        open_action.setShortcut(QKeySequence.StandardKey.Open)
        open_action.triggered.connect(self.choose_session)
        menu.addAction(open_action)
        self.export_action = QAction("&Export frame sets…", self)
        self.export_action.setShortcut(QKeySequence("Ctrl+E"))
        self.export_action.triggered.connect(self.exporter.choose)
        self.export_action.setEnabled(False)
        menu.addAction(self.export_action)
        self.save_as_action = QAction("Save session &as…", self)
        self.save_as_action.setShortcut(QKeySequence("Ctrl+Shift+S"))
        self.save_as_action.triggered.connect(self.choose_save_as)
        self.save_as_action.setEnabled(False)
        self.addAction(self.save_as_action)  # its shortcut works with the menu closed
        menu.addAction(self.save_as_action)
        self.locate_audio_action = QAction("&Locate audio…", self)
        self.locate_audio_action.setToolTip("the session's audio file moved: show where it "
                                            "is now (the session then reads it there)")
        self.locate_audio_action.triggered.connect(lambda _=False: self.locate_audio())
        self.locate_audio_action.setEnabled(False)
        menu.addAction(self.locate_audio_action)
        self.export_button = QPushButton("Export…")
        self.export_button.setToolTip("Write the accepted frame sets for Kalibr, per-camera "
                                      "folders or a bag  (Ctrl+E)")
        self.export_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.export_button.clicked.connect(self.exporter.choose)
        self.export_button.setEnabled(False)
        self.menuBar().setCornerWidget(self.export_button)
        quit_action = QAction("&Quit", self)
        quit_action.setShortcut(QKeySequence.StandardKey.Quit)
        quit_action.triggered.connect(self.close)
        menu.addAction(quit_action)
        self._build_edit_menu()
        for key, action in KEY_BINDINGS.items():
            if key in UNDO_KEYS + REDO_KEYS:
                continue  # the Edit menu's actions carry these
            shortcut = QShortcut(QKeySequence(key), self)
            shortcut.activated.connect(lambda a=action: self.run_action(a))
        QShortcut(QKeySequence("Space"), self).activated.connect(self._space)
        QShortcut(QKeySequence("W"), self).activated.connect(self.transport.hear_word)
        QShortcut(QKeySequence("Escape"), self).activated.connect(self._leave_enlarged)
        for number in range(1, 10):  # a camera alone, as a double-click on it
            QShortcut(QKeySequence(str(number)), self).activated.connect(
                lambda n=number: self.show_camera_alone(n))
        # every camera alone in turn: keys 1-9 reach no tenth (12 cameras had three a
        # keyboard could not enlarge)
        for key, step in (("PgDown", 1), ("PgUp", -1)):
            QShortcut(QKeySequence(key), self).activated.connect(
                lambda s=step: self.model is not None and self.grid.step_camera(s))
        for key, factor in (("=", 0.5), ("+", 0.5), ("-", 2.0)):  # the waveform, as the wheel
            QShortcut(QKeySequence(key), self).activated.connect(
                lambda f=factor: self.model is not None and self.waveform.zoom_at_playhead(f))

    def _space(self) -> None:
        """Space: play / pause; on a button Tab has reached (the "then next set" box, the
        status line's Cancel, the first page's buttons), press it, as Space does on any
        button: the shortcut took the key from them, and nothing else pressed them."""
        focus = QApplication.focusWidget()
        if isinstance(focus, QAbstractButton) and focus.window() is self and \
                focus.isVisible() and focus.isEnabled():
            focus.click()
            return
        self.transport.toggle()

    def _build_edit_menu(self) -> None:
        """Edit ▸ Undo / Redo, named after the step they revert (U undoes too)."""
        self.edit_menu = self.menuBar().addMenu("&Edit")
        self._idle_edit_keys: list[tuple[QAction, QShortcut]] = []
        self.undo_action = QAction("&Undo", self)
        self.redo_action = QAction("&Redo", self)
        for action, name, keys in ((self.undo_action, "undo", UNDO_KEYS),
                                   (self.redo_action, "redo", REDO_KEYS)):
            action.setShortcuts([QKeySequence(k) for k in keys])
            action.triggered.connect(lambda _=False, a=name: self.run_action(a))
            self.addAction(action)  # the shortcut works with the menu closed
            self.edit_menu.addAction(action)
            # a disabled entry's shortcut does nothing: these stand in for it and say
            # "nothing to undo", as U does
            for key in keys:
                stand_in = QShortcut(QKeySequence(key), self)
                stand_in.activated.connect(lambda a=name: self.run_action(a))
                self._idle_edit_keys.append((action, stand_in))
        self.edit_menu.addSeparator()
        self.detect_action = QAction(f"{FIND_WORDS}…", self)
        self.detect_action.setShortcut(QKeySequence(FIND_WORDS_KEY))
        self.detect_action.setToolTip("Detect trigger words again: other words, or another "
                                      "sensitivity; the sets found are added")
        self.detect_action.triggered.connect(self.detector.choose)
        self.detect_action.setEnabled(False)
        self.addAction(self.detect_action)
        self.edit_menu.addAction(self.detect_action)
        self.leave_out_action = LeaveOutAction(self)
        self.edit_menu.addAction(self.leave_out_action)
        self._update_edit_menu()

    def _update_edit_menu(self, *_args: object) -> None:
        """The Undo / Redo entries say what they would revert, and are off when nothing."""
        model = self.model
        for action, verb, label in (
                (self.undo_action, "Undo", model.undo_label if model else ""),
                (self.redo_action, "Redo", model.redo_label if model else "")):
            action.setText(f"&{verb} {label}" if label else f"&{verb}")
            action.setEnabled(bool(label))
        for action, stand_in in self._idle_edit_keys:
            stand_in.setEnabled(not action.isEnabled())  # never both: Qt would find it ambiguous
        if self.undo_button is not None:  # the review page's button says the same
            self.undo_button.setEnabled(self.undo_action.isEnabled())
            self.undo_button.setToolTip(self.undo_action.text().replace("&", ""))

    def _build_review_page(self, inputs: ReviewInputs) -> None:
        old = self.review_page.layout()
        if old is not None:
            QWidget().setLayout(old)  # reparent and drop the previous layout
        model = self.model
        assert model is not None
        layout = QVBoxLayout(self.review_page)
        layout.setContentsMargins(6, 6, 6, 6)
        split = QSplitter(Qt.Orientation.Vertical)
        top = QSplitter(Qt.Orientation.Horizontal)
        for splitter in (split, top):  # a pane dragged to nothing left a hair-thin handle
            splitter.setChildrenCollapsible(False)
        left = QWidget()
        left_layout = QVBoxLayout(left)
        left_layout.setContentsMargins(0, 0, 0, 0)
        self.grid = FrameGrid(model.streams)
        self._clap_drag_ns = None  # a drag on the waveform left with the page
        # the keys act on the window wherever the focus is; it rests on the grid (a click
        # there takes it back from the box or the waveform)
        self.grid.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        left_layout.addWidget(self.grid, 1)
        left_layout.addLayout(self._build_transport_row())
        top.addWidget(left)
        right = QWidget()
        right_layout = QVBoxLayout(right)
        right_layout.setContentsMargins(0, 0, 0, 0)
        right_layout.addLayout(self._build_filter_row())
        self.table = SetTable()
        right_layout.addWidget(self.table, 1)
        self.no_sets_label = QLabel("")  # why the list is empty, and what to do
        self.no_sets_label.setWordWrap(True)
        self.no_sets_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.no_sets_label.setStyleSheet(f"color: {WARNING_TEXT_COLOUR.name()};")
        self.no_sets_label.hide()
        right_layout.addWidget(self.no_sets_label)
        buttons = QHBoxLayout()
        for label, action in (("[A] accept", "accept"), ("[R] reject", "reject")):
            buttons.addWidget(self._action_button(label, action))
        self.undo_button = self._action_button("[U] undo", "undo")
        buttons.addWidget(self.undo_button)
        self.advance_box = QCheckBox("then next set")
        self.advance_box.setToolTip(
            "after A or R, go on to the next set in the list (as the filter shows it); "
            "off: stay on the decided set")
        self.advance_box.setChecked(model.advance_after_decision)
        # Tab reaches it (and Space then ticks it); a click leaves the focus where it
        # was, so the next Space plays as before instead of unticking it
        self.advance_box.setFocusPolicy(Qt.FocusPolicy.TabFocus)
        self.advance_box.toggled.connect(self._set_advance)
        buttons.addWidget(self.advance_box)
        right_layout.addLayout(buttons)
        edits = QHBoxLayout()
        self.add_button = self._action_button(
            "[T] add set at playhead", "add_set",
            "a trigger the detection missed: a set at the playhead (its best still "
            "frames follow)")
        self.remove_button = self._action_button(
            "[Del] remove set", "remove_set",
            "a false trigger: remove the current set (undo brings it back)")
        self.similar_button = self._action_button(
            "[S] find more like this", "find_similar",
            "search the audio for words that sound like the current set's trigger word "
            "(one you added with T, or any set) and add each one no set covers as an "
            "undecided set; undo removes them all")
        edits.addWidget(self.add_button)
        edits.addWidget(self.similar_button)
        edits.addWidget(self.remove_button)
        right_layout.addLayout(edits)
        self.counts_label = QLabel("")
        right_layout.addWidget(self.counts_label)
        self.check_label = QLabel("")
        self.check_label.setWordWrap(True)
        right_layout.addWidget(self.check_label)
        top.addWidget(right)
        top.setStretchFactor(0, 3)
        top.setStretchFactor(1, 1)
        # the list's columns at the window's font, measured (at least 480 px, as at
        # 9 pt): a larger system font cut the decision column off, and 70 average
        # characters held a 10 pt window of 12 cameras 8 px wider than half a 1920 px
        # screen
        self._list_panel = right
        # fitted to the headings already (an empty list stays so: nothing tells again)
        self._fit_list_panel(self.table.least_width())
        # a method of the window, not a closure over the panel: the connection goes with
        # the window, where a closure holds the panel's wrapper for as long as the table
        # lives and may call into a panel Qt is destroying
        self.table.least_width_changed.connect(self._fit_list_panel)
        top.setSizes([900, 500])
        split.addWidget(top)
        bottom = QWidget()
        bottom_layout = QVBoxLayout(bottom)
        bottom_layout.setContentsMargins(0, 0, 0, 0)
        start_ns, end_ns = model.time_range_ns()
        self.waveform = WaveformView(start_ns)
        self.waveform.setMinimumHeight(WAVEFORM_MIN_HEIGHT)
        bottom_layout.addWidget(self.waveform, 1)
        sync_row = QHBoxLayout()
        self.sync_line = EllipsisLabel()  # a warning's words never widen the window
        sync_row.addWidget(self.sync_line, 1)
        for label, action, tip in (
            ("−1 frame", "offset_minus_frame", "audio one frame earlier  ({)"),
            ("−1 ms", "offset_minus_ms", "audio 1 ms earlier  ([)"),
            ("+1 ms", "offset_plus_ms", "audio 1 ms later  (])"),
            ("+1 frame", "offset_plus_frame", "audio one frame later  (})"),
        ):
            sync_row.addWidget(self._action_button(label, action, tip))
        self.help_line = ElidedLabel(HINTS, HINTS_TIP, separator=" · ")
        self.help_line.setStyleSheet(f"color: {hint_text_colour(self.palette()).name()}")
        bottom_layout.addLayout(sync_row)
        bottom_layout.addWidget(self.help_line)
        split.addWidget(bottom)
        split.setStretchFactor(0, 3)
        split.setStretchFactor(1, 1)
        split.setSizes([600, 260])
        layout.addWidget(split)

        self.waveform.audio_unreadable.connect(lambda text: self.status.end("waveform", text))
        if inputs.pyramid is not None:
            self.waveform.set_audio(inputs.pyramid, model.session.sync)
            model.audio_duration_s = inputs.pyramid.size / inputs.pyramid.rate
        else:  # the marks still show where the words were heard
            self.waveform.set_sync(model.session.sync)
            gone = bool(inputs.session.audio) and not Path(inputs.session.audio).exists()
            self.waveform.show_message(f"no waveform: {inputs.no_waveform}" + (
                " · File ▸ Locate audio… shows where it is now" if gone else ""))
        self.waveform.set_claps(inputs.claps_audio_s)
        self.waveform.clap_moved.connect(self._clap_dragged)
        self.waveform.clap_dragging.connect(self._clap_dragging)
        self.waveform.set_sets(model.session.sets)
        self.waveform.show_all(start_ns, end_ns)
        # Tab in the order the eyes go: frames, sound, the list's box, Cancel (when shown)
        for before, after in ((self.grid, self.waveform), (self.waveform, self.advance_box),
                              (self.advance_box, self.cancel_button)):
            QWidget.setTabOrder(before, after)
        self.waveform.playhead_moved.connect(model.set_playhead)
        self.waveform.word_clicked.connect(model.click_word)
        self.table.set_sets(model.session.sets, start_ns, self._rescore_marks())
        self.table.set_chosen.connect(model.go_to_set)

    # -- opening ------------------------------------------------------------------------
    def choose_session(self) -> None:
        """Ctrl+O: a session file to open, looked for beside the session open now (the
        program's working folder, where it was started, is seldom where sessions are)."""
        here = self.saver.path if self.model is not None else None
        path, _ = QFileDialog.getOpenFileName(self, "Open session",
                                              str(here.parent) if here else "",
                                              "SpeechCal sessions (*.json)")
        if path:
            self.open(session_path=path)

    def open(self, *, session_path: str | None = None, recording: list[str] | None = None,
             audio: str | None = None, new_session_path: str | None = None,
             triggers: TriggerSpec | None = None, channel: int | None = None,
             target: TargetSpec | None = None, streams: StreamChoice | None = None) -> None:
        """Load a session file, or process a recording + audio (its session saved at
        ``new_session_path``, by default beside the recording; ``triggers``, ``channel``,
        ``target`` and ``streams`` as for ``load_for_review``), on a worker thread."""
        args: OpenRequest = {
            "session_path": session_path, "recording": recording, "audio": audio,
            "new_session_path": new_session_path, "triggers": triggers,
            "channel": channel, "target": target, "streams": streams}
        self._opening = args
        self._start(lambda report: load_for_review(**args, progress=report), "opening…")

    def open_without_clap(self) -> None:
        """Process the recording whose clap was not found again, its audio taken to start
        with the first frame (the offset is then set in the review)."""
        args = self._failed_recording
        if args is None:
            return
        self._opening = None
        self._start(lambda report: load_for_review(**args, audio_at_start=True,
                                                   progress=report), "opening…")

    def _start(self, work: Callable[[Progress], ReviewInputs], text: str) -> None:
        if self.model is not None and not self.saver.unsaved:
            # the set and filter shown, written before the opening reads the file: the
            # same session opened again (a camera left out, its audio located) resumes
            # there, not at the last decision's set
            self.model.save_place()
        if not self._may_drop_unsaved():  # waits for that save
            return
        self.load_error = ""
        if self.task is not None:  # the operator opens something else: the earlier opening
            self.task.abandon()  # stops, and a recording it opens anyway is closed
        # a session opened for nobody (another was opened, or the window closed, before
        # it was ready) has its recording closed at once
        self.task = BackgroundTask(work, owner=self, discard=ReviewInputs.close)
        self.task.signals.progress.connect(
            lambda t, f: self.status.report("open", t, f))
        self.task.signals.progress.connect(lambda t, f: self._show_opening(t, f))
        self.task.signals.finished.connect(self._on_loaded)
        self.task.signals.failed.connect(self._on_failed)
        self.status.begin("open", text)
        self._show_opening(text, 0.0)
        start(self.task)

    def _show_opening(self, text: str, fraction: float) -> None:
        """The first page, while an opening runs: what it is doing (it said "Open a
        calibration session" through a minute of processing), its buttons off."""
        if self.model is not None or self.task is None:
            return
        self.empty_text.setText(opening_text(text, fraction))
        self.open_problem.hide()
        self.locate_button.hide()
        self.no_clap_button.hide()
        for button in (self.open_button, self.demo_button):
            button.setEnabled(False)

    def _show_empty(self) -> None:
        """The first page as it is before anything is opened."""
        self.empty_text.setText(EMPTY_TEXT)
        for button in (self.open_button, self.demo_button):
            button.setEnabled(True)

    def open_demo(self) -> None:
        """Make (once) and open the synthetic demo session, off the UI thread."""
        from speechcal_core.synth.demo import ensure_demo_session

        def work(report: Progress) -> ReviewInputs:
            recording, audio = ensure_demo_session(progress=report)
            return load_for_review(recording=[recording], audio=audio, progress=report)

        self._opening = None  # no session file or recording of the operator's is opened
        self._start(work, "preparing the demo session…")

    def _build_filter_row(self) -> QHBoxLayout:
        """The list's title, one button per filter (F cycles them) and how many it shows."""
        row = QHBoxLayout()
        row.addWidget(QLabel("<b>Frame sets</b>"))
        row.addStretch(1)
        self.shown_label = QLabel("")
        row.addWidget(self.shown_label)
        self.filter_group = QButtonGroup(self)
        self.filter_buttons: dict[str, QToolButton] = {}
        for name in FILTERS:
            b = QToolButton()
            b.setText(name if name == "all" else f"{DECISION_SYMBOLS[name]} {name}")
            b.setToolTip(f"list {'every set' if name == 'all' else f'only {name} sets'}; "
                         "J/K step through the listed sets  (F: next filter)")
            b.setCheckable(True)
            b.setChecked(name == "all")
            b.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            b.clicked.connect(lambda _=False, n=name: self._choose_filter(n))
            self.filter_group.addButton(b)
            self.filter_buttons[name] = b
            row.addWidget(b)
        return row

    def _set_advance(self, on: bool) -> None:
        """The "then next set" box: kept for the sessions opened later, too."""
        self.advance_after_decision = on
        if self.model is not None:
            self.model.advance_after_decision = on

    def _choose_filter(self, name: str) -> None:
        if self.model is not None:
            self.model.set_filter(name)

    def _build_transport_row(self) -> QHBoxLayout:
        """Under the grid: previous set, play / pause, next set, then where the playhead is
        (the keys J, Space, K do the same)."""
        row = QHBoxLayout()
        previous = self._action_button("◀◀", "previous_set", "previous frame set  (J)")
        row.addWidget(previous)
        play = self.transport.make_button()
        row.addWidget(play)
        following = self._action_button("▶▶", "next_set", "next frame set  (K)")
        row.addWidget(following)
        self.transport_buttons = (previous, play, following)
        for button in (previous, following):  # two glyphs: the line beside them needs the room
            button.setMaximumWidth(6 * button.fontMetrics().horizontalAdvance("◀"))
        self.info_line = ElidedLabel("")  # never widens the window; the tooltip has it whole
        row.addWidget(self.info_line, 1)
        return row

    def _action_button(self, label: str, action: str, tip: str = "") -> QPushButton:
        """A button that runs a review action (keyboard focus stays on the window)."""
        b = QPushButton(label)
        if tip:
            b.setToolTip(tip)
        b.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        b.clicked.connect(lambda _=False: self.run_action(action))
        return b

    def cancel_task(self) -> None:
        if self.task is not None:
            self.task.cancel()
        self.exporter.cancel()
        self.rescorer.cancel()
        self.similar.cancel()
        self.detector.cancel()

    def _on_failed(self, message: str) -> None:
        failed, self.task = self.task, None
        self._show_empty()
        args, self._opening = self._opening or {}, None
        # no clap found in a recording: the first page offers to go on without one
        self._failed_recording = args if args.get("recording") and not args["session_path"] \
            and failed is not None and isinstance(failed.error, SyncError) else None
        self.no_clap_button.setVisible(self._failed_recording is not None
                                       and self.model is None)
        if message == "cancelled":  # the operator's Cancel: nothing went wrong
            self.status.end("open", "opening cancelled")
            return
        self.load_error = message
        self.status.end("open", f"Could not open: {message}")
        opening = args.get("session_path")
        # asked whether or not a session is open (Open over one sent the operator to the
        # command line)
        self._moved = moved_recording(opening) if opening else None
        if self.model is None:  # the first page says why, whole, and what can be done
            self.open_problem.setText(f"Could not open: {message}")
            self.open_problem.show()
            self.locate_button.setVisible(self._moved is not None)
        if not self.property("headless") and self._moved is None:
            QMessageBox.warning(self, "SpeechCal", message)
        if self._moved is not None:
            self.locate_recording()

    def locate_recording(self) -> None:
        """Ask where the recording of the session that could not be opened went, and open
        the session with it there (its review work kept; the session then reads it there)."""
        moved = self._moved
        if moved is None:
            return
        chosen = self.ask_recording_place(moved)
        if not chosen:
            return
        try:
            recording, audio = relocated_inputs(moved.session_path, chosen)
        except SpeechCalError as exc:
            self.open_problem.setText(f"{exc}")
            self.status.say(str(exc))
            return
        self.open(recording=recording, audio=audio,
                  new_session_path=str(moved.session_path))

    def locate_audio(self) -> None:
        """Ask where the session's audio file went, and open the session again with it
        there (its review work is saved; the session then reads the audio there)."""
        inputs = self.inputs
        if inputs is None or inputs.session_path is None or not inputs.session.audio:
            return
        chosen = self.ask_audio_place(inputs.session.audio)
        if not chosen:
            return
        try:
            audio = relocated_audio(inputs.session.audio, chosen)
        except SpeechCalError as exc:
            self.status.say(str(exc))
            return
        self.open(recording=list(inputs.session.recording), audio=audio,
                  new_session_path=str(inputs.session_path))

    def _ask_audio_place(self, audio: str) -> str | None:
        """The file dialog behind :attr:`ask_audio_place` (none in a headless window)."""
        if self.property("headless"):
            return None
        name = Path(audio).name
        chosen, _filter = QFileDialog.getOpenFileName(
            self, f"Where is {name} now?", str(Path(audio).parent), f"{name} ({name})")
        return chosen or None

    def _ask_recording_place(self, moved: MovedRecording) -> str | None:
        """The file dialog behind :attr:`ask_recording_place` (none in a headless window)."""
        if self.property("headless"):
            return None
        chosen, _filter = QFileDialog.getOpenFileName(
            self, f"Where is {moved.names} now? (a ROS2 bag folder: its metadata.yaml)",
            str(moved.session_path.parent))
        return chosen or None

    def _on_loaded(self, inputs: ReviewInputs) -> None:
        self.status.end("open")
        self.task = None
        self._show_empty()
        self._opening = self._moved = self._failed_recording = None
        self.open_problem.hide()
        self.locate_button.hide()
        self.no_clap_button.hide()
        if not self._may_drop_unsaved():  # a save failed while it was loading
            inputs.close()
            self.status.say("not opened: the current session's decisions are not saved")
            return
        self.transport.stop()
        if self.model is not None and not self.saver.unsaved:
            self.model.save_place()  # the session left opens again where it was
        if self.loader is not None:
            self.loader.shutdown()
            if self.loader.reading():  # its recording stays open until the decode ends
                self._old_loaders.append(self.loader)
                self.loader.stopped.connect(self.release_retired)
        self.rescorer.reset()  # what runs belongs to the previous session's model
        self.checker.reset()
        self.similar.reset()
        self.detector.reset()
        if self.inputs is not None:
            self._retired.append(self.inputs)
        self.inputs = inputs
        self.saver.reset(inputs.session_path, inputs.session_stamp, inputs.restores)
        self.status.end("save")
        self._save_warned = False
        self.save_as_action.setEnabled(True)
        self.locate_audio_action.setEnabled(
            bool(inputs.session.audio) and not Path(inputs.session.audio).exists())
        self.detect_action.setEnabled(bool(inputs.session.audio))
        self._update_saved_label()
        self.model = ReviewModel(inputs.session, inputs.source, autosave=self._autosave)
        self.leave_out_action.update()
        self.model.advance_after_decision = self.advance_after_decision
        self.loader = FrameLoader(inputs.source, parent=self)
        self.loader.loaded.connect(self._on_frame)
        self.loader.failed.connect(self._on_frame_failed)
        self._build_review_page(inputs)
        self.model.connect("playhead", lambda _t: self._refresh_playhead())
        self.transport.follow(self.model)
        self.model.connect("current_set", self.table.select_row)
        self.model.connect("current_set", lambda _row: self._on_current_set())
        self.model.connect("decision", self._on_decision)
        self.model.connect("sets", self.rescorer.schedule)
        self.model.connect("sync", self.rescorer.schedule)
        self.model.connect("sets", self._on_sets)
        self.model.connect("sync", self._on_sync)
        self.model.connect("rescored", self._on_rescored)
        self.model.connect("filter", lambda _name: self._apply_filter())
        self.model.connect("filter", lambda _name: self._update_info_line())
        for event in ("rescored", "decision", "sets", "sync"):
            self.model.connect(event, self.checker.schedule)
        for event in ("decision", "sets", "sync"):  # once the step (and its stack) is done
            self.model.connect(event, lambda *_a: QTimer.singleShot(0, self._update_edit_menu))
        self._update_edit_menu()
        self.model.connect("checks", self._update_check_line)
        self.model.connect("similar", self.similar.ask)
        # the audio of a topic of the recording is named as that topic, not the file kept
        topic = inputs.session.extra.get(TOPIC_KEY)
        heard = str(topic) if topic else Path(inputs.session.audio or "").name
        title = " + ".join(shown_name(p) for p in
                           [*(Path(r).name for r in inputs.session.recording), heard] if p)
        self.setWindowTitle(f"SpeechCal — {title}")
        self.stack.setCurrentWidget(self.review_page)
        # the focus was on the status line's Cancel, hidden as the opening ended
        self.grid.setFocus(Qt.FocusReason.OtherFocusReason)
        self.export_button.setEnabled(True)
        self.export_action.setEnabled(True)
        n = len(inputs.session.sets)
        self._opened_note = self._opening_text()
        self.status.say(self._opened_note)
        if self.on_opened is not None:
            self.on_opened(self._opened_note)
        self.exporter.reset("another session was opened before it could start")
        self._update_sync_line()
        self._update_counts()
        self._apply_filter()  # an empty list says why (no_sets_hint)
        if n:  # where the review was when the session was last saved, else the first
            self.model.go_to_set(self.model.current)
        else:
            self._refresh_playhead()
        self.rescorer.schedule()  # sets left unscored when the window last closed
        self.checker.schedule()  # checks left stale then
        self.release_retired()

    # -- model -> view ------------------------------------------------------------------
    def run_action(self, action: str) -> None:
        model = self.model
        if model is None:
            return
        removing = model.acting_set() if action == "remove_set" else None
        done, step = {"undo": ("undone", model.undo_label),
                      "redo": ("redone", model.redo_label)}.get(action, ("", ""))
        n_sets = len(model.session.sets)
        offset_ns = model.session.sync.offset_ns
        model.last_decided = None
        model.step_refused = ""
        model.trigger(action)
        if len(model.session.sets) != n_sets and not model.session.sets:
            # the model records the step after it tells of the sets: the empty list's
            # words, which name a removal that undo puts back, were worked out before it
            # (a lone set removed said no trigger word was found in the audio)
            self._apply_filter()
        # each says what it did, which also replaces a message it made untrue ("redone:
        # decision on set 2" through later decisions, "set #3 removed" after its undo)
        if removing is not None and all(s.id != removing.id for s in model.session.sets):
            # the set may have been off screen (the playhead between sets)
            self.status.say(f"set #{removing.id} removed · Ctrl+Z puts it back")
        elif step:
            moved = model.session.sync.offset_ns != offset_ns
            if moved and not self.status.running("rescore"):
                # the sets show the frames they had before (or after) that offset again:
                # the last re-scoring's word ("accepted set #1 now shows other frames:
                # look again") is no longer true; a re-scoring still needed says its own
                self.status.end("rescore")
            # an offset or a set put back may need re-scoring (one running restarts):
            # what was undone stays beside it, as what the edit itself did does
            self.status.say(f"{done}: {step}", outlasts_work=moved or
                            len(model.session.sets) != n_sets)
        elif action in ("undo", "redo"):
            self.status.say(f"nothing to {action}")
        elif action == "clap_at_playhead":  # its words stay through the re-scoring
            self.status.say(clap_moved_text(model.session.sync.offset_ns - offset_ns)
                            if model.camera_clap_ns() is not None else NO_CAMERA_CLAP,
                            outlasts_work=True)
        elif action in ("accept", "reject") and model.last_decided is not None:
            decided = model.session.set_by_id(model.last_decided)
            # "then next set" found none: the end of the list (of the undecided ones)
            end = f" · {model.step_refused}" if model.step_refused else ""
            self.status.say(f"set #{decided.id} {decided.decision}{end}")
        elif action in ("accept", "reject", "remove_set") and model.step_refused:
            self.status.say(model.step_refused)  # no set left to act on
        elif action in STEP_ACTIONS:  # why it went nowhere (counted); gone once it went on
            if model.step_refused:
                self.status.say(model.step_refused)
            else:
                self.status.withdraw(self._step_refused)
            self._step_refused = model.step_refused
        elif action in OFFSET_ACTIONS:  # its words stay through the re-scoring
            moved = model.session.sync.offset_ns - offset_ns
            self.status.say(offset_moved_text(moved, OFFSET_ACTIONS[action]),
                            outlasts_work=bool(moved))
        elif action == "add_set" and model.current_set is not None:
            added = len(model.session.sets) > n_sets
            self.status.say(f"set #{model.current_set.id} added · Ctrl+Z takes it back"
                            if added else f"set #{model.current_set.id} is here already: "
                            "selected it (T adds a set away from the others)",
                            outlasts_work=added)  # through the added set's re-scoring

    def _clap_dragging(self, shift_ns: int) -> None:
        """The clap handle is being dragged ``shift_ns`` from where it was: the grid shows
        where the release would put the playhead (see ReviewModel.preview_offset). While
        playing, the playhead follows the sound as it plays on (a preview pulled it away,
        and the sound with it, at every move)."""
        model = self.model
        if model is None:
            return
        self._clap_drag_ns = shift_ns  # the word band says how far (see _update_word_band)
        if self.transport.playing:
            self._update_word_band()
        else:
            model.preview_offset(shift_ns)  # the playhead moves: the band follows

    def _clap_dragged(self, shift_ns: int) -> None:
        """The clap handle released ``shift_ns`` from where it was: the audio moves with
        it, and the status line says so as for the keys."""
        model = self.model
        if model is None:
            return
        self._clap_drag_ns = None
        offset_ns = model.session.sync.offset_ns
        model.nudge_offset(shift_ns)  # the playhead moves: the band gives the word back
        moved = model.session.sync.offset_ns - offset_ns
        self.status.say(offset_moved_text(moved, f"{self.waveform.handle_name()} dragged"),
                        outlasts_work=bool(moved))

    def _on_current_set(self) -> None:
        """The waveform marks the new current set and, zoomed in, takes it into view."""
        current = self.model.current_set if self.model is not None else None
        self.waveform.marks.set_current(current.id if current is not None else None)
        if current is not None:
            self.waveform.bring_into_view(current.id)

    def _refresh_playhead(self) -> None:
        model = self.model
        if model is None or self.loader is None:
            return
        self.waveform.set_playhead(model.playhead_ns)
        if self.transport.playing:
            self.waveform.follow(model.playhead_ns)
        current = model.set_at_playhead()
        if current is not None:  # W's "no frame set at the playhead" no longer holds
            self.status.withdraw(NO_SET_TO_HEAR, job="audio")
        chosen = "chosen frame"
        if model.current_set is not None and model.needs_rescore(model.current_set):
            chosen = NEAREST_CAPTION if self.rescorer.held else f"{NEAREST_CAPTION}, re-scoring…"
        wanted = []
        self._pending_tiles = set()
        for tile in model.tiles():
            widget = self.grid.tiles[tile.stream]
            decision = current.decision if current else None
            if tile.index < 0 and self.transport.playing and not tile.chosen and tile.stamp_ns \
                    and widget.image is not None:  # a dropped frame: no blank flash
                widget.hold_dimmed(DROPPED_CAPTION)
                widget.set_state(decision)
                continue
            if tile.index < 0:
                widget.show_message(self._no_frame_text(tile.stream, tile.chosen,
                                                        bool(tile.stamp_ns)))
                widget.set_state(decision, "no frame")
                continue
            widget.set_state(decision, flag_words(tile.flags), flag_short_words(tile.flags))
            widget.corners = tile.corners
            widget.expect_frame(chosen if tile.chosen else f"{tile.offset_ns / 1e6:+.1f} ms")
            wanted.append((tile.stream, tile.index))
            self._pending_tiles.add(tile.stream)
        self.loader.request(wanted)
        self._update_word_band()
        self._update_info_line()

    def _update_word_band(self) -> None:
        """The band under the grid: the trigger word of the set under the playhead (or
        which set the keys act on); while the clap handle is dragged, how far the audio
        would move."""
        model = self.model
        if model is None:
            return
        current = model.set_at_playhead()
        acting = model.acting_set()
        self.grid.set_word(current.trigger.word if current else "",
                           current.decision if current else None,
                           current.trigger.source if current else "",
                           acting.id if acting is not None else None)
        self.grid.set_drag_note("" if self._clap_drag_ns is None
                                else clap_drag_text(self._clap_drag_ns,
                                                    self.waveform.handle_label()))

    def _no_frame_text(self, stream: str, in_set: bool, has_frames: bool) -> str:
        """What a tile without a frame says: no frame chosen for the set (and how far the
        camera's nearest frame lies), none near the playhead, or none at all."""
        if not has_frames:
            return "no frames in this stream"
        if not in_set:
            return "no frame near the playhead"
        away = self.model.nearest_frame_offset_ns(stream) if self.model else None
        if away is None:
            return "no frame for this set"
        return f"no frame for this set: this camera's nearest is {away / 1e9:+.2f} s away"

    def _update_info_line(self) -> None:
        """The line under the grid: the set under the playhead (its place in the list,
        skew, when it was said) and the playhead's time. Where it is too narrow (960 px,
        half a 1920 px screen) the playhead's time stays whole: the camera clock's stamp
        goes first, then when the word was said, "from start", the skew, the set's
        place; the tooltip has it all."""
        model = self.model
        if model is None:
            return
        current = model.set_at_playhead()
        start_ns, _ = model.time_range_ns()
        rel = (model.playhead_ns - start_ns) / 1e9
        t = f"t = {rel:.3f} s"
        times = [f"{t} from start ({model.playhead_ns / 1e9:.3f} s)", f"{t} from start", t]
        if current is None:
            self.info_line.set_full_text(times[0], times[1:])
            return
        # counted over the sets the filter lists, which J/K step through (the list's #
        # column is the id)
        place = list_place(model.session.sets, model.filter,
                           model.session.sets.index(current))
        said = clock_text((current.t_ns - start_ns) / 1e9)
        framed = sum(f.index >= 0 for f in current.frames)
        skew = f"skew {current.skew_ns / 1e6:.1f} ms" if framed > 1 else f"skew {MISSING}"
        # what the operator reads first leads: the set, then its skew
        named = f"set #{current.id} ({place})"
        self.info_line.set_full_text(
            f"{named} · {skew} · said at {said} · {times[0]}",
            [f"{named} · {skew} · said at {said} · {times[1]}",
             f"{named} · {skew} · {times[1]}",
             f"{named} · {skew} · {t}",
             f"{named} · {t}",
             f"set #{current.id} · {t}",
             t])

    def _on_frame(self, stream: str, index: int, image: QImage) -> None:
        tile = self.grid.tiles.get(stream)
        if tile is not None:
            tile.show_image(image)  # with the caption its request gave
        self._pending_tiles.discard(stream)

    def _on_frame_failed(self, stream: str, index: int, message: str) -> None:
        tile = self.grid.tiles.get(stream)
        if tile is not None:
            tile.show_message(f"frame {index} cannot be shown: {message}")
            tile.set_state(tile.decision, "bad frame")
        self._pending_tiles.discard(stream)

    def _on_decision(self, set_id: int, decision: str) -> None:
        model = self.model
        assert model is not None
        row = next(i for i, s in enumerate(model.session.sets) if s.id == set_id)
        decided = model.session.sets[row]  # still "…" while it waits for re-scoring
        self.table.update_row(row, decided, decided.id in self._rescore_marks())
        self._apply_filter()
        self.waveform.update_set(model.session.sets[row])
        self._update_counts()
        self._refresh_playhead()

    def _on_sets(self) -> None:
        """A set was added or removed: list, markers and counts show the new sets."""
        model = self.model
        assert model is not None
        self.table.set_sets(model.session.sets, model.time_range_ns()[0], self._rescore_marks())
        self._apply_filter()
        self.waveform.set_sets(model.session.sets)
        self._update_counts()
        self._update_info_line()  # it gives the set's place in the list
        self._update_sync_line()  # how many words fall at a still board
        revised = self._opening_text()  # its count of sets changed
        self.status.revise(self._opened_note, revised)
        self._opened_note = revised

    def _opening_text(self) -> str:
        """What the status line says of the session opened: cameras, sets, the note."""
        assert self.model is not None and self.inputs is not None
        note = "; ".join(filter(None, [self.inputs.note, self.model.history_note]))
        return (f"{counted(len(self.model.streams), 'camera')}, "
                f"{counted(len(self.model.session.sets), 'frame set')}"
                + (f" · {note}" if note else ""))

    def _on_sync(self, sync: SyncModel) -> None:
        model = self.model
        assert model is not None
        # the claps placed on the new clock (C may name another sound): the later ones'
        # lines made once
        self.waveform.set_sync(sync, model.session.claps_audio_s())
        self.waveform.set_sets(model.session.sets)
        # the playhead moved with the sound under it (see ReviewModel._playhead_after):
        # seen before the edit, it stays in view (C may have moved it seconds away)
        self.waveform.set_playhead(model.playhead_ns, keep_in_view=True)
        self.table.set_sets(model.session.sets, model.time_range_ns()[0], self._rescore_marks())
        self._apply_filter()
        self._update_sync_line()
        self._update_check_line()

    def _on_rescored(self, set_ids: list[int]) -> None:
        """Re-scored sets: their rows get figures, the tiles their chosen frames, the sync
        line how many words fall at a still board."""
        self.refresh_rescore_marks()
        self._refresh_playhead()
        self._update_check_line()
        self._update_sync_line()

    def _rescore_marks(self) -> set[int]:
        """Ids of the sets whose figures re-scoring will bring (shown as … in the list)."""
        if self.model is None or self.rescorer.held:
            return set()
        return set(self.model.rescore_ids())

    def refresh_rescore_marks(self) -> None:
        """Rewrite the list's rows (figures, or … while a set waits for re-scoring)."""
        model = self.model
        if model is None:
            return
        self.table.set_sets(model.session.sets, model.time_range_ns()[0],
                            self._rescore_marks())  # rows alike are skipped, columns fit once
        self._apply_filter()

    def _apply_filter(self) -> None:
        """Show the rows the model's filter passes; its button checked, a count if hiding,
        and under an empty list why it is empty (it runs whenever the sets change)."""
        model = self.model
        if model is None:
            return
        shown = model.shown()
        self.table.show_rows(shown, model.current)
        for name, button in self.filter_buttons.items():
            button.setChecked(name == model.filter)
        total = len(model.session.sets)
        hint = no_sets_hint(model.session, model.removed_here)
        if not hint and not shown:  # the filter hides every set
            hint = (f"no {model.filter} sets: “all” (or F, which steps through the "
                    "filters) shows every set")
        self.no_sets_label.setText(f"{WARNING_SYMBOL} {hint}" if hint else "")
        self.no_sets_label.setVisible(bool(hint))
        if len(shown) == total:
            text = ""
        elif shown:
            text = f"{len(shown)} of {total}"
        else:  # an empty list says why it is empty (its filter's button is checked)
            text = f"none of {total}"
        self.shown_label.setText(text)

    def _update_counts(self) -> None:
        if self.model is None:
            return
        c = self.model.session.counts()
        self.counts_label.setText(f"✔ {c['accepted']} accepted   ✘ {c['rejected']} rejected   "
                                  f"? {c['undecided']} undecided")
        self._update_check_line()

    def _update_check_line(self) -> None:
        """Coverage and calibration check over the sets not rejected (or "updating…")."""
        if self.model is None:
            return
        summary = check_summary(self.model.session, self.model.streams)
        self.check_label.setVisible(summary is not None)
        if summary is None:
            return
        text = summary.line
        if self.checker.last_error and summary.line.endswith("updating…"):
            text = f"calibration check failed: {self.checker.last_error}"
        warn = summary.warning
        text = unbroken_figures(text)  # "RMS ≤ 0.22 px" wrapped "px" onto a line alone
        self.check_label.setText(f"{WARNING_SYMBOL} {text}" if warn else text)
        self.check_label.setStyleSheet(f"color: {WARNING_TEXT_COLOUR.name()}" if warn else "")
        self.check_label.setToolTip("\n".join(summary.cameras))

    def release_retired(self) -> None:
        """Close the recordings of sessions opened before, once nothing reads them."""
        self._old_loaders = [lo for lo in self._old_loaders if lo.reading()]
        busy = {id(self.exporter.source), id(self.rescorer.source)}
        busy |= {id(lo.source) for lo in self._old_loaders}
        for inputs in list(self._retired):
            if id(inputs.source) not in busy:
                self._retired.remove(inputs)
                inputs.close()

    def _fit_list_panel(self, least: int) -> None:
        """The list's panel at least ``least`` pixels wide (the list's columns), and 480."""
        self._list_panel.setMinimumWidth(max(480, least))

    def _update_sync_line(self) -> None:
        """The offset line (see :func:`sync_line_forms`): a narrow window shows a shorter
        form, the tooltip has it whole."""
        if self.model is None or self.inputs is None:
            return
        line = sync_line_forms(self.model.session, self.model.time_range_ns()[0],
                               self.model.word_stillness())
        self.sync_line.set_texts(line.texts[0], line.texts[1:])
        self.sync_line.setStyleSheet(f"color: {WARNING_TEXT_COLOUR.name()}" if line.alerted
                                     else "")
        self.sync_line.setToolTip(line.tooltip)

    def _autosave(self, session: Session) -> None:
        """Save after every change (off the UI thread: :meth:`_on_saved` says how it
        went); a failure is warned about, never raised."""
        self.saver.save(session)

    def _on_saved(self) -> None:
        """A save ended: a failure is warned about, a success after one clears it."""
        if self.saver.error is not None:
            self.status.end("save", f"not saved: {self.saver.error}", warning=True)
            self._save_warned = True
        elif self._save_warned:
            self.status.end("save")
            self._save_warned = False
        if self.saver.restored:  # a kept previous version restored: where the file went
            self.status.say(self.saver.restored)
            self.saver.restored = ""
        self._update_saved_label()

    def _update_saved_label(self) -> None:
        """When the session was last saved, or (amber) that its last save failed."""
        text, tip = self.saver.label(time.time())
        warn = self.saver.unsaved
        self.saved_label.setText(f"{WARNING_SYMBOL} {text}" if warn else text)
        style = f"color: {WARNING_TEXT_COLOUR.name()}" if warn else ""
        if self.saved_label.styleSheet() != style:  # this runs every second
            self.saved_label.setStyleSheet(style)
        self.saved_label.setToolTip(tip)

    # -- saving elsewhere ---------------------------------------------------------------
    def choose_save_as(self) -> bool:
        """Ctrl+Shift+S: save the session to a file the operator picks; True if saved."""
        if self.model is None:
            return False
        current = self.saver.path or Path("session.json")
        if isinstance(self.saver.error, SessionChangedError):  # another window's: beside it
            start_at = str(free_name_beside(current))
        else:  # a failing save's folder is likely to fail again: start from home then
            start_at = str(Path.home() / current.name if self.saver.unsaved else current)
        path, _ = QFileDialog.getSaveFileName(self, "Save session as", start_at,
                                              "SpeechCal sessions (*.json)")
        return bool(path) and self.save_session_as(Path(path))

    def save_session_as(self, path: Path) -> bool:
        """Save to ``path`` (``.json`` added) and autosave there from now on."""
        assert self.model is not None and self.inputs is not None
        path = path if path.suffix == ".json" else path.with_name(path.name + ".json")
        try:
            self.saver.save_as(self.model.session, path)
        except SessionFileError as exc:
            self.status.end("save", f"not saved: {exc}", warning=True)
            if not self.property("headless"):
                QMessageBox.warning(self, "SpeechCal", str(exc))
            return False
        self.inputs.session_path = self.saver.path  # a link's target
        self.status.end("save", f"session saved as {path}")
        self._save_warned = False
        self._update_saved_label()
        return True

    def _may_drop_unsaved(self) -> bool:
        """True when nothing is unsaved, or the operator saved it elsewhere or lets it go."""
        self.saver.flush()  # the saves under way tell
        if not self.saver.unsaved:
            return True
        choice = self.ask_unsaved(f"The latest decisions are not saved: {self.saver.error}")
        if choice == "save_as":
            return self.choose_save_as()
        return choice == "discard"

    def _ask_unsaved(self, text: str) -> str:
        """The dialog behind :attr:`ask_unsaved` (none in a headless window: discard)."""
        if self.property("headless"):
            return "discard"
        box = QMessageBox(QMessageBox.Icon.Warning, "SpeechCal", text, parent=self)
        box.setInformativeText("Save them to another file before they are lost?")
        save = box.addButton("Save as…", QMessageBox.ButtonRole.AcceptRole)
        discard = box.addButton("Discard", QMessageBox.ButtonRole.DestructiveRole)
        box.addButton(QMessageBox.StandardButton.Cancel)
        box.setDefaultButton(save)
        run_modal = box.exec  # Qt's modal loop (QDialog.exec), not Python's exec
        run_modal()
        clicked = box.clickedButton()
        return "save_as" if clicked is save else "discard" if clicked is discard else "cancel"

    def show_camera_alone(self, number: int) -> None:
        """Keys 1-9: camera ``number`` alone, or the grid again; a number past the
        session's cameras says so (the key seemed to do nothing)."""
        if self.model is None or self.grid.toggle_camera(number):
            return
        cameras = len(self.grid.tiles)
        keys = "key 1 shows it" if cameras == 1 else f"keys 1-{min(cameras, 9)} show one"
        self.status.say(f"no camera {number}: this session has {counted(cameras, 'camera')} "
                        f"({keys} alone)")

    def _leave_enlarged(self) -> None:
        if self.model is not None and self.grid._enlarged:
            self.grid.toggle_enlarged()

    # -- drag and drop ------------------------------------------------------------------
    def dragEnterEvent(self, event: QDragEnterEvent) -> None:
        if event.mimeData().hasUrls():
            event.acceptProposedAction()

    def dropEvent(self, event: QDropEvent) -> None:
        request = drop_request([u.toLocalFile() for u in event.mimeData().urls()])
        if request is None:
            self.status.say("Drop a recording together with its audio file, or a session file")
        else:
            self.open(**request)

    def background_tasks(self) -> list[BackgroundTask]:
        """The window's work running on worker threads (opening, export, re-scoring,
        checks, search)."""
        tasks = [self.task, self.exporter.task, self.rescorer.task, self.checker.task,
                 self.similar.task, self.detector.task]
        return [t for t in tasks if t is not None]

    def closeEvent(self, event: QCloseEvent) -> None:
        if not self._may_drop_unsaved():
            event.ignore()
            return
        if self.model is not None and not self.saver.unsaved:
            self.model.save_place()  # the session opens again at the set shown now
            self.saver.flush()  # written before the window goes
        # background work stops and reports nothing more: a late result would change (and
        # save) a session the operator has left, or start more work for it
        for task in self.background_tasks():
            task.abandon()
        self.transport.shutdown()
        self.exporter.shutdown()
        self.rescorer.shutdown()
        self.checker.shutdown()
        self.similar.shutdown()
        self.detector.shutdown()
        # a recording closes once no frame decode reads it (at once, or as the decode
        # still running ends: the window does not wait for it)
        loaders = {id(lo.source): lo for lo in self._old_loaders}
        if self.loader is not None:
            loaders[id(self.loader.source)] = self.loader
        for inputs in [*([self.inputs] if self.inputs is not None else []), *self._retired]:
            loader = loaders.get(id(inputs.source))
            if loader is not None:
                loader.shutdown(then=inputs.close)
            else:
                inputs.close()
        self._retired.clear()
        self._old_loaders.clear()
        super().closeEvent(event)
