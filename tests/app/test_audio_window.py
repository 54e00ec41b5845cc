"""Hearing the audio in the review window: W plays the word of the set under the playhead,
Space plays from the playhead, which follows what the audio output has played, and a drag
restarts the sound at most once per short interval; without an audio output (as on CI:
offscreen, no sound card) the status line says so once and everything else works.

The tests marked ``needs_output`` play for real; they run where there is an audio output
(a PulseAudio null sink will do: ``pulseaudio --start -n --load=module-null-sink
--load=module-native-protocol-unix``) and are skipped elsewhere."""

from __future__ import annotations

import shutil
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from PySide6.QtCore import Qt
from truth_sessions import truth_session

import app.audio_player
from app.audio_player import BUFFER_S, AudioPlayer, BlockReader, multimedia
from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.playback import RESTART_INTERVAL_S, WORD_MARGIN_S, PlaybackAudio
from speechcal_core.review.model import set_time_ns
from speechcal_core.session.store import save_session


def _has_output() -> bool:
    qt, _ = multimedia()
    return qt is not None and not qt.QMediaDevices.defaultAudioOutput().isNull()


needs_output = pytest.mark.skipif(
    "not _has_output()", reason="no audio output here (no sound device or sound server)")


def test_qtmultimedia_loads_from_the_installed_pyside6() -> None:
    qt, why = multimedia()
    assert qt is not None, why
    assert isinstance(qt.QMediaDevices.audioOutputs(), list)


def test_w_plays_the_word_under_the_playhead_and_leaves_the_playhead(qtbot, window) -> None:
    model = window.model
    model.go_to_set(1)
    frame_set = model.current_set
    playhead = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_W)
    trigger = frame_set.trigger
    assert window.transport.player.asked == pytest.approx((trigger.start_s - WORD_MARGIN_S,
                                                  trigger.end_s + WORD_MARGIN_S))
    assert model.playhead_ns == playhead
    text = window.status_text.text()
    if _has_output():
        assert window.transport.player.playing
        assert f"playing set {frame_set.id}'s word \"{trigger.word}\"" in text
        qtbot.waitUntil(lambda: not window.transport.player.playing, timeout=5_000)  # ~1 s word
    else:
        assert "no audio output: no sound device found" in text
        qtbot.keyClick(window, Qt.Key.Key_W)
        assert window.status_text.text().count("no audio output") == 1
    qtbot.keyClick(window, Qt.Key.Key_K)  # the window goes on as before
    assert model.current == 2


def test_w_on_a_set_added_by_hand_plays_a_second_around_it(qtbot, window) -> None:
    model = window.model
    sets = model.session.sets
    gap_ns = (set_time_ns(sets[1]) + set_time_ns(sets[2])) // 2
    model.set_playhead(gap_ns)
    qtbot.keyClick(window, Qt.Key.Key_T)
    added = model.current_set
    assert added.trigger.source == "manual"
    qtbot.keyClick(window, Qt.Key.Key_W)
    t_s = added.trigger.t_s
    assert window.transport.player.asked == pytest.approx((t_s - 0.5, t_s + 0.5))
    if _has_output():
        assert (f"set {added.id} was added by hand and has no word bounds: playing 1 s "
                "around its time") in window.status_text.text()
    else:
        assert "no audio output" in window.status_text.text()


def test_w_away_from_any_set_says_where_to_go(qtbot, window) -> None:
    model = window.model
    model.set_playhead(model.time_range_ns()[0])
    assert model.set_at_playhead() is None
    qtbot.keyClick(window, Qt.Key.Key_W)
    assert "no frame set at the playhead" in window.status_text.text()
    assert window.transport.player.asked is None


