"""A camera tile's header: the stream and decision at the left, the caption or warning at
the right, never drawn over each other however narrow the tile."""

from __future__ import annotations

import math
from typing import ClassVar

import pytest
from PySide6.QtCore import QEvent, QPoint, QRectF, Qt
from PySide6.QtGui import QHelpEvent, QImage, QPainter
from PySide6.QtWidgets import QApplication, QToolTip

import app.frame_grid
from app.frame_grid import CameraTile
from app.style import DECISION_SYMBOLS, WARNING_SYMBOL

HEADER_BOTTOM = 22  # the header's height in CameraTile.paintEvent


class RecordingPainter(QPainter):
    """A painter that keeps where each text it draws ends up."""

    texts: ClassVar[list[tuple[str, QRectF]]] = []

    def drawText(self, *args) -> None:
        if len(args) == 3 and isinstance(args[0], QRectF):
            rect, flags, text = args
            RecordingPainter.texts.append((text, self.boundingRect(rect, flags, text)))
        super().drawText(*args)


def _header_texts(qtbot, monkeypatch: pytest.MonkeyPatch, width: int, decision: str | None,
                  caption: str = "", warning: str = "") -> list[tuple[str, QRectF]]:
    """Paint a tile ``width`` pixels wide; the texts drawn in its header, with their
    bounding boxes."""
    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    tile.resize(width, 200)
    image = QImage(8, 6, QImage.Format.Format_RGB32)
    image.fill(0)
    tile.show_image(image, caption)
    tile.set_state(decision, warning)
    monkeypatch.setattr(app.frame_grid, "QPainter", RecordingPainter)
    RecordingPainter.texts = []
    tile.grab()
    return [(text, rect) for text, rect in RecordingPainter.texts
            if rect.top() < HEADER_BOTTOM and text]


WIDTHS = [160, 200, 230, 260, 300, 360, 600]
STATES = [("rejected", "chosen frame", ""), ("accepted", "+12.3 ms", ""),
          ("undecided", "chosen frame", "blurred, few corners"), ("rejected", "", "no frame"),
          (None, "chosen frame", "")]


@pytest.mark.parametrize("width", WIDTHS)
@pytest.mark.parametrize(("decision", "caption", "warning"), STATES)
def test_header_texts_never_overlap(qtbot, monkeypatch: pytest.MonkeyPatch, width: int,
                                    decision: str | None, caption: str,
                                    warning: str) -> None:
    texts = _header_texts(qtbot, monkeypatch, width, decision, caption, warning)
    assert texts, "no header drawn"
    for n, (_, a) in enumerate(texts):
        assert a.left() >= 0 and a.right() <= width
        for _, b in texts[n + 1:]:
            assert not a.intersects(b), texts
    title = texts[0][0]
    assert title.startswith("/cam")  # the stream is named first, shortened last
    if decision:
        assert DECISION_SYMBOLS[decision] in title  # the decision never goes
    if warning:
        assert any(WARNING_SYMBOL in text for text, _ in texts[1:])  # at least its symbol


def test_a_wide_tile_shows_the_whole_header(qtbot, monkeypatch: pytest.MonkeyPatch) -> None:
    texts = _header_texts(qtbot, monkeypatch, 600, "rejected", "chosen frame")
    assert [text for text, _ in texts] == ["/cam0/image_raw  ✘ rejected", "chosen frame"]
    texts = _header_texts(qtbot, monkeypatch, 600, "undecided", "chosen frame", "blurred")
    assert [text for text, _ in texts] == ["/cam0/image_raw  ? undecided", "▲ blurred"]


def test_a_narrow_tile_drops_the_caption_before_the_decision(
        qtbot, monkeypatch: pytest.MonkeyPatch) -> None:
    # about a tile's width in a 1024 x 700 window with four cameras
    texts = _header_texts(qtbot, monkeypatch, 260, "rejected", "chosen frame")
    assert [text for text, _ in texts] == ["/cam0/image_raw  ✘ rejected"]


