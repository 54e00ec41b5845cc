"""The window's frame-set list: quality columns with warnings, and the decision filter."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from set_list_cells import cell, cell_rect, cells

from app.set_table import column
from app.style import WARNING_SYMBOL, WARNING_TEXT_COLOUR
from speechcal_core.review.model import set_time_ns
from speechcal_core.session.store import load_session, save_session


def shown_rows(window) -> list[int]:
    return [r for r in range(window.table.model().rowCount()) if not window.table.isRowHidden(r)]


def selected_rows(window) -> list[int]:
    return sorted({i.row() for i in window.table.selectedIndexes()})


def click_filter(qtbot, window, name: str) -> None:
    qtbot.mouseClick(window.filter_buttons[name], Qt.MouseButton.LeftButton)


def test_quality_columns_show_the_worst_camera_and_warn_in_amber_with_a_symbol(
    open_window, truth_session_file: Path
) -> None:
    session = load_session(truth_session_file)
    first = session.sets[0]
    figures = [(0.92, 144, ()), (0.18, 96, ("blurred",)), (None, None, ())]
    session.replace_set(replace(first, frames=tuple(
        replace(f, sharpness=sharp, corners=corners, flags=flags)
        for f, (sharp, corners, flags) in zip(first.frames, figures, strict=True))))
    save_session(session, truth_session_file)
    window = open_window(truth_session_file)
    table = window.table
    sharp, corners = cell(table, 0, column("worst sharp")), cell(table, 0, column("fewest corners"))
    assert sharp.text == "▲ 0.18"
    assert sharp.colour == WARNING_TEXT_COLOUR
    assert corners.text == "96"
    assert corners.colour != WARNING_TEXT_COLOUR
    cam1 = first.frames[1].stream
    assert f"{cam1}: sharpness 0.18, 96 corners  ▲ blurred" in sharp.tooltip
    # nearest-frame sets carry no figures
    assert cell(table, 1, column("worst sharp")).text == "–"
    assert cell(table, 1, column("fewest corners")).text == "–"
    header = table.model().headerData(column("worst sharp"), Qt.Orientation.Horizontal,
                                      Qt.ItemDataRole.ToolTipRole)
    assert "relative to its frames of the board held still" in header



def test_skew_needs_two_frames(qtbot, truth_session_file: Path) -> None:
    """A set with one camera's frame (a one-camera session) has no skew: "–", not 0.0."""
    from app.set_table import SetTable

    first, second = load_session(truth_session_file).sets[:2]
    lone = replace(first, frames=tuple(f if k == 0 else replace(f, index=-1)
                                       for k, f in enumerate(first.frames)))
    table = SetTable()
    qtbot.addWidget(table)
    table.set_sets([lone, second], first.t_ns)
    assert cell(table, 0, column("skew ms")).text == "–"
    assert cell(table, 1, column("skew ms")).text == f"{second.skew_ns / 1e6:.1f}"

def test_sets_showing_the_same_frames_say_so_in_the_word_column(
        qtbot, truth_session_file: Path) -> None:
    """A false trigger in a real set's still hold takes its frames: the two rows looked
    alike, with nothing to say that they are one view."""
    from app.set_table import SetTable

    first, second, third = load_session(truth_session_file).sets[:3]
    twin = replace(third, frames=second.frames)
    table = SetTable()
    qtbot.addWidget(table)
    table.set_sets([first, second, twin], first.t_ns)
    word = column("word")
    assert cell(table, 0, word).text == "capture"
    assert cell(table, 1, word).text == f"▲ capture · same as #{twin.id}"
    assert cell(table, 2, word).text == f"▲ capture · same as #{second.id}"
    assert cell(table, 2, word).colour == WARNING_TEXT_COLOUR
    assert cell(table, 2, word).tooltip.startswith(
        f"▲ the same frames as set #{second.id}: two trigger words in one still hold")


