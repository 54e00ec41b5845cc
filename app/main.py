"""Start the review window (``speechcal review`` / ``speechcal demo``)."""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.errors import SpeechCalError
from speechcal_core.fsutil import folder_write_problem

if TYPE_CHECKING:
    from PySide6.QtCore import QCoreApplication, QMessageLogContext, QtMsgType
    from PySide6.QtWidgets import QWidget

    from app.main_window import ReviewWindow
    from speechcal_core.sources.selection import StreamChoice
    from speechcal_core.speech.matching import TriggerSpec
    from speechcal_core.target import TargetSpec

#: how long the exit waits for cancelled background work to stop
STOP_WAIT_S = 30.0
#: how long --screenshot waits for loading, re-scoring and frames to finish
SETTLE_S = 120.0


class ScreenshotError(SpeechCalError):
    """The ``--screenshot`` file cannot be written (the CLI prints one line, exit 1)."""


def has_display() -> bool:
    """True when Qt can open a real window here (or offscreen rendering was asked for)."""
    if os.environ.get("QT_QPA_PLATFORM", "").startswith(("offscreen", "minimal")):
        return True
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


#: what Qt's offscreen platform says about itself, not about SpeechCal's window
OFFSCREEN_NOTICES = ("This plugin does not support propagateSizeHints()",)


def _drop_offscreen_notices() -> None:
    """Qt's offscreen platform warns that it cannot do window-manager hints; that reads
    like a problem with the window to someone rendering a screenshot, so it is dropped
    (every other Qt message still reaches stderr)."""
    from PySide6.QtCore import qInstallMessageHandler

    def handler(_kind: QtMsgType, _context: QMessageLogContext, message: str) -> None:
        if message not in OFFSCREEN_NOTICES:
            print(message, file=sys.stderr)

    qInstallMessageHandler(handler)


def run_review(
    *,
    session_path: str | None = None,
    recording: Sequence[str] | None = None,
    audio: str | None = None,
    new_session_path: str | None = None,
    screenshot: str | None = None,
    offer_demo: bool = True,
    triggers: TriggerSpec | None = None,
    channel: int | None = None,
    target: TargetSpec | None = None,
    streams: StreamChoice | None = None,
) -> int:
    """Open the window on the given input; with ``screenshot`` render it to PNG and exit
    (an input that fails to open writes no PNG: the error goes to stderr, exit 1).
    A recording's new session is saved at ``new_session_path`` (default: beside it),
    detects ``triggers`` in the audio's ``channel``, looks for the board ``target`` and
    uses the recording's ``streams`` (defaults: "capture", all channels, Kalibr's 6x6
    AprilGrid, all streams)."""
    if screenshot:
        check_screenshot_path(screenshot)  # before minutes of loading, not after
    if screenshot and not has_display():
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    if os.environ.get("QT_QPA_PLATFORM") == "offscreen":
        _drop_offscreen_notices()
    from PySide6.QtWidgets import QApplication

    from app.main_window import ReviewWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("SpeechCal")
    window = ReviewWindow()
    window.setProperty("headless", bool(screenshot))
    window.demo_button.setVisible(offer_demo)
    window.on_opened = lambda text: print(f"speechcal review: {text}", file=sys.stderr)
    if session_path or recording:
        window.open(session_path=session_path, recording=list(recording or []) or None,
                    audio=audio, new_session_path=new_session_path, triggers=triggers,
                    channel=channel, target=target, streams=streams)
    if not screenshot:  # a screenshot keeps the window's own size, whatever the screen
        window.fit_to_screen()
    window.show()
    try:
        if screenshot:
            ok = wait_until_settled(window, app, timeout_s=SETTLE_S)
            if window.load_error:  # a picture of "Could not open" is no screenshot of it
                print(f"speechcal review: error: {window.load_error}", file=sys.stderr)
                return 1
            save_screenshot(window, screenshot)
            print(f"wrote {screenshot}", file=sys.stderr)
            if not ok:
                print(f"speechcal review: the window was still busy after {SETTLE_S:.0f} s "
                      f"({window.status_text.text() or 'loading'}); the screenshot shows it "
                      "as it was then", file=sys.stderr)
            return 0 if ok else 1
        run_event_loop = app.exec  # Qt's event loop (QApplication.exec), not Python's exec
        return run_event_loop()
    finally:
        shut_down(window)


def shut_down(window: ReviewWindow, timeout_s: float = STOP_WAIT_S) -> None:
    """Close the window (if still open) and wait for the background work it cancels, then
    delete it: nothing may still run, or report to deleted Qt objects, as Python exits.

    Decisions are saved as they are made; when the last save failed and the operator
    declined to leave (the close was refused), stderr says they are not saved.
    """
    from PySide6.QtCore import QCoreApplication, QEvent

    from app.tasks import wait_for_all

    if window.isVisible() and not window.close():  # headless, or after the event loop
        for task in window.background_tasks():  # the close that abandons them was refused
            task.abandon()
        print("speechcal review: the last review decisions are not saved (saving failed)",
              file=sys.stderr)
    if not wait_for_all(timeout_s):
        print(f"speechcal review: background work still running after {timeout_s:.0f} s "
              "at exit", file=sys.stderr)
    # the stopped work's last reports (queued calls; dropped, they let go of its inputs)
    QCoreApplication.sendPostedEvents(None, QEvent.Type.MetaCall)
    window.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete)


def wait_until_settled(window: ReviewWindow, app: QCoreApplication,
                       timeout_s: float = 60.0) -> bool:
    """Process events until loading finished and every visible tile has its frame."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        app.processEvents()
        if window.task is None and not window.rescorer.busy() and not window.similar.busy() and \
                not window.checker.busy() and (window.loader is None or window.loader.idle()):
            for _ in range(5):
                app.processEvents()
                time.sleep(0.02)
            return True
        time.sleep(0.02)
    return False


def _screenshot_error(target: Path, reason: str) -> ScreenshotError:
    return ScreenshotError(f"{target}: cannot write the screenshot ({reason}); "
                           "give --screenshot a file name in a writable folder")


def check_screenshot_path(path: str) -> None:
    """Raise ScreenshotError now if no file can be written at ``path``."""
    target = Path(path)
    if target.is_dir():
        raise _screenshot_error(target, "it is a folder")
    with contextlib.suppress(OSError):  # what stops it is said below
        target.parent.mkdir(parents=True, exist_ok=True)
    problem = folder_write_problem(target.parent)
    if problem:
        raise _screenshot_error(target, problem)


def save_screenshot(window: QWidget, path: str) -> None:
    """Render the whole window to a PNG file (or the format the suffix names)."""
    from PySide6.QtCore import QBuffer, QByteArray, QIODevice

    target = Path(path)
    check_screenshot_path(path)
    data = QByteArray()
    buffer = QBuffer(data)
    buffer.open(QIODevice.OpenModeFlag.WriteOnly)
    fmt = target.suffix.lstrip(".").upper() or "PNG"
    if not window.grab().save(buffer, fmt):
        raise _screenshot_error(target, f"no {fmt} image writer; use a .png name")
    buffer.close()
    try:
        target.write_bytes(data.data())
    except OSError as exc:
        raise _screenshot_error(target, exc.strerror or str(exc)) from exc