def test_a_narrow_tile_keeps_the_warning_before_the_decision_word(
        qtbot, monkeypatch: pytest.MonkeyPatch) -> None:
    """The border's colour and the set list say the decision; the warning is what only
    this tile tells (a 12-camera grid at 1920 px showed "? undecided" and "▲ no-t…")."""
    texts = _header_texts(qtbot, monkeypatch, 280, "undecided", "chosen frame",
                          "target not found")
    assert [text for text, _ in texts] == ["/cam0/image_raw  ?", "▲ target not found"]


def test_the_tooltip_gives_the_header_in_full(qtbot) -> None:
    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    tile.resize(160, 120)
    tile.show()
    tile.caption = "chosen frame"
    tile.set_state("undecided", "blurred")
    pos = QPoint(20, 10)
    QApplication.sendEvent(tile, QHelpEvent(QEvent.Type.ToolTip, pos, tile.mapToGlobal(pos)))
    assert QToolTip.text() == "/cam0/image_raw\n? undecided\n▲ blurred"
    QToolTip.hideText()
    tile.key = "1"  # in a grid: the key that shows it alone
    QApplication.sendEvent(tile, QHelpEvent(QEvent.Type.ToolTip, pos, tile.mapToGlobal(pos)))
    assert QToolTip.text().endswith("\nkey 1 or double-click: this camera alone")
    QToolTip.hideText()


def test_corner_markers_grow_with_the_corners_spacing_on_screen() -> None:
    """A 1920 px image shown enlarged had 1.5 px specks for markers; a dense board in a
    small tile keeps small ones that do not run together."""
    from app.frame_grid import MARKER_RADIUS_PX, corner_spacing, marker_radius

    grid = [(x * 40.0, y * 40.0) for x in range(6) for y in range(4)]
    assert corner_spacing(grid) == 40.0
    assert corner_spacing(grid[:1]) == 0.0
    assert marker_radius(40.0 * 0.3) == 4.0  # enlarged: 12 px apart on screen
    assert marker_radius(40.0 * 0.05) == MARKER_RADIUS_PX[0]  # 2 px apart
    assert marker_radius(40.0 * 2) == MARKER_RADIUS_PX[1]


def test_setting_corners_keeps_their_spacing_for_the_markers(qtbot) -> None:
    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    tile.corners = ((0.0, 0.0), (10.0, 0.0), (30.0, 0.0))
    assert tile.corners == ((0.0, 0.0), (10.0, 0.0), (30.0, 0.0))
    assert tile._corner_spacing == 10.0


