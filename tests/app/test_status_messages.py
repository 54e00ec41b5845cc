"""The status line's messages as the operator reads them: each job's latest result
replaces its earlier one, a search's result names what it added (and a repeated one says
so), and results from long ago give way to newer work instead of lingering beside it."""

from __future__ import annotations

import time

import pytest
from PySide6.QtCore import Qt

from app.offset_text import shift_text
from app.status_line import QUIET_S
from speechcal_core.review.model import set_time_ns
from speechcal_core.review.similar import SIMILAR_SOURCE


@pytest.fixture
def clock() -> list[float]:
    """A clock the test moves on (``clock[0] += s``) for the window's status line."""
    return [time.monotonic()]


def _set_added_at_a_missed_word(qtbot, open_window, missed_voice_file):
    """The window over a session missing a voice's triggers, with T pressed at one."""
    path, missed = missed_voice_file
    window = open_window(path)
    window.model.set_playhead(missed[0]["session_ns"])
    qtbot.keyClick(window, Qt.Key.Key_T)
    return window


def test_each_search_reports_what_it_found_and_a_repeat_is_counted(
        qtbot, open_window, missed_voice_file) -> None:
    window = _set_added_at_a_missed_word(qtbot, open_window, missed_voice_file)
    model = window.model
    marked = model.current_set.id

    qtbot.keyClick(window, Qt.Key.Key_S)
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    found = [s.id for s in model.session.sets if s.trigger.source == SIMILAR_SOURCE]
    assert found
    text = window.status_text.text()
    assert f"found {len(found)} more like set {marked}" in text
    assert f"(added {', '.join(f'#{i}' for i in found)})" in text  # the ids the list shows

    qtbot.keyClick(window, Qt.Key.Key_S)  # again: what it found is covered by now
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    text = window.status_text.text()
    assert f"found nothing more like set {marked}" in text
    assert "(added" not in text and f"found {len(found)} more" not in text  # replaced
    assert "(×2)" not in text
    qtbot.keyClick(window, Qt.Key.Key_S)  # and again: the same answer, counted
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    text = window.status_text.text()
    assert f"found nothing more like set {marked}" in text and "that no set covers (×2)" in text
    assert text.count("found nothing more") == 1


def test_a_search_result_stays_beside_the_rescoring_that_follows_it(
        qtbot, open_window, missed_voice_file) -> None:
    window = _set_added_at_a_missed_word(qtbot, open_window, missed_voice_file)
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_S)
    qtbot.waitUntil(lambda: not window.similar.busy(), timeout=30_000)
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)  # the found sets
    text = window.status_text.text()
    assert text.startswith("re-scored") and f"more like set {model.current_set.id}" in text


def test_a_result_from_long_ago_gives_way_to_newer_work(
        qtbot, window, clock: list[float]) -> None:
    window.status.clock = lambda: clock[0]
    model = window.model
    model.set_playhead(model.time_range_ns()[0])
    qtbot.keyClick(window, Qt.Key.Key_W)  # away from any set
    assert "no frame set at the playhead" in window.status_text.text()
    clock[0] += QUIET_S / 2  # soon after: an offset edit's re-scoring stands beside it
    # (the model's edit: the ] key's own words, a plain message, would replace it)
    model.nudge_offset(1_000_000)
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    assert "no frame set at the playhead" in window.status_text.text()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    text = window.status_text.text()
    assert text.startswith("re-scored") and "no frame set at the playhead" in text

    clock[0] += QUIET_S + 1  # long after: the next edit's work replaces both
    model.nudge_offset(1_000_000)
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    text = window.status_text.text()
    assert text.startswith("re-scoring") and "no frame set" not in text
    assert "re-scored" not in text
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    clock[0] += QUIET_S + 1
    qtbot.keyClick(window, Qt.Key.Key_W)  # a message alone replaces them too
    assert "re-scored" not in window.status_text.text()


def test_a_repeat_is_counted_though_another_job_ended_in_between(qtbot) -> None:
    from PySide6.QtWidgets import QLabel, QProgressBar, QPushButton

    from app.status_line import StatusLine

    label = QLabel()
    status = StatusLine(label, QProgressBar(), QPushButton(), clock=lambda: 0.0)
    status.begin("similar", "searching…")
    status.end("similar", "found nothing more like set 3")
    status.begin("rescore", "re-scoring 2 frame sets…")  # the sets the first search added
    status.begin("similar", "searching…")
    status.end("rescore", "re-scored 2 frame sets")
    status.end("similar", "found nothing more like set 3")
    assert "found nothing more like set 3 (×2)" in label.text()
    assert "re-scored 2 frame sets" in label.text()


