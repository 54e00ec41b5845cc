"""The waveform marks every clap: the first as the handle that sets the offset, a later
one (the drift's) as a plain mark that moves with the sync."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtCore import Qt

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


def test_sync_line_drops_the_automatic_residuals_once_the_offset_is_edited(
        qtbot, open_window, truth_session_file: Path, tmp_path: Path) -> None:
    session = load_session(truth_session_file)
    session.sync_evidence["cameras"] = [{"name": "/cam0/image_raw", "residual_ns": 1_400_000}]
    path = tmp_path / "residuals.json"
    save_session(session, path)
    window = open_window(path)
    assert "camera residuals ≤ 1.4 ms" in window.sync_line.text()
    qtbot.keyClick(window, Qt.Key.Key_BracketRight)
    assert "edited" in window.sync_line.text()
    assert "residuals" not in window.sync_line.text()


def test_info_line_names_the_set_by_the_id_the_list_shows(
        qtbot, open_window, truth_session_file: Path) -> None:
    window = open_window(truth_session_file)
    window.model.go_to_set(1)
    window.model.remove_set()  # positions and ids part ways
    current = window.model.current_set
    n = len(window.model.session.sets)
    assert f"set #{current.id} (2 of {n})" in window.info_line.text()
