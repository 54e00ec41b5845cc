"""Stretches of an audio file read back from the file equal the loaded (resampled) array."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from audio_files import write_gated_tone

from speechcal_core.audio import load_audio
from speechcal_core.audio.file_samples import FileSamples
from speechcal_core.audio.loader import load_resampled
from speechcal_core.review.similar import SessionAudio
from speechcal_core.speech.speech_index import SpeechIndex


def _write(path: Path, rate: int, seconds: float, channels: int, **kw) -> Path:
    return write_gated_tone(path, rate, seconds, channels, seed=7, tone_hz=440.0, gate_hz=0.7, **kw)


@pytest.mark.parametrize(("name", "rate", "channels", "kw"), [
    ("a.ogg", 48000, 2, {"format": "OGG", "subtype": "VORBIS"}),  # seeks need a pre-roll
    ("a.wav", 44100, 1, {}),
    ("a.flac", 16000, 1, {}),  # no resampling
])
def test_stretches_read_back_equal_the_loaded_samples(tmp_path: Path, name: str, rate: int,
                                                     channels: int, kw: dict) -> None:
    p = _write(tmp_path / name, rate, 26.0, channels, **kw)  # > one resampling block
    native = load_audio(p)
    whole = native.resampled(16000).samples
    reader = FileSamples(p, 16000, rate_in=native.rate, size_in=native.samples.size)
    assert reader.size == len(reader) == whole.size
    rng = np.random.default_rng(1)
    spans = [(0, 300), (whole.size - 500, whole.size), (whole.size - 10, whole.size + 99),
             (5, 5)]
    spans += [(a, a + int(rng.integers(1, 12000)))
              for a in rng.integers(0, whole.size - 12000, 40).tolist()]
    for a, b in spans:
        np.testing.assert_array_equal(reader[a:b], whole[a:b], err_msg=f"{name} {a}:{b}")


def test_search_index_keeps_no_samples_array(tmp_path: Path) -> None:
    p = _write(tmp_path / "a.wav", 48000, 30.0, 1)
    index = SessionAudio(p).index()
    assert isinstance(index.samples, FileSamples)  # read back around each hit
    assert index.samples.size == 30 * 16000
    held = index.seq.nbytes + index.frames.nbytes
    assert held < 30 * 16000 * 4 / 2  # features: well under the samples' 1.9 MB


@pytest.mark.parametrize(("name", "rate", "channels", "kw"), [
    ("a.wav", 48000, 3, {}),  # two resampling blocks and a short last one
    ("a.ogg", 44100, 2, {"format": "OGG", "subtype": "VORBIS"}),
    ("a.flac", 16000, 2, {}),  # no resampling
])
def test_block_by_block_load_gives_the_samples_of_the_whole_file_load(
        tmp_path: Path, name: str, rate: int, channels: int, kw: dict) -> None:
    p = _write(tmp_path / name, rate, 47.0, channels, **kw)
    whole = load_audio(p, rate=16000)
    blocks, size_in = load_resampled(p, 16000)
    assert size_in == load_audio(p).samples.size
    assert blocks.samples.dtype == np.float32
    np.testing.assert_array_equal(blocks.samples, whole.samples)
    assert (blocks.rate, blocks.rate_in_file, blocks.channels_in_file) == (
        16000, rate, channels)


def test_search_index_features_equal_those_of_the_whole_file_load(tmp_path: Path) -> None:
    p = _write(tmp_path / "a.wav", 48000, 30.0, 2)
    index = SessionAudio(p).index()
    want = SpeechIndex.build(load_audio(p, rate=16000).samples, 16000)
    assert index.samples.size == want.samples.size
    np.testing.assert_array_equal(index.frames, want.frames)
    np.testing.assert_array_equal(index.seq, want.seq)
    assert index.n_frames == want.n_frames
    assert index.activity.segments == want.activity.segments
    np.testing.assert_array_equal(index.activity.energy_db, want.activity.energy_db)