def test_the_opening_message_keeps_its_count_of_sets_true(qtbot, open_window,
                                                          truth_session_file) -> None:
    """"3 cameras, 4 frame sets" said on opening would be wrong after a Del: it follows
    the list while it is shown, and another job's message beside it stays."""
    window = open_window(truth_session_file)
    n = len(window.model.session.sets)
    assert f"3 cameras, {n} frame sets" in window.status_text.text()
    window.status.end("export", "exported 2 frame sets")
    window.model.remove_set()
    text = window.status_text.text()
    assert f"3 cameras, {n - 1} frame sets" in text and f"{n} frame sets" not in text
    assert "exported 2 frame sets" in text


def test_decisions_undo_and_a_refused_add_each_say_what_they_did(qtbot, window) -> None:
    """An earlier message ("redone: …") never stays through later decisions, and a key
    that did nothing says so."""
    model = window.model
    model.advance_after_decision = True
    first, second = (s.id for s in model.session.sets[:2])
    qtbot.keyClick(window, Qt.Key.Key_A)
    assert f"set #{first} accepted" in window.status_text.text()
    qtbot.waitUntil(window.undo_action.isEnabled)  # the menu follows each step
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(window.redo_action.isEnabled)
    qtbot.keyClick(window, Qt.Key.Key_Z,
                   Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert "redone: " in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_R)  # the redo went back to the first set
    text = window.status_text.text()
    assert f"set #{first} rejected" in text and "redone" not in text
    qtbot.keyClick(window, Qt.Key.Key_A)  # it went on to the second
    assert f"set #{second} accepted" in window.status_text.text()

    qtbot.keyClick(window, Qt.Key.Key_T)  # at a set: it is selected, nothing added
    assert "is here already: selected it" in window.status_text.text()
    sets = model.session.sets
    model.set_playhead((set_time_ns(sets[2]) + set_time_ns(sets[3])) // 2)
    qtbot.keyClick(window, Qt.Key.Key_T)
    assert f"set #{model.current_set.id} added · Ctrl+Z takes it back" in \
        window.status_text.text()
    while model.undo_label:
        model.undo()
    qtbot.keyClick(window, Qt.Key.Key_U)
    assert "nothing to undo" in window.status_text.text()
    window.status.say("")
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert "nothing to undo" in window.status_text.text()  # the menu entry is off
    while model.redo_label:
        model.redo()
    qtbot.keyClick(window, Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)
    assert "nothing to redo" in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert "undone: " in window.status_text.text()  # the entry is on again: it undoes


def test_what_c_and_t_did_stays_through_the_rescoring_they_start(qtbot, window) -> None:
    model = window.model
    model.set_playhead(model.camera_clap_ns() - 250_000_000)
    qtbot.keyClick(window, Qt.Key.Key_C)  # the audio moves: every set is re-scored
    said = "the clap is at the playhead: audio moved +250 ms · Ctrl+Z takes it back"
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    assert said in window.status_text.text()  # not wiped the moment re-scoring begins
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    text = window.status_text.text()
    assert text.startswith("re-scored") and said in text

    sets = model.session.sets
    model.set_playhead((set_time_ns(sets[0]) + set_time_ns(sets[1])) // 2)
    qtbot.keyClick(window, Qt.Key.Key_T)  # the set added is re-scored at once
    added = f"set #{model.current_set.id} added · Ctrl+Z takes it back"
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    assert added in window.status_text.text()
    assert "the clap is at the playhead" not in window.status_text.text()  # said anew


def test_offset_keys_say_how_far_the_audio_moved_and_repeats_are_counted(
        qtbot, window) -> None:
    """[ ] { } changed only the offset line, and three undos showed one "undone: …"."""
    model = window.model
    start = model.session.sync.offset_ns
    said = "audio moved +1 ms · Ctrl+Z takes it back"
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    assert said in window.status_text.text() and "(×" not in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    assert f"{said} (×2)" in window.status_text.text()
    assert window.status_text.text().count(said) == 1
    qtbot.keyClick(window, Qt.Key.Key_BraceLeft)  # one frame earlier
    frame_ns = start + 2_000_000 - model.session.sync.offset_ns
    assert frame_ns > 1_000_000
    assert f"one frame: audio moved {shift_text(-frame_ns)} · Ctrl+Z takes it back" \
        in window.status_text.text()
    for n in (1, 2, 3):
        qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
        text = window.status_text.text()
        assert text.count("undone: audio offset change") == 1
        assert (f"undone: audio offset change (×{n})" in text) if n > 1 else "(×" not in text
    assert model.session.sync.offset_ns == start
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert "nothing to undo" in window.status_text.text()


def test_undoing_the_offset_edit_takes_back_its_look_again_warning(qtbot, window) -> None:
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_A)  # set 1 accepted as it shows now
    model.set_playhead(model.camera_clap_ns() - 250_000_000)
    qtbot.keyClick(window, Qt.Key.Key_C)  # the audio moves: set 1 gets other frames
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert "now shows other frames: look again" in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert model.session.sets[0].decision == "accepted"  # the offset went back, not it
    qtbot.wait(400)  # past the re-scoring's delay: nothing needs it
    assert not window.rescorer.busy()
    text = window.status_text.text()
    assert "undone: " in text
    assert "look again" not in text  # set 1 shows the frames it was accepted with again


def test_w_between_sets_stops_saying_so_once_the_playhead_is_on_a_set(
        qtbot, window) -> None:
    """W with the playhead between sets says "no frame set at the playhead: J / K go to
    one"; after K went to a set (which says nothing) the line went on saying it, set after
    set, quiet seconds or not. Once the playhead is on a set it is taken back; a W
    between sets again says it again."""
    from app.transport import NO_SET_TO_HEAR

    model = window.model
    sets = model.session.sets
    model.set_playhead((set_time_ns(sets[0]) + set_time_ns(sets[1])) // 2)
    assert model.set_at_playhead() is None
    qtbot.keyClick(window, Qt.Key.Key_W)
    assert NO_SET_TO_HEAR in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_K)
    assert model.set_at_playhead() is not None
    assert NO_SET_TO_HEAR not in window.status_text.text()

    model.set_playhead((set_time_ns(sets[1]) + set_time_ns(sets[2])) // 2)
    qtbot.keyClick(window, Qt.Key.Key_W)
    assert NO_SET_TO_HEAR in window.status_text.text()
    model.go_to_set(2)  # a row of the list chosen
    assert NO_SET_TO_HEAR not in window.status_text.text()


def test_a_r_and_del_with_no_set_left_say_why_they_did_nothing(qtbot, window) -> None:
    """With every set removed, A, R and Del (and their buttons) left the status line as it
    was, still saying the last set was removed, as if the key had not been pressed."""
    while window.model.session.sets:
        qtbot.keyClick(window, Qt.Key.Key_Delete)
    for key, verb in ((Qt.Key.Key_A, "decide on"), (Qt.Key.Key_R, "decide on"),
                      (Qt.Key.Key_Delete, "remove")):
        window.status.say("")
        qtbot.keyClick(window, key)
        assert window.status_text.text() == \
            f"no frame sets to {verb}: T adds one at the playhead"


def test_an_undo_that_restarts_the_rescoring_still_says_what_it_undid(
        qtbot, window, gate) -> None:
    """Ctrl+Z (or Ctrl+Y) on an offset edit while re-scoring ran lost its "undone: …"
    ("redone: …") as the re-scoring restarted for it: the operator read only "re-scoring
    N frame sets…", then "re-scored …", and could not tell the key had done anything."""
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # re-scoring starts, held by the gate
    qtbot.waitUntil(lambda: window.status.running("rescore"), timeout=5_000)
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)  # the next frame: never scored either
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    qtbot.wait(600)  # past the re-scoring's delay: it restarted for the offset undone to
    assert window.status.running("rescore")
    assert "undone: audio offset change" in window.status_text.text()
    qtbot.keyClick(window, Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)
    qtbot.wait(600)
    assert "redone: audio offset change" in window.status_text.text()
    gate.set()
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert "redone: audio offset change" in window.status_text.text()
