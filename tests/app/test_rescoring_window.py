"""The window after an offset edit: nearest frames at once, figures again off the UI thread."""

from __future__ import annotations

import threading
from pathlib import Path

from PySide6.QtCore import Qt
from set_list_cells import cell

from app.set_table import MISSING, PENDING, column
from speechcal_core.session.store import load_session


def figures(window) -> list[str]:
    return [cell(window.table, r, column("worst sharp")).text
            for r in range(window.table.model().rowCount())]


def test_offset_nudge_rescores_in_the_background_and_the_list_gets_figures_again(
    qtbot, open_window, searched_session_file: Path, gate: threading.Event
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    assert all(PENDING not in f and MISSING not in f for f in figures(window))
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # audio one frame later
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)
    # at once: nearest frames, figures to come, no warnings or corners of other frames
    assert set(figures(window)) == {PENDING}
    assert all(not t.flags and not t.corners for t in model.tiles())
    assert {t.caption for t in window.grid.tiles.values()} == {"nearest frame, re-scoring…"}
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    # the UI thread goes on while the worker is busy
    # and what the keys did stays beside it (counted: the same step twice)
    assert window.status_text.text().startswith(
        f"re-scoring {len(model.session.sets)} frame sets…  ·  one frame: audio moved ")
    assert window.status_text.text().endswith("Ctrl+Z takes it back (×2)")
    assert window.progress.isVisible() and window.cancel_button.isVisible()
    qtbot.keyClick(window, Qt.Key.Key_K)
    assert model.current == 1
    window.advance_box.setChecked(False)
    qtbot.keyClick(window, Qt.Key.Key_R)  # decided while it waits: its figures still to come
    assert model.session.sets[1].decision == "rejected"
    assert set(figures(window)) == {PENDING}
    qtbot.keyClick(window, Qt.Key.Key_U)
    gate.set()
    qtbot.waitUntil(lambda: PENDING not in "".join(figures(window)), timeout=30_000)

    assert model.rescore_ids() == [] and not window.rescorer.busy()
    assert all(MISSING not in f for f in figures(window))
    assert window.status_text.text().startswith("re-scored")
    assert not window.progress.isVisible()
    assert all(t.chosen for t in model.tiles()) and any(t.corners for t in model.tiles())
    assert {t.caption for t in window.grid.tiles.values()} == {"chosen frame"}
    window.saver.flush()  # the autosave is written off the UI thread
    saved = load_session(searched_session_file)
    assert saved.sync.offset_ns == model.session.sync.offset_ns
    frames = [f for s in saved.sets for f in s.frames]
    assert all(f.sharpness is not None or "no-target" in f.flags for f in frames)
    assert any(f.sharpness is not None for f in frames)


def test_an_added_set_gets_figures_and_cancel_keeps_nearest_frames(
    qtbot, open_window, searched_session_file: Path, gate: threading.Event
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    a, b = (s.t_ns for s in model.session.sets[1:3])
    model.set_playhead((a + b) // 2)
    qtbot.keyClick(window, Qt.Key.Key_T)
    row = model.current
    assert figures(window)[row] == PENDING
    gate.set()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert figures(window)[row] not in (PENDING, MISSING)

    gate.clear()
    qtbot.keyClick(window, Qt.Key.Key_BracketLeft)
    qtbot.waitUntil(lambda: window.rescorer.task is not None, timeout=5_000)
    qtbot.mouseClick(window.cancel_button, Qt.MouseButton.LeftButton)
    gate.set()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert "cancelled" in window.status_text.text()
    assert set(figures(window)) == {MISSING}  # nothing is coming until the next edit
    assert model.rescore_ids() == [s.id for s in model.session.sets]
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # the next edit re-scores again
    qtbot.waitUntil(lambda: model.rescore_ids() == [], timeout=30_000)


def test_cancel_before_rescoring_starts_says_so_and_keeps_nearest_frames(
    qtbot, open_window, searched_session_file: Path
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # re-scoring starts after a short delay
    assert window.rescorer.timer.isActive() and window.rescorer.task is None
    window.cancel_task()  # the Cancel button, pressed within that delay
    assert "re-scoring cancelled" in window.status_text.text()
    assert set(figures(window)) == {MISSING}  # nothing is coming until the next edit
    assert {t.caption for t in window.grid.tiles.values()} == {"nearest frame"}
    qtbot.wait(400)
    assert window.rescorer.task is None and model.rescore_ids()
    qtbot.keyClick(window, Qt.Key.Key_BracketLeft)  # the next edit re-scores again
    qtbot.waitUntil(lambda: model.rescore_ids() == [], timeout=30_000)


def test_an_accepted_set_given_other_frames_by_an_offset_edit_is_named_as_a_warning(
    qtbot, open_window, searched_session_file: Path
) -> None:
    window = open_window(searched_session_file)
    model = window.model
    model.go_to_set(2)
    third = model.current_set.id
    qtbot.keyClick(window, Qt.Key.Key_A)
    model.nudge_offset(-600_000_000)  # far enough for other still frames in that set
    qtbot.waitUntil(lambda: model.rescore_ids() == [] and not window.rescorer.busy(),
                    timeout=30_000)
    assert window.status_text.text().startswith(
        f"▲ re-scored {len(model.session.sets)} frame sets: best still frames chosen; "
        f"accepted set #{third} now shows other frames: look again")
