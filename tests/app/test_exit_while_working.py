"""Leaving the window while background work runs: the work is cancelled and has stopped
before ``speechcal review`` returns (nothing runs on as Python exits), the window hears
nothing more of it, no traceback is printed, and the decisions are saved."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, Qt, QThreadPool, QTimer
from PySide6.QtWidgets import QApplication

import app.main
import app.main_window
from app.main_window import ReviewWindow
from app.rescore_action import RescoreAction
from app.tasks import Cancelled
from speechcal_core.cli import main
from speechcal_core.review.loading import load_for_review
from speechcal_core.review.model import ReviewModel
from speechcal_core.review.rescore import RescoreRequest
from speechcal_core.session.store import load_session, save_session


@pytest.fixture
def working(monkeypatch: pytest.MonkeyPatch) -> Iterator[SimpleNamespace]:
    """Re-scoring that goes on (reporting progress on its worker thread, so a cancel stops
    it) until the test releases it; says whether it started, ended and was cancelled."""
    state = SimpleNamespace(entered=threading.Event(), release=threading.Event(),
                            ended=threading.Event(), cancelled=False)
    run = RescoreRequest.run

    def held(self: RescoreRequest, source: Any, progress: Any = None) -> Any:
        state.entered.set()
        try:
            while not state.release.wait(0.05):
                progress(self.text, 0.0)
            return run(self, source, progress)
        except Cancelled:
            state.cancelled = True
            raise
        finally:
            state.ended.set()

    monkeypatch.setattr(RescoreRequest, "run", held)
    yield state
    state.release.set()
    QThreadPool.globalInstance().waitForDone(30_000)


def _edit_offset(path: Path) -> None:
    """Move the session's offset by a frame, as the window does: every set needs
    re-scoring when it is opened."""
    inputs = load_for_review(session_path=path)
    model = ReviewModel(inputs.session, inputs.source)
    model.nudge_offset_frame(1)
    save_session(model.session, path)
    inputs.close()
    assert model.rescore_ids()


def _no_traceback(err: str) -> None:
    assert "Traceback" not in err and "deleted" not in err, err


def test_screenshot_taken_while_rescoring_returns_with_nothing_running(
        searched_session_file: Path, tmp_path: Path, working: SimpleNamespace,
        monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    _edit_offset(searched_session_file)

    def settled(window: ReviewWindow, app_: Any, timeout_s: float) -> bool:  # mid-work
        deadline = time.monotonic() + 30
        while not working.entered.is_set() and time.monotonic() < deadline:
            app_.processEvents()
            time.sleep(0.02)
        return working.entered.is_set()

    monkeypatch.setattr(app.main, "wait_until_settled", settled)
    shot = tmp_path / "shot.png"
    code = main(["review", str(searched_session_file), "--screenshot", str(shot)])
    # re-scoring was cancelled and has ended: nothing is left to run on as Python exits
    assert working.ended.is_set() and working.cancelled
    assert code == 0 and shot.read_bytes()[:4] == b"\x89PNG"
    _no_traceback(capfd.readouterr().err)
    assert load_session(searched_session_file).sets  # the session file is whole


def test_closing_while_rescoring_stops_it_keeps_decisions_and_hears_nothing_more(
        qtbot, open_window, searched_session_file: Path, working: SimpleNamespace,
        monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    heard: list[str] = []
    for name in ("_finished", "_failed"):
        original = getattr(RescoreAction, name)

        def spy(self: RescoreAction, outcome: Any, original: Any = original,
                name: str = name) -> None:
            heard.append(name)
            original(self, outcome)

        monkeypatch.setattr(RescoreAction, name, spy)
    window = open_window(searched_session_file)
    qtbot.keyClick(window, Qt.Key.Key_A)  # a decision on the first set
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # an offset edit: re-scoring
    qtbot.waitUntil(working.entered.is_set, timeout=10_000)
    assert window.close()
    assert working.ended.is_set() and working.cancelled  # the close waited for it
    assert QThreadPool.globalInstance().waitForDone(10_000)
    for _ in range(5):
        QCoreApplication.processEvents()
    assert heard == []  # its cancel reached no closed window (nor started more work)
    saved = load_session(searched_session_file)
    assert saved.sets[0].decision == "accepted"
    assert saved.sync.offset_ns == window.model.session.sync.offset_ns
    _no_traceback(capfd.readouterr().err)


def test_closing_the_window_while_it_opens_returns_once_the_work_has_stopped(
        qtbot, truth_session_file: Path, monkeypatch: pytest.MonkeyPatch,
        capfd: pytest.CaptureFixture[str]) -> None:
    entered, ended = threading.Event(), threading.Event()

    def slow(**kw: Any) -> Any:
        entered.set()
        try:
            while True:  # a long step, reporting now and then: a cancel stops it
                kw["progress"]("held", 0.1)
                time.sleep(0.05)
        finally:
            time.sleep(0.5)  # letting go takes a moment (files close)
            ended.set()

    monkeypatch.setattr(app.main_window, "load_for_review", slow)
    qapp = QApplication.instance()

    closed: list[bool] = []

    def close_when_opening() -> None:  # the operator closes the window: the loop ends
        if entered.is_set():
            timer.stop()
            for widget in qapp.topLevelWidgets():
                if isinstance(widget, ReviewWindow) and widget.isVisible():
                    closed.append(widget.close())

    timer, limit = QTimer(), QTimer()
    timer.timeout.connect(close_when_opening)
    timer.start(50)
    limit.setSingleShot(True)
    limit.timeout.connect(qapp.quit)  # never hang the test run (another window open)
    timed_out: list[bool] = []
    limit.timeout.connect(lambda: timed_out.append(True))
    limit.start(30_000)
    try:
        code = app.main.run_review(session_path=str(truth_session_file))
    finally:
        timer.stop()
        limit.stop()
    assert closed == [True] and not timed_out and entered.is_set() and ended.is_set()
    assert code == 0  # returned only once the work had ended, after the operator's close
    _no_traceback(capfd.readouterr().err)


def test_a_screenshot_of_a_window_still_busy_says_so(
        searched_session_file: Path, tmp_path: Path, working: SimpleNamespace,
        monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    _edit_offset(searched_session_file)  # re-scoring starts, and is held
    monkeypatch.setattr(app.main, "SETTLE_S", 3.0)
    shot = tmp_path / "shot.png"
    code = main(["review", str(searched_session_file), "--screenshot", str(shot)])
    err = capfd.readouterr().err
    assert code == 1 and shot.exists()
    assert "still busy after 3 s (re-scoring" in err and "as it was then" in err
    _no_traceback(err)