def test_space_moves_the_playhead_and_a_jump_plays_on_from_there(qtbot, window) -> None:
    model = window.model
    model.go_to_set(0)
    start = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert window.transport.player.asked[0] == pytest.approx(model.session.sync.to_audio(start))
    qtbot.waitUntil(lambda: model.playhead_ns > start + 200_000_000, timeout=5_000)
    if not _has_output():
        assert window.status_text.text().count("no audio output: no sound device found") == 1
    qtbot.keyClick(window, Qt.Key.Key_K)  # a jump while playing: play goes on from there
    jumped = set_time_ns(model.session.sets[1])
    assert window.transport.player.asked[0] == pytest.approx(model.session.sync.to_audio(jumped))
    qtbot.waitUntil(lambda: model.playhead_ns > jumped + 100_000_000, timeout=5_000)
    assert model.playhead_ns < jumped + 2_000_000_000  # not back where play started
    if not _has_output():
        assert window.status_text.text().count("no audio output") == 1  # said once
    qtbot.keyClick(window, Qt.Key.Key_Space)  # pause: playhead and sound stop
    assert not window.transport.player.playing
    paused = model.playhead_ns
    qtbot.wait(150)
    assert model.playhead_ns == paused


def test_transport_buttons_under_the_grid_step_sets_and_play_and_pause(qtbot, window) -> None:
    model = window.model
    model.go_to_set(1)
    previous, play, next_ = window.transport_buttons
    qtbot.mouseClick(next_, Qt.MouseButton.LeftButton)
    assert model.current_set.id == model.session.sets[2].id
    qtbot.mouseClick(previous, Qt.MouseButton.LeftButton)
    qtbot.mouseClick(previous, Qt.MouseButton.LeftButton)
    assert model.current_set.id == model.session.sets[0].id
    start = model.playhead_ns
    assert play.text() == "▶ play"
    qtbot.mouseClick(play, Qt.MouseButton.LeftButton)
    assert play.text() == "❚❚ pause" and "Space" in play.toolTip()
    qtbot.waitUntil(lambda: model.playhead_ns > start + 100_000_000, timeout=5_000)
    qtbot.mouseClick(play, Qt.MouseButton.LeftButton)
    assert play.text() == "▶ play" and not window.transport.player.playing
    paused = model.playhead_ns
    qtbot.wait(150)
    assert model.playhead_ns == paused
    qtbot.keyClick(window, Qt.Key.Key_Space)  # the key and the button are one switch
    assert play.text() == "❚❚ pause"
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert play.text() == "▶ play"


def test_play_button_shows_play_again_when_the_session_ends(qtbot, window) -> None:
    model = window.model
    _, end_ns = model.time_range_ns()
    model.set_playhead(end_ns - 200_000_000)
    qtbot.mouseClick(window.transport.button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: window.transport.button.text() == "▶ play", timeout=5_000)
    assert not window.transport.playing
    start_ns, _ = model.time_range_ns()
    qtbot.mouseClick(window.transport.button, Qt.MouseButton.LeftButton)  # again: from the start
    assert window.transport.playing and model.playhead_ns < start_ns + 200_000_000
    qtbot.mouseClick(window.transport.button, Qt.MouseButton.LeftButton)


def test_without_qtmultimedia_the_window_says_so_and_plays_on(
        qtbot, window, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(app.audio_player, "_multimedia", None)
    monkeypatch.setattr(app.audio_player, "_multimedia_error", "")
    monkeypatch.setitem(sys.modules, "PySide6.QtMultimedia", None)  # import fails
    model = window.model
    qtbot.keyClick(window, Qt.Key.Key_W)
    assert "no audio output: QtMultimedia cannot be loaded" in window.status_text.text()
    start = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Space)
    qtbot.waitUntil(lambda: model.playhead_ns > start + 100_000_000, timeout=5_000)
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert window.status_text.text().count("no audio output") == 1


