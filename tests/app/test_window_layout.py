"""What QA saw on the screenshot: the heard word hides no camera, the selected row keeps
its decision colour, the key hints fit on one line."""

from __future__ import annotations

from PySide6.QtCore import QPoint, QRect, Qt
from set_list_cells import cell_rect

from app.set_table import column
from app.style import DECISION_TEXT_COLOURS


def _area_in(widget, ancestor) -> QRect:
    return QRect(widget.mapTo(ancestor, QPoint(0, 0)), widget.size())


def test_heard_word_is_drawn_beside_the_tiles_not_over_them(window) -> None:
    grid = window.grid
    band = grid.word_band
    assert band.isVisible() and band.height() > 20 and grid.word == "capture"
    for tile in grid.tiles.values():
        assert not _area_in(band, grid).intersects(_area_in(tile, grid))


def _pixels_like(image, rect, colour, tolerance: int = 40) -> int:
    count = 0
    for y in range(rect.top(), rect.bottom()):
        for x in range(rect.left(), rect.right()):
            c = image.pixelColor(x, y)
            if (abs(c.red() - colour.red()) + abs(c.green() - colour.green())
                    + abs(c.blue() - colour.blue())) < tolerance:
                count += 1
    return count


def test_selected_row_still_shows_its_decision_colour(qtbot, window) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.keyClick(window, Qt.Key.Key_J)  # back to the accepted set
    table = window.table
    assert [i.row() for i in table.selectedIndexes()][:1] == [0]
    image = table.viewport().grab().toImage()
    rect = cell_rect(table, 0, column("decision"))
    assert _pixels_like(image, rect, DECISION_TEXT_COLOURS["accepted"]) > 10


def test_key_hints_fit_on_one_line_at_1400_px(qtbot, window) -> None:
    window.resize(1400, 900)
    qtbot.waitUntil(lambda: window.width() == 1400)
    hints = window.help_line
    assert not hints.wordWrap()
    assert hints.text() == hints.full_text  # not elided at this width
    assert hints.fontMetrics().horizontalAdvance(hints.text()) <= hints.contentsRect().width()
    assert "T add · Del remove" in hints.full_text
    assert hints.full_text.endswith("double-click: whole session")
    assert ("a double-click (or the 'whole session' button) shows the whole session"
            in hints.toolTip())


def test_the_window_fits_1100_px_and_keeps_its_width_between_sets(qtbot, window) -> None:
    """The line under the grid (time, set, skew) shares its row with the transport
    buttons: a long text is cut, it never widens the window."""
    window.resize(1100, 700)
    qtbot.waitUntil(lambda: window.width() == 1100)
    for _ in range(len(window.model.session.sets)):
        qtbot.keyClick(window, Qt.Key.Key_K)
        assert window.width() == 1100
    assert window.info_line.toolTip().startswith("set #")  # the set leads, then the time
    assert " s from start (" in window.info_line.toolTip()
    window.resize(1024, 700)  # a small laptop screen: the set's skew still shows
    qtbot.waitUntil(lambda: window.width() == 1024)
    assert " ms" in window.info_line.text() and "skew" in window.info_line.text()


def test_the_waveform_keeps_its_height_in_the_smallest_window(qtbot, window) -> None:
    """At the window's least size the waveform was 30 px high, its set labels and the
    clap's cut off."""
    from app.main_window import WAVEFORM_MIN_HEIGHT

    hint = window.minimumSizeHint()
    window.resize(hint.width(), hint.height())
    qtbot.waitUntil(lambda: window.height() == max(hint.height(), window.minimumHeight()))
    assert window.waveform.height() >= WAVEFORM_MIN_HEIGHT


def test_word_band_says_what_was_heard_and_what_was_added_by_hand() -> None:
    """A set added with T showed "? “CAPTURE”" as if the word was heard there; between
    sets the band was an empty black bar."""
    from app.frame_grid import band_text

    assert band_text("capture", "accepted") == "✔ “CAPTURE”"
    assert band_text("capture", "undecided", "manual") == "? CAPTURE · added by hand"
    assert band_text("", None) == "no frame sets · T adds one at the playhead"
    assert band_text("", None, "", 10) == \
        "between frame sets · A / R / Del act on set #10 · J / K go to one"


