"""Autosave as the operator sees it: when the session was last saved, a save that fails
(warned, decisions kept, Save as… elsewhere), and closing with unsaved decisions."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog
from set_list_cells import cell

import app.main_window
from app.main_window import ReviewWindow
from app.session_saver import saved_text
from app.set_table import column
from app.status_line import QUIET_S
from app.style import WARNING_SYMBOL, WARNING_TEXT_COLOUR
from speechcal_core.session.store import load_session, save_session


@pytest.fixture
def session_in_folder(truth_session_file: Path) -> Path:
    """The truth session in a folder of its own (which a test can take away)."""
    folder = truth_session_file.parent / "sessions"
    folder.mkdir()
    path = folder / "review.json"
    save_session(load_session(truth_session_file), path)  # its paths relative to there
    return path


def block_saving(path: Path) -> None:
    """Make saving ``path`` really fail: its folder becomes a plain file (even for root)."""
    folder = path.parent
    folder.rename(folder.with_name(folder.name + "-moved"))
    folder.write_text("not a folder")


def unblock_saving(path: Path) -> None:
    folder = path.parent
    folder.unlink()
    folder.with_name(folder.name + "-moved").rename(folder)


def assert_warned(window: ReviewWindow) -> None:
    """The save's failure: its reason at the status line's left, in short at its right
    (the reason once: a failed save showed it twice)."""
    label = window.saved_label
    assert label.text() == f"{WARNING_SYMBOL} not saved · Ctrl+Shift+S saves elsewhere"
    assert f"{WARNING_SYMBOL} not saved: " in window.status_text.text()
    assert "cannot save the session" in window.status_text.text()
    assert "cannot save the session" in label.toolTip()
    assert WARNING_TEXT_COLOUR.name() in label.styleSheet()
    assert "Save session as" in label.toolTip()


def test_saved_text_says_how_long_ago_then_the_time() -> None:
    now = time.mktime((2026, 11, 20, 15, 0, 0, 0, 0, -1))
    assert saved_text(now - 1, now) == "saved just now"
    assert saved_text(now - 42, now) == "saved 42 s ago"
    assert saved_text(now - 600, now) == "saved 10 min ago"
    assert saved_text(now - 4 * 3600, now) == "saved at 11:00"
    assert saved_text(now - 3 * 86400, now) == "saved 2026-11-17 15:00"


def test_opened_session_says_when_it_was_last_saved(open_window, truth_session_file) -> None:
    stamp = time.time() - 600
    os.utime(truth_session_file, (stamp, stamp))
    window = open_window(truth_session_file)
    assert window.saved_label.text() == "saved 10 min ago"  # before anything saves it again
    assert str(truth_session_file) in window.saved_label.toolTip()


def test_failed_autosave_warns_keeps_decisions_and_clears_after_a_later_save(
    qtbot, open_window, session_in_folder: Path
) -> None:
    window = open_window(session_in_folder)
    block_saving(session_in_folder)
    with qtbot.captureExceptions() as raised:
        qtbot.keyClick(window, Qt.Key.Key_A)
        window.saver.flush()  # the save written off the UI thread
    assert raised == []
    assert window.model.session.sets[0].decision == "accepted"
    assert "accepted" in cell(window.table, 0, column("decision")).text
    assert_warned(window)
    window._update_saved_label()  # the clock's tick keeps the warning
    assert_warned(window)
    unblock_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_R)  # on the next set (A went on to it)
    window.saver.flush()  # the save written off the UI thread
    assert window.saved_label.text() == "saved just now"
    assert window.saved_label.styleSheet() == ""
    saved = load_session(session_in_folder)
    assert [s.decision for s in saved.sets[:2]] == ["accepted", "rejected"]


def test_a_session_opened_through_a_link_autosaves_into_the_link_target(
    qtbot, open_window, session_in_folder: Path
) -> None:
    """The operator's link (in a folder of its own, as a shortcut to the session) stays
    a link; the decision lands in the file it points to, with its .bak beside that."""
    shortcuts = session_in_folder.parent.parent / "shortcuts"
    shortcuts.mkdir()
    link = shortcuts / "today.json"
    link.symlink_to(session_in_folder)
    window = open_window(link)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert window.saved_label.text() == "saved just now"
    assert link.is_symlink() and link.resolve() == session_in_folder
    assert load_session(session_in_folder).sets[0].decision == "accepted"
    assert session_in_folder.with_name("review.json.bak").is_file()
    assert [p.name for p in shortcuts.iterdir()] == ["today.json"]


def test_a_file_another_window_saved_meanwhile_is_not_overwritten(
    qtbot, open_window, session_in_folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = open_window(session_in_folder)
    second = open_window(session_in_folder)  # the same session opened twice
    qtbot.keyClick(second, Qt.Key.Key_R)
    second.saver.flush()  # the save written off the UI thread
    assert load_session(session_in_folder).sets[0].decision == "rejected"
    first.activateWindow()  # the keys are the active window's shortcuts
    qtbot.waitUntil(first.isActiveWindow, timeout=5_000)
    qtbot.keyClick(first, Qt.Key.Key_A)
    first.saver.flush()  # the save written off the UI thread
    assert first.model.session.sets[0].decision == "accepted"  # kept in the window
    assert load_session(session_in_folder).sets[0].decision == "rejected"  # not overwritten
    assert first.saved_label.text() == f"{WARNING_SYMBOL} not saved · Ctrl+Shift+S saves elsewhere"
    assert "▲ not saved: review.json changed since it was read here (another window or " \
        "program saved it)" in first.status_text.text()  # the reason before the path
    assert "Save session as" in first.saved_label.toolTip()
    offered: list[str] = []  # Save as... starts beside the session, under a free name
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        lambda _parent, _title, start, _filter: offered.append(start) or ("", ""))
    qtbot.keyClick(first, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier
                   | Qt.KeyboardModifier.ShiftModifier)
    assert offered == [str(session_in_folder.with_name("review-2.json"))]
    second.activateWindow()
    qtbot.waitUntil(second.isActiveWindow, timeout=5_000)
    qtbot.keyClick(second, Qt.Key.Key_A)  # the window that wrote it last saves on
    second.saver.flush()  # the save written off the UI thread
    assert second.saved_label.text() == "saved just now"
    assert [s.decision for s in load_session(session_in_folder).sets[:2]] == [
        "rejected", "accepted"]


def test_a_file_saved_elsewhere_while_the_window_opens_it_is_not_overwritten(
    qtbot, open_window, session_in_folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    load = app.main_window.load_for_review

    def another_window_saves_meanwhile(**kw):
        inputs = load(**kw)  # read; the window has not taken it over yet
        decided = load_session(session_in_folder)
        decided.replace_set(decided.sets[1].with_decision("rejected"))
        save_session(decided, session_in_folder)
        return inputs

    monkeypatch.setattr(app.main_window, "load_for_review", another_window_saves_meanwhile)
    window = open_window(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert load_session(session_in_folder).sets[1].decision == "rejected"  # kept
    assert window.saved_label.text().startswith(WARNING_SYMBOL)


def test_a_failed_save_stays_on_the_status_line_beside_newer_work_until_a_save_works(
    qtbot, open_window, session_in_folder: Path
) -> None:
    window = open_window(session_in_folder)
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert "not saved: " in window.status_text.text()
    later = time.monotonic() + 10 * QUIET_S  # long after: other results give way, not it
    window.status.clock = lambda: later
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    window.saver.flush()  # the save written off the UI thread
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    assert "not saved: " in window.status_text.text()
    window.status.say("a plain message")
    assert "not saved: " in window.status_text.text()
    assert_warned(window)
    unblock_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_R)  # the next decision saves
    window.saver.flush()  # the save written off the UI thread
    assert "not saved" not in window.status_text.text()
    assert window.saved_label.text() == "saved just now"


def test_save_as_writes_the_decisions_elsewhere_and_autosaves_there(
    qtbot, open_window, session_in_folder: Path, tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch
) -> None:
    window = open_window(session_in_folder)
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    elsewhere = tmp_path / "rescued" / "copy"  # the suffix is added
    (tmp_path / "rescued").mkdir()
    monkeypatch.setattr(QFileDialog, "getSaveFileName",
                        lambda *a, **k: (str(elsewhere), "SpeechCal sessions (*.json)"))
    qtbot.keyClick(window, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier
                   | Qt.KeyboardModifier.ShiftModifier)
    rescued = elsewhere.with_suffix(".json")
    assert load_session(rescued).sets[0].decision == "accepted"
    assert window.saved_label.text() == "saved just now"
    assert window.inputs.session_path == rescued
    qtbot.keyClick(window, Qt.Key.Key_R)
    window.saver.flush()  # the save written off the UI thread
    assert load_session(rescued).sets[1].decision == "rejected"
    assert Path(load_session(rescued).recording[0]).exists()  # paths follow the new folder


def test_closing_with_unsaved_decisions_asks_save_as_discard_or_cancel(
    qtbot, open_window, session_in_folder: Path, tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch
) -> None:
    # Save as… whose file dialog is cancelled (no dialog ever blocks the test)
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: ("", ""))
    window = open_window(session_in_folder)
    asked: list[str] = []
    answers = ["cancel", "save_as", "save_as"]
    window.ask_unsaved = lambda text: asked.append(text) or (answers or ["discard"]).pop(0)
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert not window.close() and window.isVisible()
    assert "not saved" in asked[0] and str(session_in_folder) in asked[0]
    assert not window.close() and window.isVisible()  # the file dialog was cancelled
    target = tmp_path / "rescued.json"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(target), ""))
    assert window.close()
    assert load_session(target).sets[0].decision == "accepted"
    assert len(asked) == 3


def test_closing_after_discard_closes_and_saved_sessions_close_without_asking(
    qtbot, open_window, session_in_folder: Path, truth_session_file: Path
) -> None:
    window = open_window(session_in_folder)
    window.ask_unsaved = lambda text: "discard"
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert window.close()
    other = open_window(truth_session_file)
    other.ask_unsaved = lambda text: pytest.fail("asked although everything was saved")
    qtbot.keyClick(other, Qt.Key.Key_A)
    other.saver.flush()  # the save written off the UI thread
    assert other.close()


def test_opening_another_session_with_unsaved_decisions_asks_first(
    qtbot, open_window, session_in_folder: Path, truth_session_file: Path
) -> None:
    window = open_window(session_in_folder)
    answers = ["cancel", "discard"]
    window.ask_unsaved = lambda text: answers.pop(0) if answers else "discard"
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    window.open(session_path=str(truth_session_file))
    assert window.task is None  # kept: nothing is opened
    assert window.model.session.sets[0].decision == "accepted"
    window.open(session_path=str(truth_session_file))
    qtbot.waitUntil(lambda: window.inputs.session_path == truth_session_file, timeout=30_000)
    assert window.saved_label.styleSheet() == ""


def test_a_save_that_fails_while_another_session_loads_is_asked_about_again(
    qtbot, open_window, session_in_folder: Path, truth_session_file: Path,
    monkeypatch: pytest.MonkeyPatch
) -> None:
    window = open_window(session_in_folder)
    release = threading.Event()
    load = app.main_window.load_for_review

    def gated(**kw):
        release.wait(30)
        return load(**kw)

    monkeypatch.setattr(app.main_window, "load_for_review", gated)
    asked: list[str] = []
    window.ask_unsaved = lambda text: asked.append(text) or "cancel"
    window.open(session_path=str(truth_session_file))  # all saved: nothing to ask yet
    assert window.task is not None and asked == []
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)  # reviewing on while it loads; the save fails
    window.saver.flush()  # the save written off the UI thread
    release.set()
    qtbot.waitUntil(lambda: window.task is None, timeout=30_000)
    assert len(asked) == 1  # asked when the load ended, and "cancel" kept the session
    assert window.inputs.session_path == session_in_folder
    assert window.model.session.sets[0].decision == "accepted"


def test_leaving_after_a_failed_save_and_a_refused_close_says_so(
        qtbot, session_in_folder: Path, capfd: pytest.CaptureFixture[str]) -> None:
    from app.main import shut_down

    window = ReviewWindow()  # not the fixture's: shut_down deletes it
    window.setProperty("headless", True)
    window.show()
    window.open(session_path=str(session_in_folder))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    block_saving(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)  # not saved
    window.saver.flush()  # the save written off the UI thread
    window.ask_unsaved = lambda _text: "cancel"  # the operator stays ...
    shut_down(window)  # ... but speechcal review is ending
    assert "decisions are not saved" in capfd.readouterr().err
    unblock_saving(session_in_folder)


def test_a_closed_window_opens_the_session_again_at_the_set_it_showed(
    qtbot, open_window, session_in_folder: Path
) -> None:
    window = open_window(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_F)  # undecided sets only
    for _ in range(3):
        qtbot.keyClick(window, Qt.Key.Key_K)
    assert window.model.current == 3
    window.close()

    again = open_window(session_in_folder)
    assert (again.model.current, again.model.filter) == (3, "undecided")
    assert again.table.currentIndex().row() == 3
    assert again.filter_buttons["undecided"].isChecked()


def test_autosave_is_written_off_the_ui_thread_and_closing_waits_for_it(
    qtbot, open_window, session_in_folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The UI thread only takes a snapshot; the file is written on a worker (a slow
    disk does not freeze the window). Decisions made while a save is written are saved
    after it, and closing the window writes what is still waiting: nothing is lost."""
    import app.session_saver

    window = open_window(session_in_folder)
    window.saver.flush()
    threads: list[threading.Thread] = []
    real = app.session_saver.save_document

    def slow_disk(*args, **kwargs):
        threads.append(threading.current_thread())
        time.sleep(0.3)
        real(*args, **kwargs)

    monkeypatch.setattr(app.session_saver, "save_document", slow_disk)
    for k in (Qt.Key.Key_A, Qt.Key.Key_R, Qt.Key.Key_A):
        qtbot.keyClick(window, k)
    assert window.saver.busy()  # the keys did not wait for the disk
    assert window.close()
    assert threads and threading.main_thread() not in threads
    # four saves asked for (three decisions, the place on closing): those that waited
    # behind one being written were written as one
    assert len(threads) < 4
    assert [s.decision for s in load_session(session_in_folder).sets[:3]] == [
        "accepted", "rejected", "accepted"]
    assert not window.saver.busy() and window.saver.error is None


