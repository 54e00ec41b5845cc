"""``process`` and a new review session take the microphone from an audio topic of the
recording, as ``sync`` does: its samples are kept as a file beside the session."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from audio_topic_bags import TOPIC, true_words, with_audio_topic

from speechcal_core.cli import main


@pytest.fixture
def topic_bag(tiny_synth: tuple[Path, dict], tmp_path: Path) -> tuple[Path, np.ndarray]:
    """The tiny session's recording with its microphone in the bag, stamped."""
    folder, truth = tiny_synth
    bag = tmp_path / "rec" / "recording.bag"
    bag.parent.mkdir()
    held = with_audio_topic(folder / truth["recording"], folder / truth["audio"], bag,
                            truth["sync"]["offset_ns"])
    return bag, held


def test_process_takes_a_stamped_audio_topic_and_keeps_its_audio_beside_the_session(
        topic_bag: tuple[Path, np.ndarray], tiny_synth: tuple[Path, dict], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    from speechcal_core.session.store import load_session

    _folder, truth = tiny_synth
    bag, held = topic_bag
    out = tmp_path / "s.json"
    args = ["process", str(bag), "--audio", TOPIC, "--transcript",
            str(true_words(truth, tmp_path / "words.csv")), "-o", str(out), "--json"]
    assert main(args) == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    kept = tmp_path / "s.audio.flac"
    assert doc["audio"] == str(kept.absolute()) and doc["audio_topic"] == TOPIC
    assert doc["sync"]["source"] == "stamped" and doc["notes"] == []
    assert f"the audio of topic {TOPIC} of recording.bag is kept as {kept}" in captured.err
    session = load_session(out)
    assert Path(session.audio) == kept.absolute() and session.extra["audio_topic"] == TOPIC
    assert abs(session.sync.offset_ns - truth["sync"]["offset_ns"]) < 1_000_000
    assert len(session.sets) == len(truth["triggers"])
    assert all(f.index >= 0 for s in session.sets for f in s.frames)
    # the file holds the topic's samples as they were, losslessly
    written, _rate = sf.read(str(kept), dtype="int16", always_2d=True)
    assert np.array_equal(written, held) and sf.info(str(kept)).format == "FLAC"
    assert session.extra["audio_file"]["channels"] == 1
    # again, replacing the session: the same audio is not written twice
    assert main([*args, "--force"]) == 0
    assert sorted(p.name for p in tmp_path.glob("s.audio*")) == ["s.audio.flac"]


def test_a_stereo_topic_with_unset_stamps_is_timed_by_the_clap_on_its_channel(
        tiny_synth: tuple[Path, dict], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    """Stamps left unset (0): the clap times the audio and a note says why; --channel
    picks the microphone's, kept in the session with every channel in the file. A file
    of that name holding other audio is left as it is."""
    from speechcal_core.session.store import load_session

    folder, truth = tiny_synth
    bag = tmp_path / "rec.bag"
    held = with_audio_topic(folder / truth["recording"], folder / truth["audio"], bag,
                            truth["sync"]["offset_ns"], unset=True, mic_channel=1)
    other = tmp_path / "s.audio.flac"
    sf.write(str(other), np.zeros(1000, np.int16), 16000)
    before = other.read_bytes()
    out = tmp_path / "s.json"
    assert main(["process", str(bag), "--audio", TOPIC, "--channel", "1", "--transcript",
                 str(true_words(truth, tmp_path / "words.csv")), "-o", str(out),
                 "--json"]) == 0
    captured = capsys.readouterr()
    doc = json.loads(captured.out)
    said = (f"{TOPIC}: its chunks' header stamps are unset (0), so they cannot time the "
            "audio; the clap does")
    assert doc["notes"] == [said] and f"note: {said}" in captured.err
    assert doc["sync"]["source"] == "auto"
    session = load_session(out)
    assert abs(session.sync.offset_ns - truth["sync"]["offset_ns"]) < 40_000_000
    assert session.audio_channel == 1
    assert other.read_bytes() == before  # not another's: a new name
    kept = Path(session.audio)
    assert kept.parent == tmp_path.absolute() and kept != other.absolute()
    assert np.array_equal(sf.read(str(kept), dtype="int16", always_2d=True)[0], held)


def test_an_audio_topic_not_in_the_recording_is_named_with_those_it_holds(
        topic_bag: tuple[Path, np.ndarray], tiny_synth: tuple[Path, dict], tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    folder, truth = tiny_synth
    bag, _held = topic_bag
    out = tmp_path / "s.json"
    assert main(["process", str(bag), "--audio", "/mic/audio", "--offset-ns",
                 str(truth["sync"]["offset_ns"]), "-o", str(out), "--json"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.strip().splitlines()[-1].endswith(
        "/mic/audio: audio file not found, and not an audio topic of the recording either "
        f"(audio topics: {TOPIC})")
    assert not out.exists() and not list(tmp_path.glob("s.audio*"))
    # a recording without any audio topic says so too
    assert main(["process", str(folder / truth["recording"]), "--audio", TOPIC,
                 "-o", str(out)]) == 1
    assert "(audio topics: none)" in capsys.readouterr().err


def test_a_new_review_session_takes_the_audio_topic_and_reopens_with_it(
        topic_bag: tuple[Path, np.ndarray], tmp_path: Path) -> None:
    from speechcal_core.review.loading import load_for_review

    bag, held = topic_bag
    inputs = load_for_review(recording=[str(bag)], audio=TOPIC)
    try:
        session = inputs.session
        kept = bag.parent / "recording.speechcal.audio.flac"
        assert Path(session.audio) == kept.absolute()
        assert session.sync.source == "stamped" and session.sets
        assert f"audio from topic {TOPIC} of recording.bag, kept as {kept.name}" in inputs.note
        assert inputs.pyramid is not None and inputs.no_waveform == ""
        assert inputs.pyramid.duration_s == pytest.approx(held.shape[0] / sf.info(
            str(kept)).samplerate)
    finally:
        inputs.close()
    again = load_for_review(recording=[str(bag)], audio=TOPIC)
    try:
        assert again.note.startswith("opened the existing recording.speechcal.json")
        assert "it uses the audio" not in again.note
    finally:
        again.close()


def test_a_session_whose_kept_topic_audio_is_gone_writes_it_again_from_the_topic(
        topic_bag: tuple[Path, np.ndarray], tmp_path: Path) -> None:
    """The session file and the bag copied without the audio file kept beside them: the
    recording still holds the topic, so opening the session writes the file again."""
    from speechcal_core.review.loading import load_for_review

    bag, held = topic_bag
    out = tmp_path / "rec" / "s.json"
    assert main(["process", str(bag), "--audio", TOPIC, "-o", str(out)]) == 0
    kept = out.with_name("s.audio.flac")
    kept.unlink()
    inputs = load_for_review(session_path=str(out))
    try:
        assert kept.exists()
        assert np.array_equal(sf.read(str(kept), dtype="int16", always_2d=True)[0], held)
        assert f"its audio file was gone: written again from topic {TOPIC} of " \
               "recording.bag" in inputs.note
        assert inputs.pyramid is not None and inputs.no_waveform == ""
    finally:
        inputs.close()
