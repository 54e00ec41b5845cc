"""Export and re-scoring in one window: the export waits for best still frames, the status
line shows both, the checks follow, and another session closes the previous recording."""

from __future__ import annotations

import json
import threading
from pathlib import Path

from PySide6.QtCore import Qt
from set_list_cells import cell

from app.set_table import MISSING, PENDING, column
from speechcal_core.frames.analysis import checks_basis
from speechcal_core.frames.nearest import nearest_index
from speechcal_core.session.store import load_session


def _stamps(manifest: Path) -> dict[int, dict[str, int]]:
    doc = json.loads(manifest.read_text())
    return {s["id"]: {f["stream"]: f["stamp_ns"] for f in s["frames"]} for s in doc["sets"]}


def test_export_waits_for_rescoring_even_after_a_cancel_and_writes_best_still_frames(
    qtbot, open_window, searched_session_file: Path, gate: threading.Event, tmp_path: Path,
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_A)  # accept the first set
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # audio one frame later: re-scoring
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    qtbot.mouseClick(window.cancel_button, Qt.MouseButton.LeftButton)
    gate.set()  # the worker sees the cancel
    qtbot.waitUntil(lambda: window.rescorer.task is None, timeout=30_000)
    gate.clear()
    assert window.rescorer.held and cell(window.table, 0, column("worst sharp")).text == MISSING

    out = tmp_path / "kalibr"
    window.exporter.start("kalibr", out)  # the accepted set shows its nearest frames
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    assert window.exporter.pending is not None and window.exporter.task is None
    text = window.status_text.text()
    assert text.startswith("re-scoring") and "waits for 1 frame set to be re-scored" in text
    assert str(out) in text and window.cancel_button.isVisible()
    assert not window.export_button.isEnabled()
    assert cell(window.table, 0, column("worst sharp")).text == PENDING
    assert not out.exists()
    gate.set()
    qtbot.waitUntil(lambda: not window.exporter.busy(), timeout=30_000)

    assert window.exporter.last_error == "" and model.export_waits_for() == []
    first = model.session.sets[0]
    written = _stamps(out / "manifest.json")
    assert written == {first.id: {f.stream: f.stamp_ns for f in first.frames}}
    assert any(f.index != nearest_index(model.source.stamps(f.stream), first.t_ns)
               for f in first.frames)  # the best still frames, not the nearest
    text = window.status_text.text()
    assert text.startswith("Exported 1 frame set (") and "re-scored" in text
    # the checks follow the frames re-scoring chose, in the session file too
    qtbot.waitUntil(lambda: not window.checker.busy(), timeout=30_000)
    window.saver.flush()  # the autosave is written off the UI thread
    saved = load_session(searched_session_file)
    assert saved.extra["checks_basis"] == checks_basis(saved.sets)
    assert window.check_label.text().startswith(("calibration check over", "▲ calibration"))


def test_cancel_while_an_export_waits_drops_it_and_nothing_is_written(
    qtbot, open_window, searched_session_file: Path, gate: threading.Event, tmp_path: Path,
) -> None:
    window = open_window(searched_session_file)
    qtbot.keyClick(window, Qt.Key.Key_A)
    qtbot.keyClick(window, Qt.Key.Key_BracketLeft)
    qtbot.mouseClick(window.export_button, Qt.MouseButton.LeftButton)
    assert "1 of them still shows the frames nearest" in window.exporter.dialog.summary.text()
    window.exporter.dialog.reject()
    out = tmp_path / "folders"
    window.exporter.start("folders", out)
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    assert window.exporter.pending is not None
    qtbot.mouseClick(window.cancel_button, Qt.MouseButton.LeftButton)
    assert window.exporter.pending is None and window.export_button.isEnabled()
    gate.set()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert not out.exists()
    text = window.status_text.text()
    assert "Export cancelled" in text and "re-scoring cancelled" in text


def test_status_line_shows_export_and_rescoring_side_by_side(
    qtbot, open_window, searched_session_file: Path, gate: threading.Event,
    export_gate: threading.Event, tmp_path: Path,
) -> None:
    window = open_window(searched_session_file)
    qtbot.keyClick(window, Qt.Key.Key_A)
    out = tmp_path / "bag"
    window.exporter.start("rosbag1", out)  # nothing waits: it runs at once
    qtbot.waitUntil(lambda: window.status_text.text() == "exporting: writing", timeout=5_000)
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # an edit while the export runs
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    text = window.status_text.text()
    assert text.startswith("exporting: writing 25%") and "re-scoring" in text
    assert window.progress.value() == 250  # the job started first
    tip = window.cancel_button.toolTip()
    assert "exporting" in tip and "re-scoring" in tip

    export_gate.set()
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    text = window.status_text.text()  # the result stays beside the job still running
    assert text.startswith("re-scoring") and "Exported 1 frame set (" in text
    assert window.progress.isVisible() and window.cancel_button.isVisible()
    gate.set()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    text = window.status_text.text()
    assert text.startswith("re-scored") and "Exported 1 frame set (" in text
    assert not window.progress.isVisible() and not window.cancel_button.isVisible()


def test_opening_another_session_closes_the_previous_recording_once_its_export_is_done(
    qtbot, open_window, searched_session_file: Path, truth_session_file: Path,
    export_gate: threading.Event, tmp_path: Path,
) -> None:
    window = open_window(searched_session_file)
    qtbot.keyClick(window, Qt.Key.Key_A)
    first = window.inputs
    closed: list[bool] = []
    close = first.source.close
    first.source.close = lambda: (closed.append(True), close())
    out = tmp_path / "kalibr"
    window.exporter.start("kalibr", out)
    qtbot.waitUntil(lambda: window.exporter.task is not None, timeout=5_000)
    window.open(session_path=str(truth_session_file))
    qtbot.waitUntil(lambda: window.inputs is not first, timeout=30_000)
    assert closed == []  # the export still reads it
    export_gate.set()
    qtbot.waitUntil(lambda: window.exporter.task is None, timeout=30_000)
    assert closed == [True] and (out / "manifest.json").exists()
    second = window.inputs
    second.source.close = lambda: closed.append(True)  # nothing reads it: closed at once
    window.open(session_path=str(searched_session_file))
    qtbot.waitUntil(lambda: window.inputs is not second, timeout=30_000)
    assert closed == [True, True] and window._retired == []
