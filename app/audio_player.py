"""Sound for the review window: a stretch of the session's audio through the default audio
output (QtMultimedia's ``QAudioSink``, fed 16-bit mono PCM as it is read).

The samples come from :class:`~speechcal_core.audio.playback.PlaybackAudio`, read a
quarter second at a time on a worker thread (:class:`BlockReader`) and written to the
sink on the UI thread as it takes them; the UI thread never reads the file.
:meth:`AudioPlayer.heard_s` says how far the sound has got by what the sink reports it
has played (not by the clock: the sink holds :data:`BUFFER_S` ahead, and may take a while
to start), so the window's playhead can follow the sound. Without an audio output (no
sound device, as on CI, or QtMultimedia not loadable) nothing plays and
:meth:`AudioPlayer.play` says why through ``say``; everything else goes on without sound.
"""

from __future__ import annotations

import importlib
import queue
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

from PySide6.QtCore import QObject, QTimer

from speechcal_core.audio.playback import Clip, PlaybackAudio, heard_s
from speechcal_core.errors import SpeechCalError

#: what the sink holds ahead of the sound (latency of a restart, and slack for the UI thread)
BUFFER_S = 0.2
#: how often the sink is topped up from what the reader has read
FEED_MS = 15
#: blocks the reader keeps ready ahead of the sink
AHEAD = 3

_END = object()  # the reader got to the end of the stretch


