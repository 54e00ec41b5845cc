"""The review window opened on the truth session, as an operator sees it after loading."""

from __future__ import annotations

import gc
import threading
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from PySide6.QtCore import QCoreApplication, QEvent, QThreadPool

import speechcal_core.export
from app.main_window import ReviewWindow
from app.tasks import Cancelled
from speechcal_core.review.checks import ChecksRequest
from speechcal_core.review.rescore import RescoreRequest


@pytest.fixture(autouse=True)
def windows_deleted_when_the_test_ends(qapp) -> Iterator[None]:
    """The windows a test shows are deleted, and their Python wrappers collected, as the
    test ends. pytest-qt only closes them and asks for a deferred delete; a wrapper the
    garbage collector met later, inside another test's event loop, destroyed its window
    from there and hung in QObject's destructor on a Qt mutex (a fresh-clone CI run)."""
    yield
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    gc.collect()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)


@pytest.fixture
def new_window(qtbot) -> Callable[[], ReviewWindow]:
    """Makes a shown, headless window with nothing opened in it."""

    def make() -> ReviewWindow:
        win = ReviewWindow()
        win.setProperty("headless", True)
        qtbot.addWidget(win)
        win.show()
        return win

    return make


@pytest.fixture
def open_window(qtbot) -> Callable[[Path], ReviewWindow]:
    """Opens a session file in a shown window and waits for every tile's frame."""

    def open_(path: Path) -> ReviewWindow:
        win = ReviewWindow()
        win.setProperty("headless", True)
        qtbot.addWidget(win)
        win.show()
        win.open(session_path=str(path))
        qtbot.waitUntil(lambda: win.model is not None, timeout=30_000)
        qtbot.waitUntil(lambda: all(t.image is not None for t in win.grid.tiles.values()),
                        timeout=30_000)
        return win

    return open_


@pytest.fixture
def window(open_window, truth_session_file: Path) -> ReviewWindow:
    return open_window(truth_session_file)


@pytest.fixture
def gate(monkeypatch: pytest.MonkeyPatch) -> threading.Event:
    """Re-scoring waits on the worker thread until the test sets this event."""
    event = threading.Event()
    run = RescoreRequest.run

    def gated(self, source, progress=None):
        progress(self.text, 0.0)
        event.wait(30)
        return run(self, source, progress)

    monkeypatch.setattr(RescoreRequest, "run", gated)
    return event


@pytest.fixture
def export_gate(monkeypatch: pytest.MonkeyPatch) -> Iterator[threading.Event]:
    """The window's export waits on its worker thread until the test sets this event
    (with threads enough for re-scoring to run beside it on a small machine)."""
    event = threading.Event()
    export = speechcal_core.export.export_frame_sets

    def gated(*args, progress, **kwargs):
        progress("writing", 0.25)
        event.wait(30)
        return export(*args, progress=progress, **kwargs)

    monkeypatch.setattr(speechcal_core.export, "export_frame_sets", gated)
    pool = QThreadPool.globalInstance()
    threads = pool.maxThreadCount()
    pool.setMaxThreadCount(max(threads, 4))
    yield event
    event.set()
    pool.setMaxThreadCount(threads)


@dataclass
class ChecksGate:
    """Calibration checks that wait on their worker thread until :attr:`release` is set,
    and how each ran: ``(basis, "taken" | "cancelled")`` in :attr:`runs`."""

    entered: threading.Event = field(default_factory=threading.Event)
    release: threading.Event = field(default_factory=threading.Event)
    runs: list[tuple[str, str]] = field(default_factory=list)


@pytest.fixture
def checks_gate(monkeypatch: pytest.MonkeyPatch) -> Iterator[ChecksGate]:
    """The window's calibration checks wait until the test releases them (see ChecksGate)."""
    gate = ChecksGate()
    run = ChecksRequest.run

    def gated(self, progress=None):
        gate.entered.set()
        gate.release.wait(30)
        try:
            result = run(self, progress)
        except Cancelled:
            gate.runs.append((self.basis, "cancelled"))
            raise
        gate.runs.append((self.basis, "taken"))
        return result

    monkeypatch.setattr(ChecksRequest, "run", gated)
    yield gate
    gate.release.set()
