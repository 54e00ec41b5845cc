"""The review window, driven like an operator would: keys, clicks, autosave, screenshot."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel
from set_list_cells import cell

from app.frame_grid import band_text
from app.main_window import ReviewWindow
from app.set_table import column
from speechcal_core.review.model import set_time_ns
from speechcal_core.session.store import load_session


def test_empty_window_says_what_to_open(qtbot) -> None:
    win = ReviewWindow()
    qtbot.addWidget(win)
    win.show()
    assert win.stack.currentIndex() == 0
    texts = " ".join(w.text() for w in win.findChildren(QLabel))
    assert "Drag a recording" in texts and "session file" in texts


def test_session_opens_with_one_tile_per_camera_and_the_heard_word(window) -> None:
    model = window.model
    assert set(window.grid.tiles) == set(model.streams)
    assert len(window.grid.tiles) == 3
    assert window.grid.word == "capture"
    assert window.table.model().rowCount() == len(model.session.sets)
    assert window.windowTitle() == "SpeechCal — recording.bag + audio.ogg"


def test_keys_accept_reject_undo_and_autosave(qtbot, window, truth_session_file) -> None:
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert window.model.session.sets[0].decision == "accepted"
    assert load_session(truth_session_file).sets[0].decision == "accepted"
    assert "accepted" in cell(window.table, 0, column("decision")).text
    assert window.saved_label.text() == "saved just now"
    assert window.model.current == 1  # "then next set": on to the next set
    qtbot.keyClick(window, Qt.Key.Key_R)
    window.saver.flush()  # the save written off the UI thread
    assert load_session(truth_session_file).sets[1].decision == "rejected"
    assert window.model.current == 2
    qtbot.keyClick(window, Qt.Key.Key_U)  # back to the set, undecided again
    window.saver.flush()  # the save written off the UI thread
    assert load_session(truth_session_file).sets[1].decision == "undecided"
    assert window.model.current == 1
    assert window.counts_label.text().startswith("✔ 1 accepted")
    window.advance_box.setChecked(False)  # deciding stays on the set
    qtbot.keyClick(window, Qt.Key.Key_R)
    window.saver.flush()  # the save written off the UI thread
    assert window.model.current == 1 and window.model.session.sets[1].decision == "rejected"



def _band_colour(wave, set_id: int):
    """The colour the waveform shows low in a set's word mark (under the envelope)."""
    from PySide6.QtCore import QPointF

    a, b = wave.mark_extent(set_id)
    # a fifth in from the start: the playhead stands at the set, often mid-word
    scene = wave.getViewBox().mapViewToScene(QPointF(a + 0.2 * (b - a), -0.95))
    point = wave.mapFromScene(scene)
    return wave.grab().toImage().pixelColor(point.x(), point.y())


def test_a_decision_recolours_its_waveform_mark(qtbot, window) -> None:
    """The set's own mark takes its decision's colour and label (every decision rebuilt
    all marks once: 100-150 ms for 66 sets on the window's thread)."""
    wave = window.waveform
    first = window.model.session.sets[0]
    undecided = _band_colour(wave, first.id)
    assert wave.marks.label_text(first.id) == f"?{first.id}"
    qtbot.keyClick(window, Qt.Key.Key_A)
    window.saver.flush()  # the save written off the UI thread
    assert wave.marks.label_text(first.id) == f"✔{first.id}"
    accepted = _band_colour(wave, first.id)
    assert accepted.green() > accepted.red() + 20 and accepted != undecided

def test_arrow_keys_step_a_frame_of_any_camera_or_with_shift_of_every_one(
        qtbot, window) -> None:
    model = window.model
    stamps = {name: model.source.stamps(name) for name in model.streams}
    start = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Right)
    assert model.playhead_ns == min(int(s[s > start][0]) for s in stamps.values())
    one = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Right, Qt.KeyboardModifier.ShiftModifier)
    assert model.playhead_ns == max(int(s[s > one][0]) for s in stamps.values())
    qtbot.keyClick(window, Qt.Key.Key_Left, Qt.KeyboardModifier.ShiftModifier)
    assert model.playhead_ns < one