def test_filter_buttons_and_f_hide_and_show_rows(qtbot, window) -> None:
    n = window.table.model().rowCount()
    window.advance_box.setChecked(False)  # the decided set stays current
    qtbot.keyClick(window, Qt.Key.Key_A)  # set 0 accepted
    qtbot.keyClick(window, Qt.Key.Key_K)
    qtbot.keyClick(window, Qt.Key.Key_R)  # set 1 rejected
    click_filter(qtbot, window, "undecided")
    assert window.model.filter == "undecided"
    assert shown_rows(window) == list(range(2, n))
    assert window.shown_label.text() == f"{n - 2} of {n}"
    click_filter(qtbot, window, "accepted")
    assert shown_rows(window) == [0]
    qtbot.keyClick(window, Qt.Key.Key_F)  # the next filter: rejected
    assert shown_rows(window) == [1]
    assert window.filter_buttons["rejected"].isChecked()
    assert not window.filter_buttons["accepted"].isChecked()
    assert selected_rows(window) == [1]  # the current set, shown again
    qtbot.keyClick(window, Qt.Key.Key_F)
    assert window.model.filter == "all" and shown_rows(window) == list(range(n))
    assert window.shown_label.text() == ""


def test_a_filter_that_hides_every_set_says_so_under_the_empty_list(qtbot, window) -> None:
    """An empty list under "accepted" before anything was accepted looked broken."""
    click_filter(qtbot, window, "accepted")
    assert shown_rows(window) == []
    assert window.no_sets_label.isVisible()
    assert window.no_sets_label.text().endswith(
        "no accepted sets: “all” (or F, which steps through the filters) shows every set")
    click_filter(qtbot, window, "all")
    assert not window.no_sets_label.isVisible()


def test_choosing_a_row_of_a_filtered_list_goes_to_that_set(qtbot, window) -> None:
    window.advance_box.setChecked(False)
    qtbot.keyClick(window, Qt.Key.Key_A)
    click_filter(qtbot, window, "undecided")
    assert 0 not in shown_rows(window) and selected_rows(window) == []
    target = shown_rows(window)[1]
    window.table.selectRow(target)
    model = window.model
    assert model.current == target
    assert model.playhead_ns == set_time_ns(model.session.sets[target])
    assert window.grid.word == model.session.sets[target].trigger.word


def test_accepting_under_the_undecided_filter_takes_the_set_out_of_view(qtbot, window) -> None:
    model = window.model
    click_filter(qtbot, window, "undecided")
    model.go_to_set(2)
    qtbot.keyClick(window, Qt.Key.Key_A)  # on to the next undecided set
    assert 2 not in shown_rows(window) and model.session.sets[2].decision == "accepted"
    assert model.current == 3 and selected_rows(window) == [3]
    assert window.counts_label.text().startswith("✔ 1 accepted")
    qtbot.keyClick(window, Qt.Key.Key_U)  # undo brings the set back, into view too
    assert 2 in shown_rows(window)
    assert model.current == 2 and selected_rows(window) == [2]