def test_ctrl_z_takes_back_a_decision_after_the_window_is_closed_and_opened_again(
    qtbot, open_window, session_in_folder: Path
) -> None:
    window = open_window(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    decided = window.model.last_decided
    window.close()

    again = open_window(session_in_folder)
    assert again.model.session.set_by_id(decided).decision == "accepted"
    assert again.undo_action.text() == f"&Undo decision on set {decided}"
    assert again.undo_action.isEnabled()
    qtbot.keyClick(again, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert again.model.session.set_by_id(decided).decision == "undecided"
    assert again.status_text.text() == f"undone: decision on set {decided}"
    again.saver.flush()
    assert load_session(session_in_folder).set_by_id(decided).decision == "undecided"


def test_undo_steps_that_no_longer_fit_the_file_are_dropped_and_the_window_says_so(
    qtbot, open_window, session_in_folder: Path
) -> None:
    window = open_window(session_in_folder)
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.close()
    session = load_session(session_in_folder)  # a hand edit of another set
    session.sets = [*session.sets[:-1], session.sets[-1].with_decision("rejected")]
    save_session(session, session_in_folder)

    again = open_window(session_in_folder)
    assert "the last review's undo steps were dropped: the frame sets or the audio " \
        "offset changed since they were saved" in again.status_text.text()
    assert not again.undo_action.isEnabled()
    assert again.model.session.sets[-1].decision == "rejected"


@pytest.mark.parametrize("opened", ["review.json.bak", "review.json.bak.1"])
def test_review_work_in_a_kept_previous_version_restores_it_as_the_session_file(
    qtbot, open_window, session_in_folder: Path, opened: str
) -> None:
    """Opened to go back to it, a kept previous version autosaved beside itself as
    review.json.bak.bak, and review.json went on holding the other version. Its review
    work is saved as review.json; the review.json it replaces is kept as a free .bak.N
    (never as .bak: that may be the version restored), and the status line says where."""
    folder = session_in_folder.parent
    older = load_session(session_in_folder)
    older.sets[-1] = older.sets[-1].with_decision("rejected")
    (folder / "review.json.bak").unlink(missing_ok=True)
    save_session(older, folder / opened, backup=False)
    current = session_in_folder.read_bytes()
    window = open_window(folder / opened)
    assert session_in_folder.read_bytes() == current  # opened only: nothing changed yet
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()
    kept = "review.json.bak.1" if opened == "review.json.bak" else "review.json.bak.2"
    assert not (folder / f"{opened}.bak").exists()
    assert (folder / kept).read_bytes() == current
    restored = load_session(session_in_folder)
    assert restored.sets[0].decision == "accepted" and restored.sets[-1].decision == "rejected"
    assert f"{opened} restored as review.json; the review.json it replaced is kept as " \
        f"{kept}" in window.status_text.text()
    assert window.saver.path == session_in_folder
    qtbot.keyClick(window, Qt.Key.Key_R)  # from now on saving goes on as usual
    window.saver.flush()
    assert load_session(folder / "review.json.bak").sets[0].decision == "accepted"
    assert (folder / kept).read_bytes() == current
    assert sorted(p.name for p in folder.iterdir()) == sorted(
        {"review.json", "review.json.bak", opened, kept})
