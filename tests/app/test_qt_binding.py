"""Guards against Qt binding releases with known defects that crash the app."""

from __future__ import annotations

import sys

from PySide6.QtCore import QObject, Signal


class _Emitter(QObject):
    changed = Signal(int, str)


def test_signal_emit_keeps_python_bool_refcounts(qtbot) -> None:
    # PySide6 6.12.0 drops a reference to True on every emit(); on Python < 3.12 the
    # interpreter then aborts with "bool_dealloc" once enough signals were sent.
    emitter = _Emitter()
    received: list[int] = []
    emitter.changed.connect(lambda n, _s: received.append(n))
    before = sys.getrefcount(True)
    for n in range(200):
        emitter.changed.emit(n, "x")
    assert len(received) == 200
    assert abs(sys.getrefcount(True) - before) < 50