def test_a_moved_audio_file_is_named(qtbot, open_window, tiny_synth, tmp_path: Path) -> None:
    folder, truth = tiny_synth
    copy = tmp_path / "session"
    shutil.copytree(folder, copy)  # the shared session's audio stays where it is
    save_session(truth_session(copy, truth), tmp_path / "review.json")
    window = open_window(tmp_path / "review.json")
    audio = Path(window.inputs.session.audio)
    assert str(copy) in str(audio)
    audio.rename(tmp_path / "moved.ogg")
    qtbot.keyClick(window, Qt.Key.Key_W)
    text = window.status_text.text()
    assert f"cannot play the audio: {audio}: audio file not found" in text
    start = window.model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Space)  # the frames play on, silent: said so
    qtbot.waitUntil(lambda: window.model.playhead_ns > start + 100_000_000, timeout=5_000)
    assert window.status_text.text().startswith(
        f"playing without sound: cannot play the audio: {audio}: audio file not found")
    qtbot.keyClick(window, Qt.Key.Key_Space)


def test_the_reader_thread_reads_the_stretch_block_by_block(tiny_synth) -> None:
    folder, truth = tiny_synth
    audio = PlaybackAudio(folder / truth["audio"])
    reader = BlockReader(audio.blocks(2.0, 4.1, block_s=0.25))
    got: list[bytes] = []
    while True:
        reader.join(0.01)
        item = reader.take()
        if item is app.audio_player._END:
            break
        if isinstance(item, bytes):
            got.append(item)
    assert b"".join(got) == audio.clip(2.0, 4.1).to_bytes()
    assert len(got) == 9  # eight quarter seconds and a tenth


def test_a_reader_stopped_early_lets_go(tiny_synth) -> None:
    folder, truth = tiny_synth
    reader = BlockReader(PlaybackAudio(folder / truth["audio"]).blocks(0.0))
    reader.join(0.2)  # it fills its queue, then waits
    first = reader.take()
    assert isinstance(first, bytes) and np.frombuffer(first, "<i2").size > 0
    reader.stop()
    reader.join(1.0)
    assert not reader._thread.is_alive()


def test_a_reader_hands_over_the_files_error(tmp_path: Path) -> None:
    path = tmp_path / "a.wav"
    sf.write(str(path), np.zeros(48000, dtype=np.float32), 48000)
    audio = PlaybackAudio(path)
    path.unlink()
    reader = BlockReader(audio.blocks(0.0))
    reader.join(1.0)
    error = reader.take()
    assert isinstance(error, AudioError) and "a.wav" in str(error)


@needs_output
def test_the_sound_goes_as_far_as_the_output_has_played(qtbot, qapp, tiny_synth) -> None:
    folder, truth = tiny_synth
    said: list[str] = []
    player = AudioPlayer(None, say=said.append)
    player.set_source(folder / truth["audio"])
    try:
        t0 = time.monotonic()
        assert player.play(2.0, 3.0), said
        seen: list[tuple[float, float]] = []
        while player.playing and time.monotonic() - t0 < 6.0:
            heard = player.heard_s()
            seen.append((time.monotonic() - t0, heard))
            qtbot.wait(10)
        assert not player.playing  # it stopped by itself, at the stretch's end
        got = np.array(seen)
        assert got[0, 1] == 2.0  # nothing heard before the output starts
        assert (np.diff(got[:, 1]) >= 0).all()
        assert got[-1, 1] > 2.9
        # never ahead of the clock, and a buffer behind it once the sink is fed
        assert (got[:, 1] - 2.0 <= got[:, 0] + 0.02).all()
        moving = got[(got[:, 1] > 2.05) & (got[:, 1] < 2.9)]
        assert len(moving) > 10
        rate = (moving[-1, 1] - moving[0, 1]) / (moving[-1, 0] - moving[0, 0])
        assert rate == pytest.approx(1.0, abs=0.2)  # the sound's own pace
    finally:
        player.shutdown()


@needs_output
def test_a_start_past_the_audios_end_says_there_is_no_sound(qapp, tiny_synth) -> None:
    folder, truth = tiny_synth
    said: list[str] = []
    player = AudioPlayer(None, say=said.append)
    player.set_source(folder / truth["audio"])
    assert not player.play(60.0, lead_in=True)
    end_s = PlaybackAudio(folder / truth["audio"]).duration_s
    assert said == [f"no sound here: the audio file holds audio seconds 0 to {end_s:.3f}"]
    assert player.play(-0.3, 0.2, lead_in=True)  # before the start: silence, then sound
    assert player.heard_s() == pytest.approx(-0.3)
    player.shutdown()


