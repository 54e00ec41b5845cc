"""A window destroyed while its background work runs: nothing is delivered to it, nothing
is logged or raised; a recording closes only once no frame decode reads it."""

from __future__ import annotations

import threading


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