class BlockReader:
    """Reads ``blocks`` on a worker thread, at most :data:`AHEAD` blocks ahead of what
    :meth:`take` has taken; no Qt here."""

    def __init__(self, blocks: Iterator[Clip], ahead: int = AHEAD) -> None:
        self._blocks = blocks
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=ahead)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="audio-reader", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            for clip in self._blocks:
                if not self._put(clip.to_bytes()):
                    return
            self._put(_END)
        except SpeechCalError as exc:  # the file went away or cannot be decoded
            self._put(exc)

    def _put(self, item: object) -> bool:
        while not self._stop.is_set():
            try:
                self._queue.put(item, timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def take(self) -> bytes | object | Exception | None:
        """The next block's bytes, ``_END``, the reader's error, or None (not read yet)."""
        try:
            return self._queue.get_nowait()
        except queue.Empty:
            return None

    def stop(self) -> None:
        self._stop.set()

    def join(self, timeout: float = 1.0) -> None:
        self._thread.join(timeout)


_multimedia: ModuleType | None = None
_multimedia_error = ""


def multimedia() -> tuple[ModuleType | None, str]:
    """``PySide6.QtMultimedia`` imported once per process, or None and why not."""
    global _multimedia, _multimedia_error
    if _multimedia is None and not _multimedia_error:
        try:
            _multimedia = importlib.import_module("PySide6.QtMultimedia")
        except (ImportError, OSError, RuntimeError) as exc:
            _multimedia_error = f"QtMultimedia cannot be loaded ({exc})"
    return _multimedia, _multimedia_error


class AudioPlayer(QObject):
    """Plays stretches of one audio file, one at a time (a new one stops the last)."""

    def __init__(self, parent: QObject, say: Callable[[str], None]) -> None:
        super().__init__(parent)
        self._say = say
        self._path: Path | None = None
        self._channel: int | None = None  # the file's channel the session uses
        self._audio: dict[int | None, PlaybackAudio] = {}  # per output rate (None: the file's)
        self._sink: Any = None
        self._io: Any = None
        self._reader: BlockReader | None = None
        self._pending = b""
        self._ended_at: float | None = None  # when the reader's last block was written
        self._start_s = 0.0  # audio time of the stretch's first sample
        self._rate = 1  # the sink's sample rate
        self._written = 0  # bytes handed to the sink
        self._timer = QTimer(self)
        self._timer.setInterval(FEED_MS)
        self._timer.timeout.connect(self._feed)
        #: why the last :meth:`play` gave no sound ("" when it plays)
        self.unavailable = ""
        #: the stretch (audio seconds) the last :meth:`play` was asked for
        self.asked: tuple[float, float | None] | None = None
        #: seconds from the last :meth:`play` to its first samples handed to the output
        self.start_latency_s: float | None = None
        self._asked_at = 0.0
        #: how many times :meth:`play` was asked (each restart counts)
        self.plays = 0

    @property
    def playing(self) -> bool:
        return self._sink is not None

    def heard_s(self) -> float | None:
        """Audio seconds the sound has got to (what the sink has played, the stretch's
        start until it starts); None when nothing plays."""
        sink = self._sink
        if sink is None:
            return None
        buffered = max(sink.bufferSize() - sink.bytesFree(), 0) // 2
        return heard_s(self._start_s, self._rate, self._written // 2, buffered,
                       sink.processedUSecs())

    def set_source(self, path: str | Path | None, channel: int | None = None) -> None:
        """The audio file to play from (another session was opened), and its channel the
        session uses (None: all mixed)."""
        self.stop()
        self._path = Path(path) if path else None
        self._channel = channel
        self._audio = {}

    def play(self, start_s: float, end_s: float | None = None, *, quiet: bool = False,
             lead_in: bool = False) -> bool:
        """Play audio seconds ``start_s`` .. ``end_s`` (default: to the end of the file);
        ``lead_in``: a start before the file plays silence until it starts.

        False when nothing plays; then ``say`` has been told why (unless ``quiet``).
        """
        self.stop()
        self._asked_at = time.monotonic()
        self.asked = (start_s, end_s)
        self.plays += 1
        self.start_latency_s = None
        if self._path is None:
            return self._cannot("this session has no audio file to play", quiet)
        try:
            if None not in self._audio:  # reads the file's header: AudioError naming it
                self._audio[None] = PlaybackAudio(self._path, channel=self._channel)
            qt, why = multimedia()
            if qt is None:
                return self._cannot(f"no audio output: {why}", quiet)
            device = qt.QMediaDevices.defaultAudioOutput()
            if device.isNull():
                return self._cannot("no audio output: no sound device found", quiet)
            audio, fmt = self._format(qt, device)
        except SpeechCalError as exc:
            return self._cannot(f"cannot play the audio: {exc}", quiet)
        if fmt is None:
            return self._cannot(f"no audio output: {device.description()} takes no 16-bit "
                                "mono sound", quiet)
        first = audio.start_index(start_s, lead_in)
        if first >= audio.end_index(end_s):
            return self._cannot("no sound here: the audio file holds audio seconds 0 to "
                                f"{audio.duration_s:.3f}", quiet)
        sink = qt.QAudioSink(device, fmt, self)
        sink.setBufferSize(2 * round(audio.rate * BUFFER_S))
        io = sink.start()
        if io is None or sink.error() != qt.QtAudio.Error.NoError:
            sink.stop()
            sink.deleteLater()
            return self._cannot(f"no audio output: {device.description()} could not be "
                                f"opened ({sink.error().name})", quiet)
        self._sink, self._io = sink, io
        self._start_s, self._rate = first / audio.rate, audio.rate
        self._reader = BlockReader(audio.blocks(start_s, end_s, lead_in=lead_in))
        self.unavailable = ""
        self._timer.start()
        return True

    def _format(self, qt: ModuleType, device: Any) -> tuple[PlaybackAudio, Any]:
        """The file read at a rate ``device`` takes, and the 16-bit mono format (None if
        it takes none)."""
        assert self._path is not None
        audio = self._audio[None]
        fmt = qt.QAudioFormat()
        fmt.setChannelCount(1)
        fmt.setSampleFormat(qt.QAudioFormat.SampleFormat.Int16)
        fmt.setSampleRate(audio.rate)
        if device.isFormatSupported(fmt):
            return audio, fmt
        rate = device.preferredFormat().sampleRate()
        fmt.setSampleRate(rate)
        if rate <= 0 or not device.isFormatSupported(fmt):
            return audio, None
        if rate not in self._audio:
            self._audio[rate] = PlaybackAudio(self._path, rate, self._channel)
        return self._audio[rate], fmt

    def _cannot(self, message: str, quiet: bool) -> bool:
        self.unavailable = message
        if not quiet:
            self._say(message)
        return False

    def _feed(self) -> None:
        """Top the sink up with what the reader has read; stop once all of it played."""
        sink, io, reader = self._sink, self._io, self._reader
        if sink is None or reader is None:
            return
        qt, _ = multimedia()
        assert qt is not None
        if sink.error() in (qt.QtAudio.Error.IOError, qt.QtAudio.Error.FatalError):
            self.stop()
            self._say(f"audio output failed ({sink.error().name})")
            return
        while True:
            if not self._pending:
                item = reader.take()
                if item is None:
                    break
                if item is _END:
                    self._ended_at = self._ended_at or time.monotonic()
                    break
                if isinstance(item, Exception):
                    self.stop()
                    self._say(f"cannot play the audio: {item}")
                    return
                self._pending = item  # type: ignore[assignment]
            free = sink.bytesFree() & ~1  # whole 16-bit samples
            if free <= 0:
                break
            written = io.write(self._pending[:free])
            if written <= 0:
                break
            if self.start_latency_s is None:
                self.start_latency_s = time.monotonic() - self._asked_at
            self._pending = self._pending[written:]
            self._written += written
        if self._ended_at is not None and not self._pending and (
                sink.state() == qt.QtAudio.State.IdleState
                or time.monotonic() - self._ended_at > BUFFER_S + 0.5):
            self.stop()  # the last samples have been played

    def stop(self) -> None:
        """Stop the sound (and the reading) at once."""
        self._timer.stop()
        if self._reader is not None:
            self._reader.stop()
            self._reader = None
        if self._sink is not None:
            self._sink.stop()
            self._sink.deleteLater()
        self._sink = self._io = None
        self._pending = b""
        self._ended_at = None
        self._written = 0

    def shutdown(self) -> None:
        """The window closes: stop, and forget the file."""
        self.set_source(None)
