"""The waveform marks every clap: the first as the handle that sets the offset, a later
one (the drift's) as a plain mark that moves with the sync."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from set_list_cells import cell

from speechcal_core.session.store import load_session, save_session


def test_a_second_clap_is_marked_and_follows_the_offset(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    session = load_session(truth_session_file)
    first = session.sync_evidence["claps"][0]
    second_audio_s = first["audio_s"] + 9.5
    session.sync_evidence["claps"] = [first, {"audio_s": second_audio_s}]
    path = tmp_path / "two_claps.json"
    save_session(session, path)
    window = open_window(path)
    wave = window.waveform
    (mark,) = wave.later_claps
    expected = wave._to_x(int(window.model.session.sync.to_session(second_audio_s)))
    assert mark.value() == pytest.approx(expected, abs=1e-6)
    assert not mark.movable and "clap 2" in mark.label.toPlainText()
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # offset +1 ms
    (mark,) = wave.later_claps
    assert mark.value() == pytest.approx(expected + 0.001, abs=1e-6)


def test_an_offset_edit_places_the_claps_once(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path, monkeypatch) -> None:
    """An offset edit placed the claps twice (the sync's, then the session's), making
    the later claps' lines anew each time."""
    import pyqtgraph as pg

    path = _two_claps_file(truth_session_file, tmp_path)
    second_s = load_session(path).sync_evidence["claps"][1]["audio_s"]
    window = open_window(path)
    wave = window.waveform
    placed, lines_added = [], []
    set_claps, add_item = wave.set_claps, wave.addItem

    def counted_set_claps(claps_audio_s) -> None:
        placed.append(tuple(claps_audio_s))
        set_claps(claps_audio_s)

    def counted_add_item(item, *args, **kwargs) -> None:
        if isinstance(item, pg.InfiniteLine):
            lines_added.append(item)
        add_item(item, *args, **kwargs)

    monkeypatch.setattr(wave, "set_claps", counted_set_claps)
    monkeypatch.setattr(wave, "addItem", counted_add_item)
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # offset +1 ms
    assert placed == [tuple(window.model.session.claps_audio_s())]
    assert lines_added == wave.later_claps and len(lines_added) == 1
    expected = wave._to_x(int(window.model.session.sync.to_session(second_s)))
    assert wave.later_claps[0].value() == pytest.approx(expected, abs=1e-6)


