"""Hearing the audio in the review window: W plays the word of the set under the playhead,
Space plays from the playhead; without an audio output (as here and on CI: offscreen, no
sound card) the status line says so once and everything else works."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from PySide6.QtCore import Qt

import app.audio_player
from app.audio_player import BlockReader, multimedia
from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.playback import WORD_MARGIN_S, PlaybackAudio
from speechcal_core.review.model import set_time_ns


def _has_output() -> bool:
    qt, _ = multimedia()
    return qt is not None and not qt.QMediaDevices.defaultAudioOutput().isNull()


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
    assert window.player.asked == pytest.approx((trigger.start_s - WORD_MARGIN_S,
                                                  trigger.end_s + WORD_MARGIN_S))
    assert model.playhead_ns == playhead
    text = window.status_text.text()
    if _has_output():
        assert window.player.playing
        assert f"playing set {frame_set.id}'s word \"{trigger.word}\"" in text
        qtbot.waitUntil(lambda: not window.player.playing, timeout=5_000)  # ~1 s word
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
    assert window.player.asked == pytest.approx((t_s - 0.5, t_s + 0.5))
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
    assert window.player.asked is None


def test_space_moves_the_playhead_and_a_jump_plays_on_from_there(qtbot, window) -> None:
    model = window.model
    model.go_to_set(0)
    start = model.playhead_ns
    qtbot.keyClick(window, Qt.Key.Key_Space)
    assert window.player.asked[0] == pytest.approx(model.session.sync.to_audio(start))
    qtbot.waitUntil(lambda: model.playhead_ns > start + 200_000_000, timeout=5_000)
    if not _has_output():
        assert window.status_text.text().count("no audio output: no sound device found") == 1
    qtbot.keyClick(window, Qt.Key.Key_K)  # a jump while playing: play goes on from there
    jumped = set_time_ns(model.session.sets[1])
    assert window.player.asked[0] == pytest.approx(model.session.sync.to_audio(jumped))
    qtbot.waitUntil(lambda: model.playhead_ns > jumped + 100_000_000, timeout=5_000)
    assert model.playhead_ns < jumped + 2_000_000_000  # not back where play started
    if not _has_output():
        assert window.status_text.text().count("no audio output") == 1  # said once
    qtbot.keyClick(window, Qt.Key.Key_Space)  # pause: playhead and sound stop
    assert not window.player.playing
    paused = model.playhead_ns
    qtbot.wait(150)
    assert model.playhead_ns == paused


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


def test_a_moved_audio_file_is_named(qtbot, window, tmp_path: Path) -> None:
    audio = Path(window.inputs.session.audio)
    moved = tmp_path / "moved.ogg"
    audio.rename(moved)
    try:
        qtbot.keyClick(window, Qt.Key.Key_W)
        text = window.status_text.text()
        assert f"cannot play the audio: {audio}: audio file not found" in text
    finally:
        moved.rename(audio)


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
