"""A recording with the microphone recorded into the bag opens in the window with that
audio topic as its audio (``speechcal review RECORDING --audio /audio/audio``)."""

from __future__ import annotations

import json
from pathlib import Path

from audio_topic_bags import TOPIC, with_audio_topic

from speechcal_core.cli import main


def test_review_of_a_recording_takes_its_audio_topic_and_names_it(
        new_window, qtbot, tiny_synth: tuple[Path, dict], tmp_path: Path) -> None:
    folder, truth = tiny_synth
    bag = tmp_path / "recording.bag"
    with_audio_topic(folder / truth["recording"], folder / truth["audio"], bag,
                     truth["sync"]["offset_ns"])
    session = tmp_path / "s.json"
    assert main(["review", str(bag), "--audio", TOPIC, "--session", str(session),
                 "--screenshot", str(tmp_path / "x.png")]) == 0
    doc = json.loads(session.read_text())
    assert doc["audio"] == "s.audio.flac" and doc["audio_topic"] == TOPIC
    assert doc["sets"] and doc["sync"]["source"] == "stamped"
    win = new_window()
    win.open(session_path=str(session))
    qtbot.waitUntil(lambda: win.model is not None, timeout=60_000)
    assert win.windowTitle() == f"SpeechCal — recording.bag + {TOPIC}"
    assert win.inputs is not None and win.inputs.no_waveform == ""  # the file kept


def test_the_offset_line_of_a_stamped_topic_says_no_negative_zero_drift(
        new_window, qtbot, tiny_synth: tuple[Path, dict], tmp_path: Path) -> None:
    """The stamps' slope over a recording with no drift comes out a hair below 1
    (-2e-16): the offset line said "drift -0.0 ppm", as if the microphone ran slow."""
    folder, truth = tiny_synth
    bag = tmp_path / "recording.bag"
    with_audio_topic(folder / truth["recording"], folder / truth["audio"], bag,
                     truth["sync"]["offset_ns"])
    session = tmp_path / "s.json"
    assert main(["process", str(bag), "--audio", TOPIC, "-o", str(session)]) == 0
    win = new_window()
    win.open(session_path=str(session))
    qtbot.waitUntil(lambda: win.model is not None, timeout=60_000)
    assert abs(win.model.session.sync.drift) < 1e-9  # the synthetic topic has none
    line = win.sync_line.toolTip() or win.sync_line.text()
    assert "drift 0.0 ppm" in line and "stamped" in line
    assert "-0.0" not in line
