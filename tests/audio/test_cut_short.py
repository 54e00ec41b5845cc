"""An audio file cut short (a copy that stopped early, a recorder that lost power) whose
header promises more than decodes: the operator is told, and playing past what decodes
gives silence instead of an error blaming a moved file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.audio import load_audio
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
