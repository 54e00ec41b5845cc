"""``speechcal detect``: JSON on stdout, one-line reasons and exit 1 for bad input."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from speechcal_core.cli import main


def test_json_lists_word_start_end_t_score(capture_scene, capsys: pytest.CaptureFixture[str]
                                           ) -> None:
    assert main(["detect", str(capture_scene.path), "--trigger", "Capture!", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc and all(set(d) == {"word", "start", "end", "t", "score"} for d in doc)
    assert all(d["word"] == "capture" and d["start"] < d["t"] < d["end"] for d in doc)


def test_transcript_replaces_listening(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                       ) -> None:
    csv = tmp_path / "words.csv"
    csv.write_text("word,start,end\nCapture!,1.0,1.5\ncaptured,2,2.5\n", encoding="utf-8")
    assert main(["detect", "unused.wav", "--transcript", str(csv), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == [
        {"word": "capture", "start": 1.0, "end": 1.5, "t": 1.25, "score": 1.0}]


def test_a_note_reaches_stderr_marked_as_one(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """Notes go to stderr as "note: …", as the other commands print them; stdout keeps the
    JSON list alone."""
    import numpy as np
    import soundfile as sf

    silent = tmp_path / "silent.wav"
    sf.write(silent, np.zeros(3 * 16000, np.float32), 16000)
    assert main(["detect", str(silent), "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out) == []
    assert f"note: {silent}: no speech found" in captured.err
    assert "--channel" not in captured.err  # one channel: nothing to pick


def test_nothing_found_in_mixed_channels_names_the_channel_option(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A stereo file whose second channel is another source: mixed, the microphone's
    speech may drown; the note says how to take one channel."""
    import numpy as np
    import soundfile as sf

    stereo = tmp_path / "stereo.wav"
    sf.write(stereo, np.zeros((3 * 16000, 2), np.float32), 16000)
    assert main(["detect", str(stereo)]) == 0
    err = capsys.readouterr().err
    assert f"note: {stereo}: no speech found in 3.0 s of audio; its 2 channels were " \
           "mixed: if the microphone is on one of them, pick it with --channel (0..1)" in err
    assert main(["detect", str(stereo), "--channel", "1"]) == 0
    assert "--channel" not in capsys.readouterr().err  # one was picked


def test_audio_too_coarse_for_speech_is_noted(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    import numpy as np
    import soundfile as sf

    coarse = tmp_path / "coarse.wav"
    sf.write(coarse, 0.1 * np.sin(np.arange(3000) * 0.3).astype(np.float32), 1000)
    assert main(["detect", str(coarse), "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out) == []
    assert f"note: {coarse}: recorded at 1000 Hz, too coarse for speech (it needs 8000 Hz " \
        "or more); record the microphone at 16 kHz" in captured.err

@pytest.mark.parametrize("content, expected", [
    (None, "not found"),
    (b"", "empty"),
    (b"not audio at all", "not a readable audio file"),
    # the recording or the session given in the audio's place: "convert it to WAV..." was
    # no help; what the file is, is
    (b"#ROSBAG V2.0\n" + bytes(60), "audio.wav: this is a ROS1 bag, not an audio file; give "
                                     "the microphone's audio file"),
    (b'{"schema": 1, "sets": []}', "audio.wav: this is a JSON file, not an audio file"),
])
def test_bad_audio_exits_1_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         content: bytes | None, expected: str) -> None:
    path = tmp_path / "audio.wav"
    if content is not None:
        path.write_bytes(content)
    assert main(["detect", str(path), "--json"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert expected in captured.err and captured.err.count("\n") == 1


@pytest.mark.parametrize("backend", ["faster-whisper", "whisperx"])
def test_missing_whisper_backend_says_what_to_install(capture_scene, backend: str,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["detect", str(capture_scene.path), "--backend", backend, "--json"]) == 1
    err = capsys.readouterr().err
    # the pip of the Python speechcal runs on (the venv's), not whichever is on PATH
    assert f"{sys.executable} -m pip install {backend}" in err and "pocketsphinx" in err


def test_unknown_backend_and_bad_options_are_reported(capture_scene,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["detect", str(capture_scene.path), "--backend", "vosk"]) == 2
    assert "unknown backend" in capsys.readouterr().err
    for option, says in ((["--trigger", ""], "no trigger word given"),
                         (["--trigger", "take picture"], "not a single word"),
                         (["--pronounce", "w=ZZ", "--trigger", "w"], "unknown phones"),
                         # a pronunciation of a word not looked for was ignored silently
                         (["--pronounce", "rapture=R AE P CH ER"],
                          "--pronounce rapture: not one of the trigger words (capture)"),
                         (["--trigger", "qzxv"], "not in the pocketsphinx dictionary"),
                         (["--backend", "example", "--example", "1:1.05"], "shorter than 0.1"),
                         (["--backend", "example", "--example", "7:6"],
                          "the end (6) must come after the start (7)"),
                         (["--backend", "example", "--example", "900:901"], "outside the")):
        assert main(["detect", str(capture_scene.path), *option]) == 2, option
        assert says in capsys.readouterr().err, option
    assert main(["detect", str(capture_scene.path), "--pronounce", "kaptcha"]) == 2
    assert main(["detect", str(capture_scene.path), "--example", "3"]) == 2


def test_a_trigger_after_the_recorder_resumed_is_found(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A chained Ogg file (the recorder paused and resumed: a second whole stream after
    the first): the trigger in the second stream is found, at its time in the whole file."""
    import io

    import soundfile as sf
    from speech_scenes import RATE, make_scene

    scene = make_scene(tmp_path / "scene.wav",
                       [("capture", "rms/capture_2"), ("capture", "slt/capture_1")])
    (_, end_1), (start_2, _) = scene.spans("capture")
    joint = int((end_1 + start_2) / 2 * RATE)
    takes = []
    for part in (scene.samples[:joint], scene.samples[joint:]):
        buf = io.BytesIO()
        sf.write(buf, part, RATE, format="OGG", subtype="VORBIS")
        takes.append(buf.getvalue())
    chained = tmp_path / "resumed.ogg"
    chained.write_bytes(b"".join(takes))
    assert main(["detect", str(chained), "--json"]) == 0
    found = [d["t"] for d in json.loads(capsys.readouterr().out)]
    assert len(found) == 2
    for t, (start, end) in zip(found, scene.spans("capture"), strict=True):
        assert start < t < end


def test_audio_of_nan_is_damaged_not_silent(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """A float WAV of NaN detected as "no speech": a damaged file, exit 1."""
    import numpy as np
    import soundfile as sf

    path = tmp_path / "mic.wav"
    sf.write(str(path), np.full(16000, np.nan, np.float32), 16000, subtype="FLOAT")
    assert main(["detect", str(path), "--json"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert f"{path}: the audio is damaged: all of its" in captured.err