def test_a_larger_system_font_keeps_every_column_of_the_list_in_view(
        qtbot, open_window, truth_session_file) -> None:
    """At 11-12 pt the decision column was cut off behind a scrollbar: the list's pane
    grows with the font."""
    from PySide6.QtGui import QFont
    from PySide6.QtWidgets import QApplication

    before = QApplication.font()
    font = QFont(before)
    font.setPointSizeF(12.0)
    QApplication.setFont(font)
    try:
        window = open_window(truth_session_file)
        window.resize(1400, 900)
        qtbot.waitUntil(lambda: window.width() == 1400)
        table = window.table
        qtbot.waitUntil(lambda: table.horizontalScrollBar().maximum() == 0, timeout=5_000)
    finally:
        QApplication.setFont(before)


def test_no_pane_can_be_dragged_away_to_nothing(window) -> None:
    """A splitter dragged to its end hid the waveform, or the list with its Accept and
    Reject buttons, behind a hair-thin handle."""
    from PySide6.QtWidgets import QSplitter

    splitters = window.findChildren(QSplitter)
    assert len(splitters) == 2
    for splitter in splitters:
        assert not splitter.childrenCollapsible()
        splitter.setSizes([0] + [10_000] * (splitter.count() - 1))
        assert min(splitter.sizes()) > 0


def test_the_window_opens_within_a_screen_smaller_than_its_first_size(qtbot) -> None:
    """At 1400 x 900 the window reached past a 1366 x 768 laptop screen, its waveform and
    offset buttons below the screen's edge; the test platform's screen is 800 x 800."""
    from app.main_window import WINDOW_SIZE, ReviewWindow

    window = ReviewWindow()
    window.setProperty("headless", True)
    qtbot.addWidget(window)
    assert (window.width(), window.height()) == WINDOW_SIZE  # a screenshot's size
    room = window.screen().availableGeometry()
    assert room.width() < WINDOW_SIZE[0] and room.height() < WINDOW_SIZE[1]
    window.fit_to_screen()
    window.show()
    assert 0 < window.frameGeometry().width() <= room.width()
    assert 0 < window.frameGeometry().height() <= room.height()
    assert window.width() >= room.width() - 50 and window.height() >= room.height() - 100


def test_the_grid_takes_the_columns_that_show_the_frames_largest(qtbot) -> None:
    """Seven cameras beside the list on a 1366 x 768 laptop were three rows of three,
    frames 110 px high beside two empty tiles; two rows of four show them 155 px high.
    The grid's least size stays the near-square grid's, so it never holds the window."""
    from app.frame_grid import FrameGrid, best_columns

    assert best_columns(7, 865, 415) == 4  # 2 rows of 4, not 3 of 3
    assert best_columns(9, 1230, 640) == 3  # a larger screen: 3 x 3 is as good
    assert best_columns(12, 865, 415) == 4 and best_columns(4, 865, 415) == 2
    assert best_columns(2, 865, 415) == 2 and best_columns(1, 865, 415) == 1

    grid = FrameGrid([f"/cam{k}/image_raw" for k in range(7)])
    qtbot.addWidget(grid)
    grid.show()
    least = grid.minimumSizeHint()

    def rows() -> int:
        layout = grid._layout
        return 1 + max(layout.getItemPosition(layout.indexOf(t))[0] for t in grid.tiles.values())

    grid.resize(865, 415 + grid.word_band.height() + 4)
    qtbot.waitUntil(lambda: grid.columns == 4)
    assert rows() == 2
    assert grid.minimumSizeHint() == least
    for tile in grid.tiles.values():
        assert tile.isVisible() and tile.height() > 190 and tile.width() > 200
    grid.resize(least)  # shrunk to its least size: back to three columns, all in view
    qtbot.waitUntil(lambda: grid.columns == 3)
    area = grid._tile_area.rect()
    for tile in grid.tiles.values():
        assert area.contains(tile.geometry())
    grid.toggle_enlarged("/cam6/image_raw")  # one camera alone, then the grid again
    assert grid.columns == 1
    grid.resize(865, 415 + grid.word_band.height() + 4)
    grid.toggle_enlarged()
    qtbot.waitUntil(lambda: grid.columns == 4)