def test_clicking_a_row_jumps_to_that_set(qtbot, window) -> None:
    last = window.table.model().rowCount() - 1
    window.table.selectRow(last)
    assert window.model.current == last
    assert window.model.playhead_ns == set_time_ns(window.model.session.sets[last])


def test_tile_without_a_frame_near_the_playhead_says_so(qtbot, window) -> None:
    _start, end = window.model.time_range_ns()
    window.model.playhead_ns = end + 10**9
    window._refresh_playhead()
    for tile in window.grid.tiles.values():
        assert tile.image is None and "no frame near the playhead" in tile.message


def test_during_playback_a_dropped_frame_keeps_the_last_image_dimmed(qtbot, window) -> None:
    """Playing over a gap in a camera's frames blanked its tile with an amber "no frame"
    at every gap; while playing, the last image stays, dimmed, captioned as dropped."""
    tiles = window.grid.tiles.values()
    qtbot.waitUntil(lambda: all(t.image is not None for t in tiles), timeout=10_000)
    _start, end = window.model.time_range_ns()
    window.transport.playing = True
    try:
        window.model.playhead_ns = end + 10**9  # no frame near: as in a gap
        window._refresh_playhead()
        for tile in tiles:
            assert tile.image is not None and tile.dimmed
            assert tile.caption == "dropped frame" and tile.warning == ""
    finally:
        window.transport.playing = False
    window._refresh_playhead()  # stopped: the tile says there is no frame
    assert all(t.image is None and t.message == "no frame near the playhead" for t in tiles)


def test_pausing_in_a_dropped_frame_shows_the_tile_as_paused(qtbot, window) -> None:
    """Paused where a camera dropped a frame, its tile kept the dimmed earlier image,
    captioned "dropped frame" and without the "no frame" warning: it was worked out for
    playback and nothing worked it out again when play stopped. Paused, it says there is
    no frame near the playhead; back on a frame, the frame shows undimmed."""
    import numpy as np

    model = window.model
    gaps = {name: np.nonzero(np.diff(stamps) > 1.6 * model._periods[name])[0]
            for name, stamps in model._stamps.items()}
    stream = next(name for name, found in gaps.items() if len(found))
    stamps, period = model._stamps[stream], model._periods[stream]
    before = int(stamps[gaps[stream][0]])
    model.set_playhead(before)
    tile = window.grid.tiles[stream]
    qtbot.waitUntil(lambda: tile.image is not None and not tile.dimmed, timeout=10_000)
    window.transport.playing = True  # as the play key does, without the clock moving on
    model.set_playhead(before + period)  # in the gap
    assert tile.dimmed and tile.caption == "dropped frame"
    qtbot.keyClick(window, Qt.Key.Key_Space)  # pause
    assert not window.transport.playing
    assert tile.image is None and not tile.dimmed
    assert tile.message == "no frame near the playhead" and tile.warning == "no frame"
    model.set_playhead(before)  # paused, back on the frame before the gap
    qtbot.waitUntil(lambda: tile.image is not None, timeout=10_000)
    assert not tile.dimmed and tile.warning == "" and tile.caption != "dropped frame"