def test_sets_added_or_removed_while_filtered_keep_rows_and_sets_in_step(
    qtbot, window
) -> None:
    model = window.model
    n = window.table.model().rowCount()
    click_filter(qtbot, window, "accepted")  # none yet: every row hidden
    assert shown_rows(window) == [] and window.shown_label.text() == f"none of {n}"
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    model.set_playhead((a + b) // 2)
    qtbot.keyClick(window, Qt.Key.Key_T)  # a new undecided set, hidden by the filter
    assert window.table.model().rowCount() == n + 1 and shown_rows(window) == []
    qtbot.keyClick(window, Qt.Key.Key_A)
    assert shown_rows(window) == [1] and selected_rows(window) == [1]
    assert cell(window.table, 1, 0).text == str(model.session.sets[1].id)
    qtbot.keyClick(window, Qt.Key.Key_Delete)
    assert window.table.model().rowCount() == n and shown_rows(window) == []
    click_filter(qtbot, window, "all")
    assert shown_rows(window) == list(range(n))
    assert selected_rows(window) == [model.current]


def test_rewriting_the_list_keeps_unchanged_rows_and_fits_the_columns(
        qtbot, truth_session_file: Path) -> None:
    """Re-scoring and offset edits rewrite the list: only the rows that show something
    else are announced (and repainted), and the columns fit their texts (each cell
    written measured the whole table again: a 66-set list took 1.1 s on the window's
    thread)."""
    from app.set_table import SetTable

    sets = load_session(truth_session_file).sets
    table = SetTable()
    qtbot.addWidget(table)
    table.set_sets(sets, sets[0].t_ns)
    announced: list[tuple[int, int]] = []
    table.model().dataChanged.connect(
        lambda first, last, _roles: announced.append((first.row(), last.row())))
    changed = [sets[0], sets[1].with_decision("accepted"), *sets[2:]]
    table.set_sets(changed, sets[0].t_ns)
    assert announced == [(1, 1)]  # the unchanged rows are left alone
    assert cell(table, 1, column("decision")).text == "✔ accepted"
    width = table.fontMetrics().horizontalAdvance(cell(table, 1, column("word")).text)
    assert table.columnWidth(column("word")) >= width
    table.resize(600, 300)
    table.show()
    qtbot.waitUntil(table.isVisible)
    header, last = table.horizontalHeader(), table.model().columnCount() - 1
    assert header.sectionPosition(last) + header.sectionSize(last) >= \
        table.viewport().width() - 1  # the decision column takes the rest


def test_columns_follow_their_widest_text(qtbot, truth_session_file: Path) -> None:
    """A column widens when a wider text appears in it and narrows when the widest goes
    (a set at 100 minutes widens the time column), and a decision resizes none (the
    decision column, last, takes the rest)."""
    from app.set_table import SetTable

    sets = load_session(truth_session_file).sets
    table = SetTable()
    qtbot.addWidget(table)
    table.set_sets(sets, sets[0].t_ns)
    time_col = column("time")
    widths = [table.columnWidth(c) for c in range(table.model().columnCount() - 1)]
    resized: list[int] = []
    table.horizontalHeader().sectionResized.connect(lambda col, _old, _new: resized.append(col))
    table.update_row(1, sets[1].with_decision("accepted"))
    assert resized == [] and cell(table, 1, column("decision")).text == "✔ accepted"
    late = replace(sets[2], t_ns=sets[0].t_ns + 6000 * 10**9)
    table.set_sets([*sets[:2], late, *sets[3:]], sets[0].t_ns)
    assert cell(table, 2, time_col).text == "100:00.00"
    assert set(resized) == {time_col} and table.columnWidth(time_col) > widths[time_col]
    table.set_sets(sets, sets[0].t_ns)
    assert [table.columnWidth(c) for c in range(table.model().columnCount() - 1)] == widths


def test_fitting_the_columns_gives_qts_widths_without_reading_a_row(
        qtbot, truth_session_file: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The columns are as wide as Qt's own fitting makes them (every cell measured
    through the list's delegate), though fitting reads no row: each text shape is
    measured once (a hundred sets: 800 cells, each read through Python, on every
    refit)."""
    from PySide6.QtWidgets import QTableView

    from app.set_table import SetListModel, SetTable

    sets = load_session(truth_session_file).sets
    sets = [*sets, replace(sets[0], id=99, trigger=replace(sets[0].trigger, source="similar"))]
    table = SetTable()
    qtbot.addWidget(table)
    table.resize(1000, 300)  # room for every column (a narrow list narrows the word's)
    table.show()
    table.set_sets(sets, sets[0].t_ns)
    last = table.model().columnCount() - 1
    fitted = [table.columnWidth(col) for col in range(last)]
    for col in range(last):  # as Qt measures them
        QTableView.resizeColumnToContents(table, col)
    assert [table.columnWidth(col) for col in range(last)] == fitted
    reads: list[int] = []
    real = SetListModel.data
    monkeypatch.setattr(SetListModel, "data",
                        lambda self, index, role=0: reads.append(1) or real(self, index, role))
    for col in range(last):
        table.setColumnWidth(col, 5)
    table.fit_columns()
    assert [table.columnWidth(col) for col in range(last)] == fitted
    assert reads == []


def test_a_rewrite_shows_what_a_list_written_afresh_shows(
        qtbot, truth_session_file: Path) -> None:
    """Rows rewritten in place (re-scoring rewrites the whole list after each batch of
    sets) say what a list written afresh says: texts, tooltips and colours (a warning
    that comes and goes, a decision, a re-scoring mark)."""
    from app.set_table import SetTable

    sets = load_session(truth_session_file).sets
    table = SetTable()
    qtbot.addWidget(table)
    table.set_sets(sets, sets[0].t_ns, {sets[0].id})
    changed = [sets[0], sets[1].with_decision("rejected"), *sets[2:]]
    lost = replace(sets[2], frames=tuple(replace(f, index=-1) if k == 0 else f
                                         for k, f in enumerate(sets[2].frames)))
    for version in (changed, [*changed[:2], lost, *changed[3:]], sets, changed[:-1], sets):
        table.set_sets(version, sets[0].t_ns)
        fresh = SetTable()
        qtbot.addWidget(fresh)
        fresh.set_sets(version, sets[0].t_ns)
        assert cells(table) == cells(fresh)
    assert any(WARNING_SYMBOL in c.text for row in cells(fresh) for c in row) is False
    table.set_sets([*changed[:2], lost, *changed[3:]], sets[0].t_ns)
    assert any(WARNING_SYMBOL in c.text for c in cells(table)[2])


def test_the_current_row_stays_in_view_when_the_list_gets_shorter(qtbot) -> None:
    """Shrinking the window left the current set's row below the list's visible part."""
    from app.set_table import SetTable
    from speechcal_core.session.model import FrameChoice, FrameSet, Trigger

    sets = [FrameSet(i + 1, 10**18 + i * 10**9, Trigger("capture", i, i + 0.4),
                     (FrameChoice("/cam0/image_raw", i, 10**18 + i * 10**9, 0.9, 144),))
            for i in range(40)]
    table = SetTable()
    qtbot.addWidget(table)
    table.resize(480, 900)
    table.show()
    table.set_sets(sets, sets[0].t_ns)
    table.select_row(25)
    table.resize(480, 200)
    qtbot.waitUntil(lambda: table.viewport().height() < 200)
    qtbot.wait(50)
    rect = cell_rect(table, 25)
    assert table.viewport().rect().contains(rect)


def test_a_click_on_the_selected_row_goes_back_to_its_set(qtbot, window) -> None:
    """Scrubbed off the set, its row stays selected: clicking it returns to the set
    (a click on another row chooses that one, once)."""
    model, table = window.model, window.table
    model.go_to_set(1)
    a, b = (set_time_ns(s) for s in model.session.sets[1:3])
    model.set_playhead((a + b) // 2)
    chosen: list[int] = []
    table.set_chosen.connect(chosen.append)
    row_1 = cell_rect(table, 1).center()
    qtbot.mouseClick(table.viewport(), Qt.MouseButton.LeftButton, pos=row_1)
    assert chosen == [1] and model.playhead_ns == a
    row_2 = cell_rect(table, 2).center()
    qtbot.mouseClick(table.viewport(), Qt.MouseButton.LeftButton, pos=row_2)
    assert chosen == [1, 2] and model.current == 2


def test_a_long_word_cell_gives_way_to_the_decision_column(
        qtbot, truth_session_file: Path) -> None:
    """"▲ capture · similar · same as #1, #3" widened the word column until the frames
    and decision columns went out of view behind a scrollbar in a 1280 px window: the
    word column now narrows (the row's tooltip says it whole), down to its header."""
    from app.set_table import SetTable

    first, second, third = load_session(truth_session_file).sets[:3]
    similar = replace(second.trigger, source="similar")
    sets = [first, replace(second, frames=first.frames, trigger=similar),
            replace(third, frames=first.frames)]
    table = SetTable()
    qtbot.addWidget(table)
    table.resize(1000, 300)
    table.show()
    table.set_sets(sets, first.t_ns)
    word, decision = column("word"), column("decision")
    wide = table.columnWidth(word)
    assert cell(table, 1, word).text.endswith("same as #1, #3")
    table.resize(480, 300)  # the list's pane at its least width
    qtbot.waitUntil(lambda: table.columnWidth(word) < wide)
    assert table.horizontalScrollBar().maximum() == 0
    assert table.columnWidth(decision) >= table.sizeHintForColumn(decision)
    assert table.columnWidth(word) >= table.horizontalHeader().sectionSizeHint(word)
    assert cell(table, 1, word).tooltip.startswith("▲ the same frames as set #1, #3")
    table.resize(1000, 300)  # room again: the whole text
    qtbot.waitUntil(lambda: table.columnWidth(word) == wide)


def test_the_line_under_the_grid_counts_the_sets_the_filter_lists(qtbot, window) -> None:
    """Under a filter J/K step through the listed sets: "set #5 (2/14)" counted every set
    while the operator stepped through three."""
    model = window.model
    n = len(model.session.sets)
    window.advance_box.setChecked(False)
    qtbot.keyClick(window, Qt.Key.Key_R)  # set 0 rejected
    qtbot.keyClick(window, Qt.Key.Key_K)
    qtbot.keyClick(window, Qt.Key.Key_K)
    qtbot.keyClick(window, Qt.Key.Key_R)  # set 2 rejected
    assert f"({3}/{n}) · " in window.info_line.full_text
    click_filter(qtbot, window, "rejected")  # the current set is the second listed
    assert f"set #{model.current_set.id} (2/2 rejected) · " in window.info_line.full_text
    qtbot.keyClick(window, Qt.Key.Key_J)
    assert f"set #{model.current_set.id} (1/2 rejected) · " in window.info_line.full_text
    click_filter(qtbot, window, "accepted")  # hides every set, the current one too
    assert f"set #{model.current_set.id} (no accepted sets listed) · " \
        in window.info_line.full_text
    click_filter(qtbot, window, "undecided")
    assert f"set #{model.current_set.id} (not among the {n - 2} undecided) · " \
        in window.info_line.full_text
    qtbot.keyClick(window, Qt.Key.Key_K)  # on to the undecided sets
    assert f"(1/{n - 2} undecided) · " in window.info_line.full_text
    click_filter(qtbot, window, "all")
    assert f"(2/{n}) · " in window.info_line.full_text


def test_an_empty_list_shows_every_column_heading_without_a_scrollbar(
        qtbot, open_window, wrong_word_session_file: Path) -> None:
    """A session with no sets (no trigger word found) opened with every column at Qt's
    default 100 px: the list scrolled sideways, "frames" cut off and "decision" out of
    view, until a set was added."""
    window = open_window(wrong_word_session_file)
    table = window.table
    assert table.model().rowCount() == 0
    qtbot.wait(50)  # the layout settles
    header = table.horizontalHeader()
    widths = [header.sectionSize(c) for c in range(header.count())]
    assert sum(widths) <= table.viewport().width()
    assert not table.horizontalScrollBar().isVisible()
    assert all(header.sectionSize(c) >= header.sectionSizeHint(c)
               for c in range(header.count()))
    assert header.sectionSize(column("#")) < 60  # fitted to its heading, not 100 px
    assert window._list_panel.minimumWidth() >= table.least_width()  # never cut narrower
