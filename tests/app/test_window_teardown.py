"""A window destroyed while its background work runs: nothing is delivered to it, nothing
is logged or raised; a recording closes only once no frame decode reads it."""

from __future__ import annotations

import gc
import threading

import pytest
from PySide6.QtCore import QCoreApplication, QEvent, QThreadPool

import app.main_window
from app.main_window import ReviewWindow


def test_window_destroyed_while_opening_gets_nothing_and_logs_nothing(
        qtbot, truth_session_file, monkeypatch: pytest.MonkeyPatch, capfd) -> None:
    release = threading.Event()
    load = app.main_window.load_for_review

    def gated(**kw):
        kw["progress"]("held", 0.1)
        release.wait(30)
        kw["progress"]("going on", 0.5)
        return load(**kw)

    monkeypatch.setattr(app.main_window, "load_for_review", gated)
    win = ReviewWindow()
    win.setProperty("headless", True)
    win.open(session_path=str(truth_session_file))
    task, label = win.task, win.status.text
    qtbot.waitUntil(lambda: "held" in label.text(), timeout=10_000)
    win.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)
    del win
    gc.collect()
    with qtbot.captureExceptions() as raised:
        release.set()
        assert task.done.wait(30)
        QThreadPool.globalInstance().waitForDone(10_000)
        for _ in range(5):
            QCoreApplication.processEvents()
    assert raised == []
    err = capfd.readouterr().err
    assert "deleted" not in err and "Traceback" not in err, err


class _SlowSource:
    """A recording whose decodes wait for the test; records reads after closing."""

    def __init__(self, source) -> None:
        self.source, self.entered, self.release = source, threading.Event(), threading.Event()
        self.closed = False
        self.read_after_close = False

    def frame(self, stream, index):
        self.entered.set()
        self.release.wait(30)
        self.read_after_close |= self.closed
        return self.source.frame(stream, index)

    def close(self) -> None:
        self.closed = True
        self.source.close()

    def __getattr__(self, name):
        return getattr(self.source, name)


def test_closing_while_a_frame_decodes_closes_the_recording_after_it(qtbot, window) -> None:
    slow = _SlowSource(window.inputs.source)
    window.loader.source = slow
    window.inputs.source = slow
    stream = next(iter(window.model.streams))
    window.loader.request([(stream, 3), (stream, 4), (stream, 5)])
    assert slow.entered.wait(10)
    window.close()  # does not wait for the decode
    assert window.loader.reading() and not slow.closed
    slow.release.set()
    qtbot.waitUntil(lambda: slow.closed, timeout=10_000)
    window.loader.pool.waitForDone(10_000)
    assert not slow.read_after_close  # the queued decodes never started