def test_a_dimmed_tile_keeps_its_caption_until_the_next_frame_is_decoded(
        qtbot, window, monkeypatch) -> None:
    """Playing on from a dropped frame, the tile took the next frame's caption ("+0.4 ms")
    at once, over the old dimmed image, until that frame was decoded: caption and image
    now change together."""
    import threading

    import numpy as np

    model = window.model
    gaps = {name: np.nonzero(np.diff(stamps) > 1.6 * model._periods[name])[0]
            for name, stamps in model._stamps.items()}
    stream = next(name for name, found in gaps.items() if len(found))
    stamps, period = model._stamps[stream], model._periods[stream]
    gap = int(gaps[stream][0])
    model.set_playhead(int(stamps[gap]))
    tile = window.grid.tiles[stream]
    qtbot.waitUntil(lambda: tile.image is not None and not tile.dimmed, timeout=10_000)
    old_image = tile.image
    decoded = threading.Event()
    source = window.loader.source
    frame = source.frame
    monkeypatch.setattr(source, "frame", lambda s, i: (decoded.wait(10), frame(s, i))[1])
    window.loader._cache.pop((stream, gap + 1), None)
    window.transport.playing = True  # as the play key does, without the clock moving on
    try:
        model.set_playhead(int(stamps[gap]) + period)  # in the gap
        assert tile.dimmed and tile.caption == "dropped frame"
        model.set_playhead(int(stamps[gap + 1]))  # the frame after it, still decoding
        assert tile.image is old_image and tile.dimmed
        assert tile.caption == "dropped frame"
        decoded.set()
        qtbot.waitUntil(lambda: tile.image is not old_image, timeout=10_000)
        assert not tile.dimmed and tile.caption.endswith(" ms")
    finally:
        decoded.set()
        window.transport.playing = False


def test_a_camera_without_a_frame_in_the_set_says_so_and_how_far_its_nearest_is(
        qtbot, window) -> None:
    """At a set whose camera got no frame, the tile said "no frame near the playhead"
    and the line under the grid a skew of 0.0 ms from the one frame left."""
    from dataclasses import replace

    from speechcal_core.session.model import FrameChoice

    model = window.model
    first = model.session.sets[0]
    keep, *gone = first.frames
    frames = (keep, *(FrameChoice(f.stream, -1, first.t_ns, flags=("no-frame",))
                      for f in gone))
    model.session.sets[0] = replace(first, frames=frames)
    model.go_to_set(0)
    window._refresh_playhead()
    for f in gone:
        message = window.grid.tiles[f.stream].message
        assert message.startswith("no frame for this set: this camera's nearest is ")
        assert message.endswith(" s away")
    assert "· skew – ·" in window.info_line.full_text


def test_double_click_enlarges_a_camera_and_escape_returns(qtbot, window) -> None:
    name = window.model.streams[1]
    qtbot.mouseDClick(window.grid.tiles[name], Qt.MouseButton.LeftButton)
    assert [n for n, t in window.grid.tiles.items() if t.isVisible()] == [name]
    # the enlarged view says that the others are hidden and how to get them back
    others = len(window.grid.tiles) - 1
    assert window.grid.tiles[name].footnote == (
        f"{others} other cameras hidden · Esc or double-click: all cameras")
    qtbot.keyClick(window, Qt.Key.Key_Escape)
    assert all(t.isVisible() for t in window.grid.tiles.values())
    assert not any(t.footnote for t in window.grid.tiles.values())


def test_bad_session_file_is_reported_not_crashed_on(qtbot, tmp_path: Path) -> None:
    path = tmp_path / "broken.json"
    path.write_text(json.dumps({"schema": 99}))
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.open(session_path=str(path))
    qtbot.waitUntil(lambda: win.task is None, timeout=10_000)
    assert "newer SpeechCal" in win.load_error
    assert "newer SpeechCal" in win.status_text.text()