def test_the_heard_word_fits_a_narrow_grid_instead_of_losing_both_ends(qtbot) -> None:
    """In a window half a 1920 px screen wide the band under four cameras cut "? CAPTURE
    · added by hand" at both ends, the decision's symbol with them."""
    from PySide6.QtGui import QFont, QFontMetrics

    from app.frame_grid import FrameGrid, band_text

    grid = FrameGrid(["/cam0/image_raw"])
    qtbot.addWidget(grid)
    band = grid.word_band
    text = band_text("capture", "undecided", "manual")
    big = QFont(band.font())
    big.setPixelSize(band.HEIGHT - 10)
    big.setBold(True)
    band.resize(1000, band.HEIGHT)  # room: as it was
    assert band.fitted(big, text) == (big, text)
    band.resize(440, band.HEIGHT)
    font, shown = band.fitted(big, text)
    assert shown == text and font.pixelSize() < big.pixelSize()  # smaller, whole
    assert QFontMetrics(font).horizontalAdvance(shown) <= 440 - 2 * band.PAD_PX
    band.resize(120, band.HEIGHT)  # at the least letter size: the end gives way
    font, shown = band.fitted(big, text)
    assert font.pixelSize() == band.LEAST_PX and shown.startswith("? CAP")
    assert shown.endswith("…") and QFontMetrics(font).horizontalAdvance(shown) <= 108


def test_key_hints_on_a_laptop_drop_whole_hints_not_half_a_word(qtbot, window) -> None:
    """At 1366 x 768 the line ended "waveform: wheel zoom, click seek, double-click:
    whole ses…"; it now ends with the last hint that fits whole, then "· …"."""
    from app.main_window import HINTS, SCREEN_MARGIN_PX

    window.resize(1366 - SCREEN_MARGIN_PX[0], 768 - SCREEN_MARGIN_PX[1])
    qtbot.waitUntil(lambda: window.width() == 1366 - SCREEN_MARGIN_PX[0])
    hints = window.help_line
    shown = hints.text()
    assert shown != HINTS and shown.endswith(" · …"), shown
    kept = shown.removesuffix(" · …")
    assert HINTS.startswith(kept + " · ")  # whole hints, from the first
    assert hints.fontMetrics().horizontalAdvance(shown) <= hints.contentsRect().width()
    assert "double-click a camera: enlarge" in shown
    assert hints.toolTip().startswith("Space play / pause")  # the whole list is there


def test_the_playhead_time_shows_whole_at_half_a_1920_px_screen(qtbot, window) -> None:
    """At 960 px the line under the grid was cut at "said at 00:04.39 · t …": the
    playhead's time, the one thing an operator must read there, was only in its
    tooltip. The set's place, skew and time said give way to it, the tooltip keeps all."""
    from PySide6.QtWidgets import QApplication

    window.resize(960, 1040)
    qtbot.waitUntil(lambda: window.width() == 960)
    model, line = window.model, window.info_line
    start_ns = model.time_range_ns()[0]
    for _ in range(len(model.session.sets) + 1):
        QApplication.processEvents()
        t = f"t = {(model.playhead_ns - start_ns) / 1e9:.3f} s"
        assert t in line.text(), line.text()
        assert line.fontMetrics().horizontalAdvance(line.text()) <= line.contentsRect().width()
        assert line.toolTip() == line.full_text and " s from start (" in line.full_text
        if model.set_at_playhead() is not None:  # which set, still said
            assert line.text().startswith(f"set #{model.set_at_playhead().id}")
        qtbot.keyClick(window, Qt.Key.Key_K)
    model.set_playhead(start_ns)  # between sets: the time alone, whole
    assert f"t = {0:.3f} s from start" in line.text()


def _luminance(colour) -> float:
    """WCAG relative luminance of a QColor."""
    def channel(v: int) -> float:
        c = v / 255
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
    return (0.2126 * channel(colour.red()) + 0.7152 * channel(colour.green())
            + 0.0722 * channel(colour.blue()))


def test_the_key_hints_are_dark_enough_to_read(window) -> None:
    """The help line under the waveform was Qt's "gray" on the light window: 3.4:1, under
    the 4.5:1 that small text needs. Its darkest pixel (a glyph's core) against the
    window now holds 4.5:1 at least."""
    image = window.help_line.grab().toImage()
    darkest = min((image.pixelColor(x, y) for y in range(image.height())
                   for x in range(image.width())), key=_luminance)
    background = window.help_line.palette().color(window.help_line.backgroundRole())
    lighter, darker = sorted((_luminance(background), _luminance(darkest)), reverse=True)
    assert (lighter + 0.05) / (darker + 0.05) >= 4.5