@needs_output
def test_the_playhead_shows_what_is_heard_not_the_clock(qtbot, window) -> None:
    model = window.model
    sync = model.session.sync
    model.go_to_set(0)
    start = model.playhead_ns
    t0 = time.monotonic()
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert window.transport.player.playing
    qtbot.waitUntil(lambda: model.playhead_ns > start + 300_000_000, timeout=6_000)
    for _ in range(10):
        heard = window.transport.player.heard_s()
        assert heard is not None
        # one step (40 ms) apart at most, the sound's pace in between
        assert abs(model.playhead_ns - sync.to_session(heard)) < 70_000_000
        # the clock would be ahead by what the sink holds (and its start-up)
        clock = start + int((time.monotonic() - t0) * 1e9)
        assert model.playhead_ns < clock - BUFFER_S / 2 * 1e9
        qtbot.wait(30)
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert not window.transport.player.playing


def _play_from_set_1(qtbot, window) -> tuple[int, int]:
    """Space at frame set 1, then a restart interval later: the playhead where play
    started, and the player's play count by then."""
    window.model.go_to_set(1)
    start = window.model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Space)
    qtbot.wait(int(RESTART_INTERVAL_S * 1000) + 50)
    return start, window.transport.player.plays


def _drag(qtbot, window, move, positions) -> list[int]:
    """``move`` to each of ``positions`` 10 ms apart (the mouse moves of a drag); the
    playhead after each."""
    after = []
    for value in positions:
        move(value)
        qtbot.wait(10)
        after.append(window.model.playhead_ns)
    return after


def test_dragging_the_playhead_while_playing_restarts_the_sound_now_and_then(
        qtbot, window) -> None:
    model = window.model
    start, plays = _play_from_set_1(qtbot, window)
    t0 = time.monotonic()
    positions = [start + k * 20_000_000 for k in range(1, 41)]  # 40 moves, 0.8 s forward
    after = _drag(qtbot, window, model.set_playhead, positions)
    dragged_s = time.monotonic() - t0
    qtbot.wait(int(RESTART_INTERVAL_S * 1000) + 50)  # the last restart, from the last move
    restarts = window.transport.player.plays - plays
    assert 2 <= restarts <= dragged_s / RESTART_INTERVAL_S + 2  # not one a move
    sync = model.session.sync
    assert window.transport.player.asked[0] == pytest.approx(sync.to_audio(positions[-1]))
    # the playhead stays with the mouse: sound of the stretch before does not pull it back
    for pos, now in zip(positions, after, strict=True):
        assert pos <= now < pos + 60_000_000
    assert window.transport.playing
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert not window.transport.player.playing


def test_dragging_the_clap_while_playing_lets_the_sound_play_on(qtbot, window) -> None:
    """The playhead follows the sound as it plays: a drag's preview pulled it (and the
    sound, restarted from there) away at every move. Released, the offset moves and the
    playhead with the sound under it, which plays on from there."""
    model = window.model
    set_ns, plays = _play_from_set_1(qtbot, window)
    shifts = [k * 5_000_000 for k in range(1, 41)]  # the handle 0.2 s on, 5 ms a move
    _drag(qtbot, window, window.waveform.clap_dragging.emit, shifts)
    assert window.transport.player.plays == plays  # no restart
    sync, playhead = model.session.sync, model.playhead_ns
    window.waveform.clap_moved.emit(shifts[-1])  # released: the offset is applied
    assert model.playhead_ns == pytest.approx(playhead + shifts[-1], abs=1)
    moved_ns = set_time_ns(model.current_set)
    assert model.current == 1 and moved_ns != set_ns  # the set moved with the offset
    # and the sound plays on from where it was, through the new offset
    assert window.transport.player.asked[0] == pytest.approx(sync.to_audio(playhead))
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert not window.transport.player.playing
