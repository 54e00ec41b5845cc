"""The calibration check in the window: a newer decision stops a check under way, and the
operator's own searches never wait behind one."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from PySide6.QtCore import Qt, QThreadPool

from speechcal_core.frames.analysis import checks_basis
from speechcal_core.session.store import load_session


@pytest.fixture
def one_shared_thread() -> Iterator[None]:
    """Qt's shared pool with a single thread, as on a one-core laptop."""
    pool = QThreadPool.globalInstance()
    threads = pool.maxThreadCount()
    pool.setMaxThreadCount(1)
    yield
    pool.setMaxThreadCount(threads)


def test_a_decision_during_a_check_cancels_it_and_the_next_check_lands(
    qtbot, open_window, searched_session_file: Path, checks_gate,
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    assert not model.checks_due()
    qtbot.keyClick(window, Qt.Key.Key_R)  # reject the first set: the checks are due
    qtbot.waitUntil(checks_gate.entered.is_set, timeout=5_000)
    first = checks_basis(model.session.sets)
    model.go_to_set(1)
    qtbot.keyClick(window, Qt.Key.Key_R)  # and the second, while that check runs
    second = checks_basis(model.session.sets)
    checks_gate.release.set()
    qtbot.waitUntil(lambda: not window.checker.busy(), timeout=30_000)

    assert checks_gate.runs == [(first, "cancelled"), (second, "taken")]
    assert window.checker.last_error == "" and not model.checks_due()
    window.saver.flush()  # the autosave is written off the UI thread
    assert load_session(searched_session_file).extra["checks_basis"] == second


def test_find_more_like_this_does_not_wait_for_a_running_check(
    qtbot, open_window, searched_session_file: Path, checks_gate, one_shared_thread,
) -> None:
    window = open_window(searched_session_file)
    qtbot.keyClick(window, Qt.Key.Key_R)
    qtbot.waitUntil(checks_gate.entered.is_set, timeout=5_000)
    qtbot.keyClick(window, Qt.Key.Key_S)
    assert window.status.running("similar")
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)  # check still held
    assert window.similar.last is not None and window.similar.last_error == ""
    assert window.checker.busy() and checks_gate.runs == []
    checks_gate.release.set()
    qtbot.waitUntil(lambda: not window.checker.busy(), timeout=30_000)
    assert checks_gate.runs == [(checks_basis(window.model.session.sets), "taken")]


def test_a_hand_edited_coverage_of_the_wrong_kind_is_named_on_opening(
    qtbot, new_window, searched_session_file: Path,
) -> None:
    """The calibration line formatted a camera's coverage as numbers: a string there
    raised in the window (a traceback on stderr, the line left stale). Such a file is
    refused on opening with the figure named, as a set's damaged sharpness is."""
    import json

    data = json.loads(searched_session_file.read_text())
    stream = next(iter(data["coverage"]))
    data["coverage"][stream]["progress"]["x"] = "wide"
    searched_session_file.write_text(json.dumps(data))
    window = new_window()
    with qtbot.captureExceptions() as raised:
        window.open(session_path=str(searched_session_file))
        qtbot.waitUntil(lambda: bool(window.load_error) or window.model is not None,
                        timeout=30_000)
    assert raised == []
    assert window.model is None
    said = window.open_problem.text()
    assert said.startswith(f"Could not open: {searched_session_file}: damaged session file")
    assert f"the coverage of {stream}: its progress x is 'wide', not a number" in said
    del data["coverage"]  # the fix the message offers
    searched_session_file.write_text(json.dumps(data))
    with qtbot.captureExceptions() as raised:
        window.open(session_path=str(searched_session_file))
        qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    assert raised == []
    assert "calibration check over" in window.check_label.text()


def test_the_check_line_wraps_no_unit_away_from_its_figure(qtbot, new_window,
                                                           searched_session_file) -> None:
    """On a 1366 x 768 screen the line wrapped as "RMS ≤ 0.22" / "px; 2 cameras…"."""
    import re

    window = new_window()
    window.resize(1350, 720)
    window.open(session_path=str(searched_session_file))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    qtbot.waitUntil(lambda: "RMS" in window.check_label.text(), timeout=30_000)
    text = window.check_label.text()
    assert window.check_label.wordWrap()
    assert "\u00a0px" in text and not re.search(r"\d (px|ms|s)\b|[≤≥] \d", text), text