def test_review_screenshot_command_writes_a_png(truth_session_file: Path, tmp_path: Path) -> None:
    shot = tmp_path / "window.png"
    result = subprocess.run(
        [sys.executable, "-m", "speechcal_core.cli", "review", str(truth_session_file),
         "--screenshot", str(shot)],
        capture_output=True, text=True, timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert shot.stat().st_size > 20_000


def test_offset_buttons_and_clap_drag_edit_the_sync(qtbot, window, truth_session_file) -> None:
    before = window.model.session.sync.offset_ns
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    window.saver.flush()  # the save written off the UI thread
    assert window.model.session.sync.offset_ns == before + 1_000_000
    assert "edited" in window.sync_line.text()
    clap = window.waveform.clap
    clap.setValue(clap.value() + 0.010)  # drag the clap handle 10 ms later
    clap.sigPositionChangeFinished.emit(clap)
    window.saver.flush()
    assert window.model.session.sync.offset_ns == pytest.approx(before + 11_000_000, abs=2)
    assert load_session(truth_session_file).sync.offset_ns == window.model.session.sync.offset_ns


def test_demo_button_opens_the_demo_session_and_processes_it(
    qtbot, tiny_synth, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import shutil

    folder, _truth = tiny_synth
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    shutil.copytree(folder, tmp_path / "speechcal" / "demo")  # an earlier demo is reused
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    qtbot.mouseClick(win.demo_button, Qt.MouseButton.LeftButton)
    # while it is processed, the first page says so (it said "Open a calibration
    # session", its buttons on, through a minute of processing)
    assert win.empty_text.text().startswith("<h2>Opening…</h2>")
    assert not win.demo_button.isEnabled() and not win.open_button.isEnabled()
    qtbot.waitUntil(lambda: win.task is None, timeout=120_000)
    assert win.load_error == ""
    assert "Open a calibration session" in win.empty_text.text() and win.demo_button.isEnabled()
    assert win.model is not None and len(win.model.session.sets) >= 1
    assert (tmp_path / "speechcal" / "demo" / "recording.speechcal.json").exists()


def test_a_cancelled_opening_gives_the_first_page_back_with_no_problem_named(
        qtbot, tiny_synth, tmp_path: Path) -> None:
    """Cancel while a recording was processed said "Could not open: cancelled" in amber
    on the first page, as if something had gone wrong."""
    folder, truth = tiny_synth
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    win.open(recording=[str(folder / truth["recording"])], audio=str(folder / "audio.ogg"),
             new_session_path=str(tmp_path / "s.json"))
    assert not win.open_button.isEnabled()
    win.cancel_task()
    qtbot.waitUntil(lambda: win.task is None, timeout=60_000)
    assert win.model is None and win.load_error == ""
    assert win.status_text.text() == "opening cancelled"
    assert not win.open_problem.isVisible() and win.open_button.isEnabled()
    assert "Open a calibration session" in win.empty_text.text()


def test_a_recording_whose_clap_is_not_heard_opens_with_the_audio_at_its_start(
        qtbot, tiny_synth, tmp_path: Path) -> None:
    """Audio started after the clap: the window said so and sent the operator to the
    command line (sync --audio-clap, process --offset-ns). The first page now offers to
    open it anyway, the offset to be set in the review."""
    import soundfile as sf

    folder, truth = tiny_synth
    samples, rate = sf.read(str(folder / "audio.ogg"))
    start = int((truth["claps"][0]["audio_s"] + 0.5) * rate)  # cut after the clap
    cut = tmp_path / "late.flac"
    sf.write(str(cut), samples[start:], rate)
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    win.open(recording=[str(folder / truth["recording"])], audio=str(cut),
             new_session_path=str(tmp_path / "s.json"))
    qtbot.waitUntil(lambda: win.task is None, timeout=60_000)
    assert win.model is None and "no clap found in the audio" in win.open_problem.text()
    assert win.no_clap_button.isVisible()
    qtbot.mouseClick(win.no_clap_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: win.task is None, timeout=120_000)
    assert win.model is not None and win.load_error == ""
    sync = win.model.session.sync
    assert sync.source == "assumed" and sync.offset_ns == win.model.time_range_ns()[0]
    # nobody edited the offset yet: the line said "edited ✎"
    assert "assumed, not measured" in win.sync_line.toolTip()
    assert "edited" not in win.sync_line.toolTip()
    assert "no clap: the audio is taken to start with the first frame" \
        in win.status_text.toolTip() + win.status_text.text()
    # the note promised a count on the offset line, which says none below ten words (nor
    # while enough of them fall at a still board): it says when the line warns
    assert len(win.model.session.sets) < 10 and "words at a still board" not in \
        win.sync_line.toolTip()
    assert "counts them" not in win.status_text.toolTip()
    assert "of ten words or more, the line under the waveform warns while too few do" \
        in win.status_text.toolTip()
    assert not win.no_clap_button.isVisible()
    assert load_session(tmp_path / "s.json").sync.offset_ns == sync.offset_ns
    qtbot.keyClick(win, Qt.Key.Key_BraceRight)  # the operator moves it: edited now
    assert win.model.session.sync.source == "manual"
    assert "edited ✎" in win.sync_line.toolTip()
    qtbot.keyClick(win, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert "assumed, not measured" in win.sync_line.toolTip()
    # no clap to drag: the audio's start is the handle that sets the offset (a key press
    # moved it one frame, so seconds off took a hundred presses)
    wave = win.waveform
    assert wave.clap.isVisible() and wave.clap.label.toPlainText() == "◂ audio start ▸"
    assert wave.clap.value() == pytest.approx(wave._to_x(sync.offset_ns), abs=1e-6)
    wave.clap.setValue(wave.clap.value() + 2.5)
    wave.clap.sigDragged.emit(wave.clap)
    wave.clap.sigPositionChangeFinished.emit(wave.clap)
    moved = win.model.session.sync
    assert moved.source == "manual"
    assert moved.offset_ns - sync.offset_ns == pytest.approx(2.5e9, abs=1e6)
    assert "audio start dragged" in win.status_text.toolTip() + win.status_text.text()


def test_t_adds_a_set_at_the_playhead_and_delete_removes_it(
    qtbot, window, truth_session_file
) -> None:
    model = window.model
    rows = window.table.model().rowCount()
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    model.set_playhead((a + b) // 2)
    marks = {i: window.waveform.mark_extent(i) for i in window.waveform.marks.ids()}
    qtbot.keyClick(window, Qt.Key.Key_T)
    window.saver.flush()  # the save written off the UI thread
    assert window.table.model().rowCount() == rows + 1
    assert len(window.waveform.marks) == rows + 1
    assert {i: window.waveform.mark_extent(i) for i in marks} == marks
    assert window.table.selectedIndexes()[0].row() == 1 == model.current
    assert cell(window.table, 1, 0).text == str(model.current_set.id)
    assert cell(window.table, 1, column("word")).text.endswith(" · added")
    assert len(load_session(truth_session_file).sets) == rows + 1
    assert "T add · Del remove" in window.help_line.text()
    qtbot.keyClick(window, Qt.Key.Key_Delete)
    window.saver.flush()  # the save written off the UI thread
    assert window.table.model().rowCount() == rows
    assert {i: window.waveform.mark_extent(i) for i in window.waveform.marks.ids()} == marks
    assert len(load_session(truth_session_file).sets) == rows
    assert window.counts_label.text().endswith(f"? {rows} undecided")


def test_between_sets_the_band_names_the_set_the_keys_act_on(qtbot, window) -> None:
    """Scrubbed away from the current set, A / R / Del still act on it: the band says
    which, and Del's status message names the set it removed."""
    model = window.model
    model.go_to_set(1)
    kept = model.current_set.id
    a, b = (set_time_ns(s) for s in model.session.sets[2:4])
    model.set_playhead((a + b) // 2)
    assert window.grid.word_band.decides == kept
    qtbot.keyClick(window, Qt.Key.Key_Delete)
    window.saver.flush()  # the save written off the UI thread
    assert all(s.id != kept for s in model.session.sets)
    assert window.status_text.text() == f"set #{kept} removed · Ctrl+Z puts it back"
    qtbot.keyClick(window, Qt.Key.Key_U)
    window.saver.flush()  # the save written off the UI thread
    assert any(s.id == kept for s in model.session.sets)
    assert window.status_text.text() == f"undone: removing set {kept}"  # not "removed"
    qtbot.waitUntil(window.redo_action.isEnabled)
    window.redo_action.trigger()  # as the menu entry or Ctrl+Y
    assert all(s.id != kept for s in model.session.sets)
    assert window.status_text.text() == f"redone: removing set {kept}"


def test_with_every_set_removed_the_list_and_band_say_so(qtbot, window) -> None:
    """The empty list said no trigger word was found in the audio, and the word band
    "J / K go to one", though the operator had just removed them all."""
    while window.model.session.sets:
        qtbot.keyClick(window, Qt.Key.Key_Delete)
    assert window.no_sets_label.isVisible()
    assert window.no_sets_label.text().startswith(
        "▲ No frame sets left: every “capture” was removed (Ctrl+Z puts the last back).")
    assert band_text(window.grid.word_band.word, None, "", window.grid.word_band.decides) \
        == "no frame sets · T adds one at the playhead"
    qtbot.keyClick(window, Qt.Key.Key_U)
    assert window.table.model().rowCount() == 1 and not window.no_sets_label.isVisible()


def test_a_lone_set_removed_is_not_taken_for_a_word_never_heard(
        qtbot, open_window, truth_session_file, tmp_path) -> None:
    """A session of one set (one word heard): Del on it left the empty list saying no
    “capture” was found in the audio, as if none had been heard, where Ctrl+Z puts it
    back; so too after redoing the removal."""
    from speechcal_core.session.store import save_session

    session = load_session(truth_session_file)
    session.sets[:] = session.sets[:1]
    path = tmp_path / "one_set.json"
    save_session(session, path)
    window = open_window(path)
    removed = "▲ No frame sets left: every “capture” was removed (Ctrl+Z puts the last back)."
    qtbot.keyClick(window, Qt.Key.Key_Delete)
    assert not window.model.session.sets
    assert window.no_sets_label.text().startswith(removed)
    qtbot.keyClick(window, Qt.Key.Key_U)
    assert not window.no_sets_label.isVisible()
    window.run_action("redo")
    assert window.no_sets_label.text().startswith(removed)


def test_add_and_remove_buttons_do_what_t_and_delete_do(qtbot, window) -> None:
    model = window.model
    rows = window.table.model().rowCount()
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    model.set_playhead((a + b) // 2)
    qtbot.mouseClick(window.add_button, Qt.MouseButton.LeftButton)
    assert window.table.model().rowCount() == rows + 1
    assert model.current_set.trigger.source == "manual"
    qtbot.mouseClick(window.remove_button, Qt.MouseButton.LeftButton)
    assert window.table.model().rowCount() == rows
    assert all(s.trigger.source != "manual" for s in model.session.sets)


def test_waveform_keeps_no_samples_and_draws_the_file_ones_zoomed_in(window) -> None:
    import numpy as np

    from speechcal_core.audio import load_audio
    from speechcal_core.audio.file_samples import FileSamples

    view = window.waveform
    pyramid = view.pyramid
    loaded = load_audio(window.model.session.audio)
    assert isinstance(pyramid.source, FileSamples)  # the samples stay in the file
    assert pyramid.size == loaded.samples.size
    levels = sum(a.nbytes + b.nbytes for _, a, b in pyramid.levels)
    assert levels < loaded.samples.nbytes / 20  # plus the stretch last drawn, if any
    mid_ns = int(view.sync.to_session(loaded.duration_s / 2))
    view.setXRange(view._to_x(mid_ns), view._to_x(mid_ns + 5_000_000), padding=0)
    view.redraw()
    xs, ys = view._upper.getData()
    drawn = ys / view.drawn_scale
    first = int(np.floor(float(view.sync.to_audio(view._to_ns(xs[0]))) * loaded.rate + 0.5))
    assert 100 < drawn.size < 1000  # raw samples: 5 ms of audio
    np.testing.assert_allclose(drawn, loaded.samples[first:first + drawn.size], atol=1e-6)