def test_sync_line_drops_the_automatic_residuals_once_the_offset_is_edited(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    session = load_session(truth_session_file)
    session.sync_evidence["cameras"] = [{"name": "/cam0/image_raw", "residual_ns": 1_400_000},
                                        {"name": "/cam1/image_raw", "residual_ns": -300_000}]
    path = tmp_path / "residuals.json"
    save_session(session, path)
    window = open_window(path)
    assert "camera residuals ≤ 1.4 ms" in window.sync_line.text()
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    assert "edited" in window.sync_line.text()
    assert "residuals" not in window.sync_line.text()


def test_one_clap_or_one_camera_is_not_shown_as_measured(
        open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """"drift 0.0 ppm · camera residuals ≤ 0.0 ms" read as measured, where one clap
    measures no drift and one camera has no other to differ from."""
    session = load_session(truth_session_file)
    session.sync_evidence["claps"] = session.sync_evidence["claps"][:1]
    session.sync = replace(session.sync, drift=0.0)
    session.sync_evidence["cameras"] = [{"name": "/cam0/image_raw", "residual_ns": 0}]
    path = tmp_path / "one.json"
    save_session(session, path)
    text = open_window(path).sync_line.text()
    assert "drift not measured (one clap)" in text and "residuals" not in text


def test_an_offset_given_without_a_clap_does_not_speak_of_one_clap(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """A session made with an offset given (process --offset-ns) holds no clap at all,
    yet the line said "drift not measured (one clap)"."""
    session = load_session(truth_session_file)
    session.sync = replace(session.sync, drift=0.0, source="manual")
    session.sync_evidence = {}
    path = tmp_path / "given.json"
    save_session(session, path)
    window = open_window(path)
    assert "drift not measured (no clap)" in window.sync_line.text()
    window.resize(960, 1040)
    qtbot.waitUntil(lambda: window.width() == 960, timeout=5_000)
    assert "one clap" not in window.sync_line.shown_text()


def test_a_camera_that_timed_only_the_first_clap_wrongly_is_no_alarm(
        open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """In line at the second clap, its clock is right and the others set the offset:
    the amber "clap +105.5 ms off the others" asked for a fix there was none to make."""
    session = load_session(truth_session_file)
    period = 66_666_667
    session.sync_evidence["cameras"] = [
        {"name": f"/cam{k}/image_raw", "residual_ns": r0, "residuals_ns": [r0, r1],
         "period_ns": period}
        for k, (r0, r1) in enumerate([(1_800_000, 2_700_000), (105_500_000, -800_000),
                                      (0, 300_000)])]
    note = ("/cam1/image_raw: clap +105.5 ms off the other cameras at the first clap but "
            "in line at the second: it did not time the first clap well, its clock is "
            "right; the other cameras set the offset, nothing to do")
    session.sync_evidence["warnings"] = [note]
    path = tmp_path / "misread.json"
    save_session(session, path)
    window = open_window(path)
    text = window.sync_line.text()
    assert not text.startswith("▲") and "color" not in window.sync_line.styleSheet()
    assert "camera residuals ≤ 1.8 ms" in text
    assert note in window.sync_line.toolTip()


def test_sync_line_names_a_camera_whose_clap_sits_a_frame_off_in_amber(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """A camera clap timed wrongly (or a clock that is off) was a neutral "residuals
    ≤ 176.5 ms": the line now names the camera and turns amber, the note as tooltip."""
    session = load_session(truth_session_file)
    session.sync_evidence["cameras"] = [
        {"name": "/cam0/image_raw", "residual_ns": 1_400_000, "period_ns": 66_666_667},
        {"name": "/cam2/image_raw", "residual_ns": 176_500_000, "period_ns": 66_666_667}]
    session.sync_evidence["warnings"] = ["/cam2/image_raw: clap +176.5 ms off the other "
                                         "cameras; its clock may be off"]
    path = tmp_path / "off.json"
    save_session(session, path)
    window = open_window(path)
    text = window.sync_line.text()
    assert text.startswith("▲ ") and "/cam2/image_raw clap +176.5 ms off the others" in text
    assert "/cam0" not in text
    assert "color" in window.sync_line.styleSheet()
    assert "\n/cam2/image_raw: clap +176.5 ms off" in window.sync_line.toolTip()
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # an edited offset: no residuals
    assert not window.sync_line.text().startswith("▲") and not window.sync_line.styleSheet()

def test_sync_line_says_after_when_the_audio_starts_after_the_first_frame(
        qtbot, open_window, truth_session_file: Path) -> None:
    window = open_window(truth_session_file)
    model = window.model
    lead_ns = model.time_range_ns()[0] - model.session.sync.offset_ns
    assert lead_ns > 0  # the synthetic audio starts before the first frame
    assert f"{lead_ns / 1e9:.3f} s before the first frame · drift " in window.sync_line.text()
    model.nudge_offset(lead_ns + 1_183_000_000)  # the clap dragged far to the right
    assert window.sync_line.text().startswith(
        "audio starts 1.183 s after the first frame · drift ")
    model.nudge_offset(-1_183_000_000)
    assert window.sync_line.text().startswith("audio starts with the first frame · ")


def test_info_line_names_the_set_by_the_id_the_list_shows(
        qtbot, open_window, truth_session_file: Path) -> None:
    window = open_window(truth_session_file)
    window.model.go_to_set(1)
    window.model.remove_set()  # positions and ids part ways
    current = window.model.current_set
    n = len(window.model.session.sets)
    assert window.info_line.full_text.startswith(f"set #{current.id} (2/{n}) · skew ")


def test_info_line_says_when_the_word_was_said_as_the_list_does(
        qtbot, open_window, truth_session_file: Path) -> None:
    """The playhead stands on the set's frames, often a little after the word: the line
    gives the word's time in the list's own form, so the two figures are not mistaken."""
    window = open_window(truth_session_file)
    window.model.go_to_set(2)
    row = window.model.session.sets.index(window.model.current_set)
    listed = cell(window.table, row, 1).text
    assert f" · said at {listed} · t = " in window.info_line.full_text


def _two_claps_file(truth_session_file: Path, tmp_path: Path, shift_s: float = 0.0) -> Path:
    """The truth session with a second clap late in the recording (the drift's), its
    offset ``shift_s`` later than the truth's (as a manual edit saved earlier leaves it)."""
    session = load_session(truth_session_file)
    first = session.sync_evidence["claps"][0]
    session.sync_evidence["claps"] = [first, {"audio_s": first["audio_s"] + 9.5}]
    session.sync = session.sync.with_offset(session.sync.offset_ns + round(shift_s * 1e9))
    path = tmp_path / "two_claps.json"
    save_session(session, path)
    return path


def _marks_x(wave) -> list[float]:
    """Where the clap handle, the later claps and both ends of every trigger mark are."""
    regions = [wave.marks.region(set_id) for set_id in wave.marks.ids()]
    return [wave.clap.value(), *(line.value() for line in wave.later_claps),
            *(x for region in regions for x in region)]


def _view(wave) -> tuple[float, float]:
    x0, x1 = wave.getViewBox().viewRange()[0]
    return x0, x1


def _drag_clap(wave, by_s: float) -> None:
    """Drag the clap handle ``by_s`` seconds and let go, as the mouse does."""
    wave.clap.setValue(wave.clap.value() + by_s)
    wave.clap.sigDragged.emit(wave.clap)
    wave.clap.sigPositionChangeFinished.emit(wave.clap)


def test_a_large_offset_edit_widens_the_view_to_every_clap_and_trigger_mark(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    window = open_window(_two_claps_file(truth_session_file, tmp_path))
    wave = window.waveform
    x0, x1 = _view(wave)
    assert all(x0 <= x <= x1 for x in _marks_x(wave))
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # a small edit: the view stays
    assert _view(wave) == (x0, x1)

    _drag_clap(wave, 3.0)  # clap 2 (and the last words) beyond the session's end
    (mark,) = wave.later_claps
    assert mark.value() > window.waveform._to_x(window.model.time_range_ns()[1])
    v0, v1 = _view(wave)
    assert v0 == pytest.approx(x0) and v1 > x1
    assert all(v0 <= x <= v1 for x in _marks_x(wave))
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # small edits after it: it stays
    qtbot.keyClick(window, Qt.Key.Key_BraceRight)
    assert _view(wave) == (v0, v1)
    assert all(v0 <= x <= v1 for x in _marks_x(wave))

    _drag_clap(wave, -8.0)  # far the other way: the first words before the first frame
    w0, w1 = _view(wave)
    assert w0 < v0 and w1 == pytest.approx(v1)  # widened, never narrowed
    assert all(w0 <= x <= w1 for x in _marks_x(wave))


def test_a_session_opened_with_its_offset_edited_far_shows_every_mark(
        open_window, truth_session_file: Path, tmp_path: Path) -> None:
    window = open_window(_two_claps_file(truth_session_file, tmp_path, shift_s=4.0))
    wave = window.waveform
    (mark,) = wave.later_claps
    assert mark.value() > wave._to_x(window.model.time_range_ns()[1])
    x0, x1 = _view(wave)
    assert all(x0 <= x <= x1 for x in _marks_x(wave))


def test_a_zoomed_in_view_keeps_its_zoom_through_an_offset_edit(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    window = open_window(_two_claps_file(truth_session_file, tmp_path))
    wave = window.waveform
    x0, x1 = _view(wave)
    zoom = (x0 + 0.2 * (x1 - x0), x0 + 0.5 * (x1 - x0))
    wave.setXRange(*zoom, padding=0)
    zoom = _view(wave)
    _drag_clap(wave, 3.0)
    assert _view(wave) == zoom
    wave.setXRange(-1e6, 1e6, padding=0)  # zoomed out as far as the wheel goes
    v0, v1 = _view(wave)
    assert all(v0 <= x <= v1 for x in _marks_x(wave))
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # zoomed out further than the whole
    assert _view(wave) == (v0, v1)


def test_clock_text_rounds_before_splitting_minutes() -> None:
    from app.set_table import clock_text

    assert clock_text(4.39) == "00:04.39"
    assert clock_text(59.996) == "01:00.00"
    assert clock_text(125.5) == "02:05.50"
    assert clock_text(-0.4) == "-00:00.40"
    assert clock_text(-0.001) == "00:00.00"


def test_an_offset_edit_moves_the_trigger_marks(
        qtbot, open_window, truth_session_file: Path) -> None:
    window = open_window(truth_session_file)
    wave = window.waveform
    before = _marks_x(wave)
    labels = [m.set_id for m in wave.marks.shown_labels()]
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)  # +1 ms
    after = _marks_x(wave)
    regions = after[1 + len(wave.later_claps):]
    assert regions == pytest.approx([x + 0.001 for x in before[1 + len(wave.later_claps):]],
                                    abs=1e-6)
    assert [m.set_id for m in wave.marks.shown_labels()] == labels


def test_sync_line_warns_while_many_words_fall_in_a_move_until_the_offset_is_right(
        qtbot, open_window, noisy_synth, tmp_path: Path) -> None:
    """A session processed with the offset a second off (another session's audio looks
    the same): amber, with what to do in the tooltip; put right, the warning goes once
    the sets are re-scored."""
    from truth_sessions import searched_session, truth_sync

    folder, truth = noisy_synth
    sync = truth_sync(truth)
    path = tmp_path / "offset_off.json"
    save_session(searched_session(folder, truth, sync.with_offset(sync.offset_ns + 10**9)),
                 path)
    window = open_window(path)
    text = window.sync_line.text()
    assert text.startswith("▲ ") and " words at a still board" in text
    assert "Is the audio this recording's?" in window.sync_line.toolTip()
    assert "color" in window.sync_line.styleSheet()
    window.model.nudge_offset(-10**9)
    qtbot.waitUntil(lambda: not window.rescorer.busy(), timeout=30_000)
    assert not window.sync_line.text().startswith("▲") and not window.sync_line.styleSheet()
    assert window.model.word_stillness().judged == len(truth["triggers"])


def test_c_moves_the_audio_so_the_sound_at_the_playhead_is_the_clap(
        qtbot, open_window, truth_session_file: Path) -> None:
    window = open_window(truth_session_file)
    model = window.model
    seen = model.camera_clap_ns()
    taken = window.waveform.clap.value()  # the sound taken for the clap
    model.set_playhead(seen - 1_250_000_000)
    qtbot.keyClick(window, Qt.Key.Key_C)
    assert model.session.sync.source == "manual"
    assert window.status_text.text() == \
        "the clap is at the playhead: audio moved +1.250 s · Ctrl+Z takes it back"
    # the clap handle marks the sound named the clap, now where the cameras saw it
    assert window.waveform.clap.value() == pytest.approx(window.waveform._to_x(seen),
                                                         abs=0.001)
    assert model.session.sync_evidence["claps"][0]["audio_source"] == "manual"
    window.saver.flush()
    saved = load_session(truth_session_file).sync_evidence["claps"][0]
    heard = model.session.sync.to_audio(seen)
    assert saved["audio_source"] == "manual" and saved["audio_s"] == pytest.approx(heard)
    qtbot.keyClick(window, Qt.Key.Key_U)  # the handle goes back to the sound taken before
    assert window.waveform.clap.value() == pytest.approx(taken, abs=0.001)
    assert model.session.sync_evidence["claps"][0].get("audio_source") != "manual"


def test_c_says_a_shift_under_a_millisecond_and_when_the_clap_was_there_already(
        qtbot, window) -> None:
    """Zoomed in on the clap, C moves the audio by microseconds: it said "+0.000 s"; with
    the clap at the playhead already it made no step yet said "Ctrl+Z takes it back"."""
    model = window.model
    seen = model.camera_clap_ns()
    model.set_playhead(seen - 400_000)
    qtbot.keyClick(window, Qt.Key.Key_C)
    assert window.status_text.text() == \
        "the clap is at the playhead: audio moved +400 µs · Ctrl+Z takes it back"
    assert model.undo_label == "audio offset change"
    model.undo()
    assert model.undo_label == ""
    model.set_playhead(seen)  # the clap handle clicked: the playhead on it
    qtbot.keyClick(window, Qt.Key.Key_C)
    assert window.status_text.text() == \
        "the clap is at the playhead already: the audio did not move, nothing to undo"
    assert model.undo_label == ""


def test_undoing_a_large_clap_shift_gives_the_view_back_as_it_was(
        qtbot, open_window, truth_session_file: Path) -> None:
    """C with the playhead seconds from the clap widens the view to the moved marks;
    undone, the marks are back where they were and so is the view (it stayed wide)."""
    window = open_window(truth_session_file)
    wave, model = window.waveform, window.model
    before = _view(wave)
    model.set_playhead(model.time_range_ns()[1] - 1_000_000_000)  # far from the clap
    qtbot.keyClick(window, Qt.Key.Key_C)
    assert _view(wave)[0] < before[0] - 5.0
    qtbot.keyClick(window, Qt.Key.Key_U)
    assert _view(wave) == pytest.approx(before, abs=1e-6)
    assert wave.whole == pytest.approx(before, abs=1e-6)
    qtbot.keyClick(window, Qt.Key.Key_Y, Qt.KeyboardModifier.ControlModifier)  # redo
    v0, v1 = _view(wave)
    assert v0 < before[0] - 5.0 and all(v0 <= x <= v1 for x in _marks_x(wave))


def test_a_half_screen_window_shows_the_sync_line_s_figures_in_shorter_words(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """At 960 px (half a 1920 px screen) a one-clap session's line was cut at "camera
    residu…": the figures lost for words. Shorter words keep every figure in view; the
    tooltip still has the line whole."""
    session = load_session(truth_session_file)
    session.sync_evidence["claps"] = session.sync_evidence["claps"][:1]
    session.sync = replace(session.sync, drift=0.0)
    session.sync_evidence["cameras"] = [{"name": "/cam0/image_raw", "residual_ns": 1_400_000},
                                        {"name": "/cam1/image_raw", "residual_ns": -300_000}]
    path = tmp_path / "one_clap.json"
    save_session(session, path)
    window = open_window(path)
    window.resize(960, 1040)
    qtbot.waitUntil(lambda: window.width() == 960, timeout=5_000)
    line = window.sync_line
    assert "drift not measured (one clap)" in line.text()  # whole, as the tooltip
    assert line.toolTip().startswith(line.text())
    shown = line.shown_text()
    assert "…" not in shown and "one clap" in shown and shown.endswith("residuals ≤ 1.4 ms")
    assert "before" in shown and "auto ✓" in shown
    assert line.fontMetrics().horizontalAdvance(shown) <= line.contentsRect().width()


def test_a_narrow_window_keeps_a_sync_warning_before_the_figures(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    """A warning comes first and in shorter words too: the camera off the others stays
    named at 960 px, the figures after it shortened."""
    session = load_session(truth_session_file)
    session.sync_evidence["cameras"] = [
        {"name": "/cam0/image_raw", "residual_ns": 300_000},
        {"name": "/cam1/image_raw", "residual_ns": 176_500_000, "period_ns": 66_666_667}]
    path = tmp_path / "off.json"
    save_session(session, path)
    window = open_window(path)
    window.resize(960, 1040)
    qtbot.waitUntil(lambda: window.width() == 960, timeout=5_000)
    shown = window.sync_line.shown_text()
    assert shown.startswith("▲ /cam1/image_raw clap +176.5 ms off") and "…" not in shown
    assert "before" in shown and "drift" in shown
