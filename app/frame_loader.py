"""Decodes frames on a worker pool and hands QImages back to the UI thread."""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QRunnable, QThreadPool, Signal
from PySide6.QtGui import QImage

from app.qt_image import to_qimage

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource


class _Signals(QObject):
    loaded = Signal(int, str, int, QImage)  # generation, stream, index, image
    failed = Signal(int, str, int, str)
    stopped = Signal()


class _DecodeJob(QRunnable):
    def __init__(self, loader: FrameLoader, generation: int, stream: str, index: int) -> None:
        super().__init__()
        self.loader, self.generation, self.stream, self.index = loader, generation, stream, index

    def run(self) -> None:
        if not self.loader._begin_decode(self.generation):
            return  # the playhead moved on before this job started, or the loader stopped
        try:
            self._decode()
        finally:
            self.loader._end_decode()

    def _decode(self) -> None:
        try:
            frame = self.loader.source.frame(self.stream, self.index)
            if frame is None:
                raise ValueError("frame could not be decoded")
            image = to_qimage(frame)
        except Exception as exc:  # a bad frame must not take the window down
            self.loader.signals.failed.emit(self.generation, self.stream, self.index, str(exc))
            return
        self.loader.signals.loaded.emit(self.generation, self.stream, self.index, image)


class FrameLoader(QObject):
    """Latest-request-wins frame decoding with a small cache of decoded images."""

    loaded = Signal(str, int, QImage)
    failed = Signal(str, int, str)
    #: after :meth:`shutdown`, the last running decode has let go of the source
    stopped = Signal()

    def __init__(self, source: FrameSource, cache_size: int = 256,
                 parent: QObject | None = None) -> None:
        super().__init__(parent)
        self.source = source
        self.generation = 0
        self.pending = 0
        self.signals = _Signals()
        self.signals.loaded.connect(self._on_loaded)
        self.signals.failed.connect(self._on_failed)
        self.signals.stopped.connect(self.stopped)
        self.pool = QThreadPool(self)
        self.pool.setMaxThreadCount(2)
        self._cache: OrderedDict[tuple[str, int], QImage] = OrderedDict()
        self._cache_size = cache_size
        self._lock = threading.Lock()  # guards the three below (worker threads read them)
        self._reading = 0  # decodes reading the source right now
        self._stopped = False
        self._after_stop: list[Callable[[], None]] = []

    def request(self, wanted: list[tuple[str, int]]) -> None:
        """Load these (stream, index) frames; cached ones are delivered at once."""
        self.generation += 1
        self.pool.clear()
        self.pending = 0
        for stream, index in wanted:
            image = self._cache.get((stream, index))
            if image is not None:
                self._cache.move_to_end((stream, index))
                self.loaded.emit(stream, index, image)
            else:
                self.pending += 1
                self.pool.start(_DecodeJob(self, self.generation, stream, index))

    def _on_loaded(self, generation: int, stream: str, index: int, image: QImage) -> None:
        self._cache[(stream, index)] = image
        while len(self._cache) > self._cache_size:
            self._cache.popitem(last=False)
        if generation == self.generation:
            self.pending = max(0, self.pending - 1)
            self.loaded.emit(stream, index, image)

    def _on_failed(self, generation: int, stream: str, index: int, message: str) -> None:
        if generation == self.generation:
            self.pending = max(0, self.pending - 1)
            self.failed.emit(stream, index, message)

    def idle(self) -> bool:
        """True when no requested frame is still being decoded."""
        return self.pending == 0

    def reading(self) -> bool:
        """True while a decode reads the source (after :meth:`shutdown` too)."""
        with self._lock:
            return self._reading > 0

    def shutdown(self, then: Callable[[], None] | None = None) -> None:
        """Stop for good without waiting: no new decode starts, and ``then()`` (e.g. closing
        the recording) runs once no decode reads the source any more: at once when none
        does, else on the worker thread as the last one ends (then :attr:`stopped`)."""
        self.pool.clear()
        with self._lock:
            self._stopped = True
            self.generation += 1
            if self._reading and then is not None:
                self._after_stop.append(then)
                then = None
        if then is not None:
            then()

    def _begin_decode(self, generation: int) -> bool:
        with self._lock:
            if self._stopped or generation != self.generation:
                return False
            self._reading += 1
            return True

    def _end_decode(self) -> None:
        with self._lock:
            self._reading -= 1
            last = self._stopped and self._reading == 0
            after, self._after_stop = (self._after_stop, []) if last else ([], self._after_stop)
        for fn in after:
            fn()
        if last:  # through the Python-owned ``signals``: this loader may be deleted by now
            self.signals.stopped.emit()
