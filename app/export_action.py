"""The window's export: dialog, replace confirmation, and the export on a worker thread.

All export logic is in :mod:`speechcal_core.export`; this only asks and reports.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject
from PySide6.QtWidgets import QMessageBox

from app.export_dialog import ExportDialog
from app.tasks import BackgroundTask, start

if TYPE_CHECKING:
    from app.main_window import ReviewWindow
    from speechcal_core.export import ExportResult


class ExportAction(QObject):
    """Runs one export at a time for a :class:`ReviewWindow`."""

    def __init__(self, window: ReviewWindow) -> None:
        super().__init__(window)
        self.window = window
        self.dialog: ExportDialog | None = None
        self.replace_box: QMessageBox | None = None
        self.task: BackgroundTask | None = None
        self.last_result: ExportResult | None = None
        self.last_error = ""

    # -- asking -------------------------------------------------------------------------
    def choose(self) -> None:
        """Open the export dialog (non-blocking); accepting it starts the export."""
        w = self.window
        if w.model is None or w.inputs is None or self.task is not None:
            return
        path = w.inputs.session_path
        base = Path(path).parent if path else Path(w.model.session.recording[0]).parent
        stem = Path(path).name.split(".")[0] if path else "export"
        self.dialog = ExportDialog(w, base, stem, w.model.session.counts())
        self.dialog.accepted.connect(self._dialog_accepted)
        self.dialog.open()

    def _dialog_accepted(self) -> None:
        assert self.dialog is not None
        fmt, out, include = self.dialog.choice()
        self.start(fmt, out, include_undecided=include)

    def start(self, fmt: str, out: Path, *, force: bool = False,
              include_undecided: bool = False) -> None:
        """Export to ``out``; an existing folder is replaced only after the operator agrees."""
        out = Path(out).absolute()
        if out.exists() and not force:
            self._ask_replace(fmt, out, include_undecided)
            return
        self._run(fmt, out, force, include_undecided)

    def _ask_replace(self, fmt: str, out: Path, include_undecided: bool) -> None:
        box = QMessageBox(QMessageBox.Icon.Warning, "SpeechCal",
                          f"{out} already exists.\nReplace it with this export?",
                          QMessageBox.StandardButton.Cancel, self.window)
        replace_button = box.addButton("Replace", QMessageBox.ButtonRole.DestructiveRole)
        box.setDefaultButton(QMessageBox.StandardButton.Cancel)

        def answered(button) -> None:
            if button is replace_button:
                self._run(fmt, out, True, include_undecided)
            else:
                self.window.status_text.setText(f"Export not written: {out} already exists")

        box.buttonClicked.connect(answered)
        self.replace_box = box
        box.open()

    # -- running ------------------------------------------------------------------------
    def _run(self, fmt: str, out: Path, force: bool, include_undecided: bool) -> None:
        from speechcal_core.export import export_frame_sets

        w = self.window
        assert w.model is not None and w.inputs is not None
        session = w.model.session
        snapshot = replace(session, sets=list(session.sets))  # review may go on meanwhile
        source, session_path = w.inputs.source, w.inputs.session_path
        self.last_error = ""
        self.last_result = None
        self.task = BackgroundTask(lambda report: export_frame_sets(
            snapshot, source, fmt, out, force=force, include_undecided=include_undecided,
            session_path=session_path, progress=report))
        self.task.signals.progress.connect(w._on_progress)
        self.task.signals.finished.connect(self._finished)
        self.task.signals.failed.connect(self._failed)
        w._show_busy(f"exporting to {out}…")
        self._set_enabled(False)
        start(self.task)

    def cancel(self) -> None:
        if self.task is not None:
            self.task.cancel()

    def _set_enabled(self, enabled: bool) -> None:
        self.window.export_button.setEnabled(enabled)
        self.window.export_action.setEnabled(enabled)

    def _done(self) -> None:
        self.task = None
        self._set_enabled(True)
        self.window.progress.hide()
        self.window.cancel_button.hide()

    def _finished(self, result: ExportResult) -> None:
        self._done()
        self.last_result = result
        left = f", {len(result.skipped)} frames left out (see manifest)" if result.skipped else ""
        self.window.status_text.setText(
            f"Exported {result.sets} frame sets ({result.frames} frames) as {result.format} "
            f"to {result.out}{left}")

    def _failed(self, message: str) -> None:
        self._done()
        self.last_error = message
        if message == "cancelled":
            self.window.status_text.setText("Export cancelled; nothing was written")
            return
        self.window.status_text.setText(f"Export failed: {message}")
        if not self.window.property("headless"):
            QMessageBox.warning(self.window, "SpeechCal", message)