def _green_share(qtbot, width: int) -> float:
    """The share of the board's inside (on screen, a 3 px rim left out) drawn in the
    markers' green: a 12x12 board of corners 8 image pixels apart on a grey 640x480
    image, in a tile ``width`` wide."""
    from PySide6.QtGui import QColor, QImage

    from app.frame_grid import MARKER_COLOUR

    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    image = QImage(640, 480, QImage.Format.Format_Grayscale8)
    image.fill(QColor(128, 128, 128))
    tile.show_image(image, "chosen frame")
    tile.corners = tuple((200.0 + 8 * x, 150.0 + 8 * y) for y in range(12) for x in range(12))
    tile.resize(width, width * 3 // 4 + 25)
    grabbed = tile.grab().toImage()
    header = 22
    scale = min((tile.width() - 6) / 640, (tile.height() - header - 3) / 480)
    left = 3 + ((tile.width() - 6) - 640 * scale) / 2
    top = header + ((tile.height() - header - 3) - 480 * scale) / 2
    xs = range(int(left + 200 * scale) + 3, int(left + 288 * scale) - 3)
    ys = range(int(top + 150 * scale) + 3, int(top + 238 * scale) - 3)
    inside = [grabbed.pixelColor(x, y) for x in xs for y in ys]
    green = sum(1 for c in inside if c.green() > 160 and c.red() < 120)
    assert inside and MARKER_COLOUR.green() > 160
    return green / len(inside)


def test_a_dense_board_in_a_small_tile_is_outlined_not_covered(qtbot) -> None:
    """Markers of corners a few screen pixels apart ran together into a green block that
    hid the board one checks for blur: there the board's outline is drawn instead."""
    small, large = _green_share(qtbot, 200), _green_share(qtbot, 1000)
    assert small < 0.02  # an outline: the board's image stays visible inside it
    assert large > 0.1  # 12 px apart: a marker on every corner

@pytest.mark.parametrize(("cameras", "least_width"), [(1, 160), (4, 160), (9, 149),
                                                       (12, 111), (16, 111), (25, 100)])
def test_many_cameras_shrink_the_tiles_least_size(qtbot, cameras: int,
                                                  least_width: int) -> None:
    """12 cameras made a window at least 1148 px wide (4 columns of 160 px tiles); more
    than two columns now share GRID_MIN_WIDTH_PX, while a tile keeps 100 px at least."""
    from app.frame_grid import GRID_MARGIN_PX, FrameGrid

    grid = FrameGrid([f"/cam{k}/image_raw" for k in range(cameras)])
    qtbot.addWidget(grid)
    assert {t.minimumWidth() for t in grid.tiles.values()} == {least_width}
    cols = math.ceil(math.sqrt(cameras))
    assert grid.minimumSizeHint().width() <= \
        cols * least_width + (cols - 1) * 4 + 2 * GRID_MARGIN_PX  # the focus frame's room
    grid.toggle_enlarged("/cam0/image_raw")  # one camera alone keeps the full least size
    assert grid.tiles["/cam0/image_raw"].minimumWidth() == 160


def test_a_narrow_tile_says_at_its_foot_that_it_shows_a_nearest_frame(qtbot) -> None:
    """While a set waits for re-scoring its tiles show the frames nearest its time; in a
    grid of six cameras the header had no room for that caption and nothing said so."""
    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    tile.caption = "nearest frame, re-scoring…"
    tile.set_state("undecided", "")
    assert tile.caption_at_foot(tile.caption) == ""  # the header shows it: said once
    assert tile.caption_at_foot("") == "nearest frame, re-scoring…"  # it had no room
    tile.caption = "chosen frame"
    assert tile.caption_at_foot("") == ""  # the usual case needs no word


def test_a_boards_spacing_is_computed_once_and_its_outline_only_where_drawn(
        qtbot, monkeypatch: pytest.MonkeyPatch) -> None:
    """A set step gives every tile its corners again: a board seen before (J then K)
    is not measured again, and the outline (a convex hull) is computed only for a tile
    small enough to draw it instead of the markers."""
    from PySide6.QtGui import QColor, QImage

    import app.frame_grid as frame_grid

    computed: list[str] = []
    for name in ("corner_spacing", "corner_outline"):
        real = getattr(frame_grid, name)
        monkeypatch.setattr(frame_grid, name, lambda c, real=real, name=name:
                            computed.append(name) or real(c))
    frame_grid.kept_corner_spacing.cache_clear()
    frame_grid.kept_corner_outline.cache_clear()
    tile = CameraTile("/cam0/image_raw")
    qtbot.addWidget(tile)
    image = QImage(640, 480, QImage.Format.Format_Grayscale8)
    image.fill(QColor(128, 128, 128))
    tile.show_image(image, "chosen frame")
    tile.resize(1000, 775)
    board = tuple((200.0 + 8 * x, 150.0 + 8 * y) for y in range(12) for x in range(12))
    other = tuple((x + 1.0, y) for x, y in board)
    for corners in (board, other, board, other):
        tile.corners = corners
        tile.grab()
    assert computed == ["corner_spacing", "corner_spacing"]  # markers: no outline
    assert tile._corner_spacing == 8.0
    tile.resize(200, 175)
    tile.grab()
    assert computed[-1] == "corner_outline"


@pytest.fixture(scope="module")
def twelve_camera_synth(tmp_path_factory: pytest.TempPathFactory):
    """A 8 s, 12-camera synthetic session with one trigger: (folder, truth)."""
    import json

    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    out = tmp_path_factory.mktemp("twelve") / "session"
    generate_session(out, SynthOptions(cameras=12, fisheye=0, duration=8.0, width=160,
                                       height=120, seed=21, claps=1, triggers=1))
    return out, json.loads((out / "truth.json").read_text())


#: the flags the 12-camera set's first cameras get (the rest none)
TWELVE_FLAGS = [("no-target",), ("blurred",), ("skew",), ("blurred", "no-target"),
                ("moving",)]


def open_twelve_flagged(open_window, twelve_camera_synth, tmp_path):
    """The twelve-camera session with its first set's frames flagged (TWELVE_FLAGS),
    opened in the window."""
    from dataclasses import replace

    from truth_sessions import truth_session

    from speechcal_core.session.store import save_session

    session = truth_session(*twelve_camera_synth)
    first = session.sets[0]
    frames = [replace(f, flags=TWELVE_FLAGS[k]) if k < len(TWELVE_FLAGS) else f
              for k, f in enumerate(first.frames)]
    session.sets[0] = replace(first, frames=tuple(frames))
    path = tmp_path / "twelve.json"
    save_session(session, path)
    return open_window(path)

def test_twelve_cameras_on_a_laptop_say_each_warning_in_words(
        qtbot, monkeypatch: pytest.MonkeyPatch, open_window, twelve_camera_synth,
        tmp_path) -> None:
    """Twelve cameras in a window on a 1366 x 768 screen: the tiles' headers cut "▲ target
    not found" to "▲ targ…" (the words only in the tooltip). Each warning now says its
    word in full or short ("▲ no board"), the cameras' names drop the "/image_raw" they
    all share, and every tile names its camera the same way."""
    from app.main_window import SCREEN_MARGIN_PX
    from speechcal_core.review.summary import FLAG_SHORT_WORDS, FLAG_WORDS

    window = open_twelve_flagged(open_window, twelve_camera_synth, tmp_path)
    window.resize(1366 - SCREEN_MARGIN_PX[0], 768 - SCREEN_MARGIN_PX[1])
    qtbot.waitUntil(lambda: window.grid.columns == 4)
    tiles = list(window.grid.tiles.values())
    assert all(t.width() < 230 for t in tiles)  # as narrow as they were

    monkeypatch.setattr(app.frame_grid, "QPainter", RecordingPainter)
    titles = []
    for k, tile in enumerate(tiles):
        RecordingPainter.texts = []
        tile.grab()
        texts = [(text, rect) for text, rect in RecordingPainter.texts
                 if rect.top() < HEADER_BOTTOM and text]
        assert texts[0][0] == f"/cam{k}  ? undecided" or texts[0][0] == f"/cam{k}  ?"
        titles.append(texts[0][0])
        notes = [text for text, _ in texts[1:]]
        flags = TWELVE_FLAGS[k] if k < len(TWELVE_FLAGS) else ()
        if not flags:
            continue
        assert len(notes) == 1 and "…" not in notes[0], notes
        words = [FLAG_WORDS.get(f, f) for f in flags], [FLAG_SHORT_WORDS.get(f, f) for f in flags]
        assert notes[0] in {f"{WARNING_SYMBOL} {', '.join(w)}" for w in words}, notes
        for a, b in ((texts[0][1], r) for _, r in texts[1:]):
            assert not a.intersects(b) and b.right() <= tile.width()


@pytest.mark.parametrize("size", [(960, 1040), (1024, 768)])
def test_twelve_cameras_in_a_small_window_say_each_warning_whole(
        qtbot, monkeypatch: pytest.MonkeyPatch, open_window, twelve_camera_synth,
        tmp_path, size: tuple[int, int]) -> None:
    """Twelve cameras at half a 1920 px screen (960 px) or on a 1024 px screen: a tile's
    header had room for "▲ no bo…" only, the words in its tooltip alone. Where the
    header has no room for them, it keeps the warning's symbol and the tile says the
    words at its foot, whole, over no other text."""
    from speechcal_core.review.summary import FLAG_SHORT_WORDS, FLAG_WORDS

    window = open_twelve_flagged(open_window, twelve_camera_synth, tmp_path)
    window.resize(*size)
    qtbot.waitUntil(lambda: window.size().toTuple() == size)
    tiles = list(window.grid.tiles.values())
    assert all(t.width() < 160 for t in tiles)

    monkeypatch.setattr(app.frame_grid, "QPainter", RecordingPainter)
    for k, tile in enumerate(tiles[:len(TWELVE_FLAGS)]):
        RecordingPainter.texts = []
        tile.grab()
        texts = [(text, rect) for text, rect in RecordingPainter.texts if text]
        flags = TWELVE_FLAGS[k]
        words = [FLAG_WORDS.get(f, f) for f in flags], [FLAG_SHORT_WORDS.get(f, f) for f in flags]
        said = {f"{WARNING_SYMBOL} {', '.join(w)}" for w in words}
        assert any(text in said for text, _ in texts), (size, texts)
        assert not any("…" in text for text, _ in texts), texts
        for n, (_, a) in enumerate(texts):
            assert a.left() >= 0 and a.right() <= tile.width() and a.bottom() <= tile.height()
            for _, b in texts[n + 1:]:
                assert not a.intersects(b), texts


def test_compact_names_keep_what_tells_the_cameras_apart() -> None:
    from app.frame_grid import compact_names

    assert compact_names(["/cam0/image_raw", "/cam10/image_raw"]) == \
        {"/cam0/image_raw": "/cam0", "/cam10/image_raw": "/cam10"}
    assert compact_names(["/l/image_raw/compressed", "/r/image_raw/compressed"]) == \
        {"/l/image_raw/compressed": "/l", "/r/image_raw/compressed": "/r"}
    assert compact_names(["/left/image", "/right/image_raw"]) == \
        {"/left/image": "/left/image", "/right/image_raw": "/right/image_raw"}
    assert compact_names(["/cam0/image_raw"]) == {"/cam0/image_raw": "/cam0/image_raw"}
    assert compact_names(["/image_raw", "/a/image_raw"]) == \
        {"/image_raw": "/image_raw", "/a/image_raw": "/a/image_raw"}  # nothing left of one


@pytest.mark.parametrize("width", [160, 180, 200, 240])
def test_a_tile_s_message_wraps_inside_its_borders(qtbot, monkeypatch: pytest.MonkeyPatch,
                                                   width: int) -> None:
    """In a narrow tile (the 12-camera grid at 960 or 1024 px), "this camera's nearest is"
    ran from edge to edge, under the amber warning border (drawn 3-5 px in): the message
    now wraps clear of it."""
    tile = CameraTile("/cam2/image_raw")
    qtbot.addWidget(tile)
    tile.resize(width, 150)
    message = "no frame for this set: this camera's nearest is -0.01 s away"
    tile.show_message(message)
    tile.set_state("undecided", "no frame")
    monkeypatch.setattr(app.frame_grid, "QPainter", RecordingPainter)
    RecordingPainter.texts = []
    tile.grab()
    [rect] = [rect for text, rect in RecordingPainter.texts if text == message]
    assert tile.width() == width
    assert rect.left() >= 6 and rect.right() <= width - 6


def test_pgdown_and_pgup_show_cameras_past_the_ninth_alone(
        qtbot, open_window, twelve_camera_synth, tmp_path) -> None:
    """Keys 1-9 show a camera alone; a twelve-camera session's /cam9-/cam11 could be
    enlarged only with the mouse. PgDown / PgUp step through every camera alone."""
    window = open_twelve_flagged(open_window, twelve_camera_synth, tmp_path)
    grid = window.grid
    names = list(grid.tiles)

    def alone() -> list[str]:
        return [n for n, t in grid.tiles.items() if t.isVisible()]

    qtbot.keyClick(window, Qt.Key.Key_9)
    assert alone() == [names[8]]
    for name in names[9:]:
        qtbot.keyClick(window, Qt.Key.Key_PageDown)
        assert alone() == [name]
    qtbot.keyClick(window, Qt.Key.Key_PageDown)  # round to the first
    assert alone() == [names[0]]
    qtbot.keyClick(window, Qt.Key.Key_PageUp)
    assert alone() == [names[-1]]
    qtbot.keyClick(window, Qt.Key.Key_Escape)
    assert len(alone()) == 12
    qtbot.keyClick(window, Qt.Key.Key_PageUp)  # from the grid: the last camera
    assert alone() == [names[-1]]
