"""An audio file cut short (a copy that stopped early, a recorder that lost power) whose
header promises more than decodes: the operator is told, and playing past what decodes
gives silence instead of an error blaming a moved file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.audio import AudioError, load_audio
from speechcal_core.audio.loader import cut_short_note, load_resampled
from speechcal_core.audio.playback import PlaybackAudio
from speechcal_core.cli import main

RATE = 16000


@pytest.fixture(scope="module")
def cut_flac(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 10 s FLAC file of which only the first half of the bytes is left."""
    folder = tmp_path_factory.mktemp("cut")
    whole = folder / "whole.flac"
    noise = 0.1 * np.random.default_rng(2).standard_normal(10 * RATE)
    sf.write(whole, noise.astype(np.float32), RATE)
    cut = folder / "mic.flac"
    data = whole.read_bytes()
    cut.write_bytes(data[:len(data) // 2])
    return cut


def test_a_cut_file_loads_what_decodes_and_knows_its_header_length(cut_flac: Path) -> None:
    audio = load_audio(cut_flac)
    assert audio.header_s == 10.0
    assert 2.0 < audio.duration_s < 6.0
    assert load_resampled(cut_flac, 8000)[0].header_s == 10.0
    assert audio.resampled(8000).header_s == 10.0
    assert cut_short_note(audio) == (
        f"{cut_flac}: only the first {audio.duration_s:.1f} s of the 10.0 s its header "
        "gives decode; the file is cut short or damaged (a copy that stopped early, a "
        "recorder that lost power), and the rest is left out: copy the take again if you "
        "have it whole")


def test_a_whole_file_gets_no_note(cut_flac: Path) -> None:
    assert cut_short_note(load_audio(cut_flac.parent / "whole.flac")) == ""


def test_detect_says_the_file_is_cut_short(cut_flac: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["detect", str(cut_flac), "--json"]) == 0
    err = capsys.readouterr().err
    assert f"note: {cut_flac}: only the first" in err and "cut short or damaged" in err


def test_playing_past_what_decodes_is_silence(cut_flac: Path) -> None:
    loaded = load_audio(cut_flac).samples
    player = PlaybackAudio(cut_flac)
    assert player.duration_s == 10.0  # as the header says: the session's times reach there
    start = 2 * RATE
    stretch = player.samples.read(start, 8 * RATE)
    np.testing.assert_array_equal(stretch[:loaded.size - start], loaded[start:])
    assert not np.any(player.samples.read(7 * RATE, 8 * RATE))


def test_no_clap_in_a_cut_file_blames_the_file_not_the_clap(cut_flac: Path) -> None:
    """The clap lay in the part that does not decode: ``sync`` and ``process`` (which
    syncs before it detects, so the detector's note never showed) said only "no clap
    found ... clap once, sharply", sending the operator to record again."""
    from speechcal_core.sync.errors import SyncError
    from speechcal_core.sync.pipeline import heard_claps

    with pytest.raises(SyncError) as err:
        heard_claps(load_audio(cut_flac))
    msg = str(err.value)
    assert msg.startswith(f"{cut_flac}: no clap found in the audio")
    assert "header gives decode; the file is cut short or damaged" in msg
    assert "copy the take again if you have it whole" in msg and "\n" not in msg
    assert msg.count(str(cut_flac)) == 1


def _wav_cut(folder: Path, data_size: int | None = None) -> Path:
    """A 10 s 16-bit WAV file of which the first 40% of the bytes is left (its data
    chunk's size set to ``data_size`` first, as a recorder may leave it)."""
    whole = folder / "whole.wav"
    sf.write(whole, 0.1 * np.random.default_rng(3).standard_normal(10 * RATE), RATE,
             subtype="PCM_16")
    data = bytearray(whole.read_bytes())
    at = data.index(b"data") + 4
    if data_size is not None:
        data[at:at + 4] = data_size.to_bytes(4, "little")
    cut = folder / "mic.wav"
    cut.write_bytes(bytes(data[:int(0.4 * len(data))]))
    return cut


def test_a_cut_wav_file_is_named_cut_short_by_its_data_chunk(tmp_path: Path,
                                                             capsys: pytest.CaptureFixture[str]
                                                             ) -> None:
    """libsndfile gives a WAV file the length of what is left of it: a copy that stopped
    half way through seemed a whole, shorter take."""
    cut = _wav_cut(tmp_path)
    audio = load_audio(cut)
    assert audio.header_s == 10.0 and audio.duration_s == pytest.approx(4.0, abs=0.01)
    assert load_resampled(cut, 8000)[0].header_s == 10.0
    assert cut_short_note(audio).startswith(f"{cut}: only the first 4.0 s of the 10.0 s its "
                                            "header gives decode")
    assert main(["detect", str(cut), "--json"]) == 0
    assert f"note: {cut}: only the first 4.0 s of the 10.0 s" in capsys.readouterr().err


def test_a_streamed_wav_file_of_unknown_length_gets_no_note(tmp_path: Path) -> None:
    assert cut_short_note(load_audio(_wav_cut(tmp_path, 0xFFFFFFFF))) == ""
    assert cut_short_note(load_audio(tmp_path / "whole.wav")) == ""


def test_a_wav_file_whose_header_never_got_its_length_says_how_to_repair_it(
        tmp_path: Path) -> None:
    """libsndfile reads none of it: the file was said to hold no audio samples, and to be
    recorded again."""
    cut = _wav_cut(tmp_path, 0)
    with pytest.raises(AudioError) as exc:
        load_audio(cut)
    assert str(exc.value) == (
        f"{cut}: its header says it holds no audio, yet {cut.stat().st_size - 44} bytes "
        "of it follow (the "
        "recorder stopped before it wrote the length); repair the header, e.g. sox "
        "--ignore-length mic.wav fixed.wav, and give that file")
    with pytest.raises(AudioError, match="sox --ignore-length"):
        load_resampled(cut, 8000)
