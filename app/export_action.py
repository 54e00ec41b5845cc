"""The window's export: dialog, replace confirmation, and the export on a worker thread.

All export logic is in :mod:`speechcal_core.export`; this only asks and reports (job
``"export"`` of the status line). Sets still waiting for re-scoring show their nearest
frames, not the best still ones: an export that would hold any of them waits until
re-scoring has chosen their frames (starting it if it was cancelled), then runs.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QMessageBox

from app.export_dialog import ExportDialog
from app.tasks import BackgroundTask, start
from speechcal_core.export.earlier import TARGET_FORMATS
from speechcal_core.export.run import export_target
from speechcal_core.text import counted

if TYPE_CHECKING:
    from PySide6.QtWidgets import QAbstractButton

    from app.main_window import ReviewWindow
    from speechcal_core.export import ExportResult
    from speechcal_core.session.model import Session
    from speechcal_core.sources.base import FrameSource
    from speechcal_core.target import TargetSpec


class ExportAction(QObject):
    """Runs one export at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window)
        self.window = window
        self.dialog: ExportDialog | None = None
        self.replace_box: QMessageBox | None = None
        self.task: BackgroundTask | None = None
        #: (format, folder, force, include undecided, board chosen in the dialog) of an
        #: export waiting for re-scoring
        self.pending: tuple[str, Path, bool, bool, TargetSpec | None] | None = None
        self.source: FrameSource | None = None  # the recording the running export reads
        self.last_result: ExportResult | None = None
        self.last_error = ""
        self.last_format = ""  # the format last chosen in the dialog, offered again
        self._from_dialog = False  # the export being started was chosen in the dialog

    def busy(self) -> bool:
        """True while an export runs or waits for re-scoring."""
        return self.task is not None or self.pending is not None

    # -- asking -------------------------------------------------------------------------
    def choose(self) -> None:
        """Open the export dialog (non-blocking); accepting it starts the export."""
        w = self.window
        if w.model is None or w.inputs is None or self.busy():
            return
        path = w.inputs.session_path
        # whole: a session opened as "session.json" offered "session-kalibr", not where
        base = (Path(path) if path else Path(w.model.session.recording[0])).absolute().parent
        stem = Path(path).name.split(".")[0] if path else "export"
        self.dialog = ExportDialog(w, base, stem, w.model.session.counts(),
                                   waiting=lambda include: len(w.model.export_waits_for(include)),
                                   refusal=self.refusal,
                                   board=export_target(w.model.session, None))
        if self.last_format:  # the format of the export before (the folder follows it)
            self.dialog.set_format(self.last_format)
        self.dialog.accepted.connect(self._dialog_accepted)
        self.dialog.open()

    def _dialog_accepted(self) -> None:
        assert self.dialog is not None
        fmt, out, include, target = self.dialog.choice()
        self.last_format = fmt
        self._from_dialog = True  # a replace declined goes back to the dialog
        try:
            self.start(fmt, out, include_undecided=include, target=target)
        finally:
            self._from_dialog = False

    def start(self, fmt: str, out: Path, *, force: bool = False,
              include_undecided: bool = False, target: TargetSpec | None = None) -> None:
        """Export to ``out``; an existing folder is replaced only after the operator agrees,
        and one the export reads (see :meth:`refusal`) is refused before asking.
        ``target``: the board to describe (None: the session's, or the one assumed)."""
        out = Path(out).absolute()
        board = (target or export_target(self.window.model.session, None)[0]) \
            if fmt in TARGET_FORMATS and self.window.model is not None else None
        why = self.refusal(out, board)
        if why:
            self.last_error = why
            self.window.status.end("export", f"Export not written: {why}")
            if not self.window.property("headless"):
                QMessageBox.warning(self.window, "SpeechCal", why)
            return
        if os.path.lexists(out) and not force:  # a dangling link is replaced too
            self._ask_replace(fmt, out, include_undecided, target)
            return
        self._run(fmt, out, force, include_undecided, target)

    def refusal(self, out: Path, board: TargetSpec | None = None) -> str:
        """Why the export may never write ``out`` (it is, holds or lies inside the open
        session's recording, audio or session file, or is an earlier export kept for its
        edited target.yaml unless ``board``, the one a Kalibr export writes, is that one:
        the core's own check), "" if it may."""
        from speechcal_core.export.errors import ExportError
        from speechcal_core.export.run import check_output, session_inputs

        w = self.window
        if w.model is None or w.inputs is None:
            return ""
        protected = session_inputs(w.model.session, w.inputs.session_path)
        try:
            check_output(Path(out), True, protected, board)  # forced: an existing one is asked
        except ExportError as exc:
            return str(exc)
        return ""

    def _ask_replace(self, fmt: str, out: Path, include_undecided: bool,
                     target: TargetSpec | None) -> None:
        box = QMessageBox(QMessageBox.Icon.Warning, "SpeechCal",
                          f"{out} already exists.\nReplace it with this export?",
                          QMessageBox.StandardButton.Cancel, self.window)
        replace_button = box.addButton("Replace", QMessageBox.ButtonRole.DestructiveRole)
        box.setDefaultButton(QMessageBox.StandardButton.Cancel)
        dialog = self.dialog if self._from_dialog else None

        def answered(button: QAbstractButton) -> None:
            if button is replace_button:
                self._run(fmt, out, True, include_undecided, target)
                return
            self.window.status.end("export", f"Export not written: {out} already exists")
            if dialog is not None and dialog is self.dialog:
                # back to the choices made, to name another folder (or Cancel): they
                # were all lost, the dialog opened afresh with the default folder
                dialog.open()
                dialog.path_edit.setFocus()
                dialog.path_edit.selectAll()

        box.buttonClicked.connect(answered)
        self.replace_box = box
        box.open()

    # -- running ------------------------------------------------------------------------
    def _run(self, fmt: str, out: Path, force: bool, include_undecided: bool,
             target: TargetSpec | None) -> None:
        self.last_error = ""
        self.last_result = None
        self.pending = (fmt, out, force, include_undecided, target)
        self._set_enabled(False)
        self._go()

    def _go(self) -> None:
        """Start the pending export, or wait while sets it holds wait for re-scoring."""
        from speechcal_core.export import export_frame_sets

        w = self.window
        assert self.pending is not None and w.model is not None and w.inputs is not None
        fmt, out, force, include_undecided, target = self.pending
        waiting = w.model.export_waits_for(include_undecided)
        if waiting:
            if not w.rescorer.busy():
                w.rescorer.start_now()  # also after the operator cancelled it
            if not w.rescorer.busy():
                self._drop_pending("Export not written: frame sets still show their nearest "
                                   "frames and cannot be re-scored")
                return
            n = len(waiting)
            w.status.begin("export", f"export to {out} waits for {n} frame "
                                     f"set{'' if n == 1 else 's'} to be re-scored")
            return
        self.pending = None
        snapshot = _snapshot(w.model.session)
        source, session_path = w.inputs.source, w.inputs.session_path
        self.source = source
        self.task = BackgroundTask(lambda report: export_frame_sets(
            snapshot, source, fmt, out, force=force, include_undecided=include_undecided,
            target=target, session_path=session_path, progress=report), owner=self)
        self.task.signals.progress.connect(
            lambda text, f: w.status.report("export", f"exporting: {text}", f))
        self.task.signals.finished.connect(self._finished)
        self.task.signals.failed.connect(self._failed)
        w.status.begin("export", f"exporting to {out}…")
        start(self.task)

    def rescoring_stopped(self) -> None:
        """Re-scoring ended (finished, failed, cancelled or restarted for a newer edit):
        a waiting export starts, keeps waiting, or is dropped with the reason."""
        if self.pending is None:
            return
        rescorer = self.window.rescorer
        if rescorer.held:
            why = f"re-scoring failed: {rescorer.last_error}" if rescorer.last_error \
                else "re-scoring was cancelled"
            self._drop_pending(f"Export not written: {why}")
        else:
            self._go()  # runs now, or waits on (re-scoring restarted for a newer edit)

    def reset(self, why: str) -> None:
        """Another session opens: a waiting export is dropped (a running one finishes),
        and the export dialog or replace prompt still open is closed unanswered: it was
        asked for the session left, and would export the one opened in its place."""
        asked = False
        if self.replace_box is not None and self.replace_box.isVisible():
            self.replace_box.buttonClicked.disconnect()  # its answer would export
            self.replace_box.reject()
            asked = True
        if self.dialog is not None and self.dialog.isVisible():
            self.dialog.reject()
            asked = True
        if self.pending is not None:
            self._drop_pending(f"Export not written: {why}")
        elif asked:
            self.last_error = f"Export not written: {why}"
            self.window.status.end("export", self.last_error)

    def cancel(self) -> None:
        if self.pending is not None:
            self._drop_pending("Export cancelled; nothing was written")
        if self.task is not None:
            self.task.cancel()

    def shutdown(self, wait_s: float = 10.0) -> None:
        """Stop for good (the window closes): cancel and wait for the worker to let go of
        the recording; how it ended is not reported (the window no longer shows it)."""
        task = self.task
        self.cancel()
        if task is not None:
            task.abandon()
            task.done.wait(wait_s)

    def _drop_pending(self, message: str) -> None:
        self.pending = None
        self.last_error = message
        self._set_enabled(True)
        self.window.status.end("export", message)

    def _set_enabled(self, enabled: bool) -> None:
        enabled = enabled and self.window.model is not None
        self.window.export_button.setEnabled(enabled)
        self.window.export_action.setEnabled(enabled)

    def _done(self, message: str) -> None:
        self.task, self.source = None, None
        self._set_enabled(True)
        self.window.status.end("export", message)
        self.window.release_retired()

    def _finished(self, result: ExportResult) -> None:
        self.last_result = result
        shown = "; ".join(result.skipped[:2]) + (" …" if len(result.skipped) > 2 else "")
        left = f"; {len(result.skipped)} left out: {shown}" if result.skipped else ""
        notes = "".join(f"; note: {note}" for note in result.notes)
        self._done(f"Exported {counted(result.sets, 'frame set')} "
                   f"({counted(result.frames, 'frame')}) as "
                   f"{result.format} to {result.out}{left}{notes}")

    def _failed(self, message: str) -> None:
        self.last_error = message
        if message == "cancelled":
            self._done("Export cancelled; nothing was written")
            return
        self._done(f"Export failed: {message}")
        if not self.window.property("headless"):
            QMessageBox.warning(self.window, "SpeechCal", message)


def _snapshot(session: Session) -> Session:
    """What the export reads on its worker thread while the review goes on: the sets and
    the extras as they are now (an offset edit meanwhile drops frame details in place)."""
    extra = dict(session.extra)
    if isinstance(extra.get("frame_details"), dict):
        extra["frame_details"] = dict(extra["frame_details"])
    return replace(session, sets=list(session.sets), extra=extra)
