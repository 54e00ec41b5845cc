"""Opening a session while another is still opening: the earlier opening is given up, and
a recording it opens anyway is closed (also when the window closed meanwhile)."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

import app.main_window
from speechcal_core.review.loading import ReviewInputs, load_for_review


@pytest.fixture
def slow_first(monkeypatch: pytest.MonkeyPatch
               ) -> Iterator[tuple[threading.Event, threading.Event, list, list]]:
    """The window's first opening, once running, waits until the test sets the gate, then
    opens its session even if cancelled meanwhile (as one past its last progress report
    does). Gives the event set once it runs, the gate, the sessions opened (in the order
    they are ready) and those closed."""
    running = threading.Event()
    gate = threading.Event()
    opened: list[ReviewInputs] = []
    closed: list[ReviewInputs] = []
    calls = 0

    def load(*, progress, **kwargs) -> ReviewInputs:
        nonlocal calls
        calls += 1
        if calls == 1:
            running.set()
            gate.wait(30)
            progress = None  # it no longer hears of the cancel
        inputs = load_for_review(progress=progress, **kwargs)
        opened.append(inputs)
        return inputs

    close = ReviewInputs.close

    def spy(inputs: ReviewInputs) -> None:
        closed.append(inputs)
        close(inputs)

    monkeypatch.setattr(app.main_window, "load_for_review", load)
    monkeypatch.setattr(ReviewInputs, "close", spy)
    yield running, gate, opened, closed
    gate.set()


def held(items: list, item: object) -> bool:
    """Whether ``item`` itself is in ``items``."""
    return any(i is item for i in items)


def test_a_second_open_gives_up_the_first_and_closes_the_recording_it_opens_anyway(
        qtbot, new_window, slow_first, truth_session_file: Path,
        searched_session_file: Path) -> None:
    running, gate, opened, closed = slow_first
    win = new_window()
    win.open(session_path=str(truth_session_file))
    assert running.wait(30)
    win.open(session_path=str(searched_session_file))
    qtbot.waitUntil(lambda: win.model is not None, timeout=30_000)
    second = win.inputs
    assert second is not None and second.session_path == searched_session_file
    gate.set()
    qtbot.waitUntil(lambda: len(opened) == 2 and held(closed, opened[1]), timeout=30_000)
    assert opened[1].session_path == truth_session_file
    qtbot.wait(200)  # the late result is not shown either
    assert win.inputs is second and not held(closed, second)
    assert win.task is None


def test_a_window_closed_while_opening_closes_the_recording_opened_after(
        qtbot, new_window, slow_first, truth_session_file: Path) -> None:
    running, gate, opened, closed = slow_first
    win = new_window()
    win.open(session_path=str(truth_session_file))
    assert running.wait(30)
    win.close()
    gate.set()
    qtbot.waitUntil(lambda: len(opened) == 1 and held(closed, opened[0]), timeout=30_000)
    assert win.inputs is None
