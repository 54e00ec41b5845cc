"""Loading audio files of every supported kind, rate and channel count."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from audio_files import write_spliced_ogg

from speechcal_core.audio import AudioError, load_audio, resample
from speechcal_core.audio.identity import audio_identity
from speechcal_core.audio.loader import UNKNOWN_FRAMES, load_resampled


def _write(path: Path, data: np.ndarray, rate: int, **kw) -> Path:
    with sf.SoundFile(str(path), "w", samplerate=rate,
                      channels=1 if data.ndim == 1 else data.shape[1], **kw) as f:
        for i in range(0, data.shape[0], 4096):  # DESIGN §5: write Ogg in blocks
            f.write(data[i:i + 4096])
    return path


def _tone(rate: int, seconds: float = 1.0, hz: float = 440.0) -> np.ndarray:
    t = np.arange(int(rate * seconds)) / rate
    return (0.5 * np.sin(2 * np.pi * hz * t)).astype(np.float32)


@pytest.mark.parametrize("rate", [8000, 16000, 44100, 96000])
def test_wav_any_rate_loads_mono_float32(tmp_path: Path, rate: int) -> None:
    p = _write(tmp_path / "a.wav", _tone(rate), rate)
    a = load_audio(p)
    assert a.rate == rate and a.samples.dtype == np.float32 and a.samples.ndim == 1
    assert a.duration_s == pytest.approx(1.0)
    assert a.channels_in_file == 1


def test_stereo_mixes_or_picks_channel(tmp_path: Path) -> None:
    left, right = _tone(16000), np.zeros(16000, np.float32)
    p = _write(tmp_path / "s.flac", np.stack([left, right], axis=1), 16000)
    mixed = load_audio(p)
    assert mixed.channels_in_file == 2
    assert np.allclose(mixed.samples, left / 2, atol=1e-3)
    assert np.allclose(load_audio(p, channel=0).samples, left, atol=1e-3)
    assert np.allclose(load_audio(p, channel=1).samples, 0.0, atol=1e-3)
    with pytest.raises(AudioError, match="channel 2"):
        load_audio(p, channel=2)


@pytest.mark.parametrize(("name", "kw"), [
    ("a.ogg", {"format": "OGG", "subtype": "VORBIS"}),
    ("a.opus", {"format": "OGG", "subtype": "OPUS"}),
    ("a.mp3", {"format": "MP3", "subtype": "MPEG_LAYER_III"}),
    ("a.flac", {}),
])
def test_compressed_formats_load(tmp_path: Path, name: str, kw: dict) -> None:
    p = _write(tmp_path / name, _tone(48000, 2.0), 48000, **kw)
    a = load_audio(p, rate=16000)
    assert a.rate == 16000 and a.rate_in_file == 48000
    assert a.duration_s == pytest.approx(2.0, abs=0.08)
    assert 0.2 < float(np.sqrt(np.mean(a.samples[4000:20000] ** 2))) < 0.5


def test_resample_matches_tone_and_length() -> None:
    x = _tone(96000, 3.0, 1000.0)
    y = resample(x, 96000, 16000)
    assert y.size == 48000
    ref = _tone(16000, 3.0, 1000.0)
    assert np.max(np.abs(y[100:-100] - ref[100:-100])) < 1e-3


def test_blockwise_resample_equals_one_call(monkeypatch: pytest.MonkeyPatch) -> None:
    from scipy.signal import resample_poly

    import speechcal_core.audio.resampling as rs

    rng = np.random.default_rng(0)
    x = rng.standard_normal(50_000).astype(np.float32)
    monkeypatch.setattr(rs, "BLOCK", 4096)
    y = rs.resample(x, 44100, 16000)
    ref = resample_poly(x, 160, 441)
    assert y.size == ref.size
    assert np.max(np.abs(y - ref)) < 1e-4


def test_missing_file_names_it(tmp_path: Path) -> None:
    with pytest.raises(AudioError, match=r"nope\.wav: audio file not found"):
        load_audio(tmp_path / "nope.wav")


def test_empty_and_garbage_files_are_refused(tmp_path: Path) -> None:
    (tmp_path / "empty.wav").write_bytes(b"")
    with pytest.raises(AudioError, match="empty"):
        load_audio(tmp_path / "empty.wav")
    (tmp_path / "junk.ogg").write_bytes(b"this is not audio" * 100)
    with pytest.raises(AudioError, match="not a readable audio file"):
        load_audio(tmp_path / "junk.ogg")
    p = _write(tmp_path / "zero.wav", np.zeros(0, np.float32), 16000)
    with pytest.raises(AudioError, match="no audio samples"):
        load_audio(p)


def test_a_phone_recorders_m4a_is_refused_naming_how_to_convert_it(tmp_path: Path) -> None:
    """libsndfile has no AAC decoder: "not a readable audio file (Format not recognised)"
    said nothing of what the file is or how to get one that reads."""
    p = tmp_path / "mic take 1.m4a"
    # an MPEG-4 audio file's first box, as a phone's voice recorder writes it
    p.write_bytes(b"\x00\x00\x00\x20ftypM4A \x00\x00\x00\x00M4A mp42isom" + bytes(4000))
    with pytest.raises(AudioError) as info:
        load_audio(p)
    assert str(info.value) == (f"{p}: M4A audio is not read; convert it to WAV or FLAC "
                               "first, e.g. ffmpeg -i 'mic take 1.m4a' 'mic take 1.wav'")


def test_a_file_whose_header_does_not_know_its_length_loads_what_decodes(
        tmp_path: Path) -> None:
    p = write_spliced_ogg(tmp_path / "spliced.ogg", 16000, 40.0, seed=3)
    assert sf.info(str(p)).frames >= UNKNOWN_FRAMES  # the case itself, as libsndfile sees it
    audio = load_audio(p)
    assert 16000 < audio.samples.size <= 40 * 16000
    resampled, size_in = load_resampled(p, 8000)
    assert size_in == audio.samples.size
    assert resampled.samples.size == -(-size_in // 2)
    assert audio_identity(p) is None  # no length to tell this file from another by


def _with_non_numbers(rate: int, share: float, value: float = float("nan")) -> np.ndarray:
    """A tone whose first ``share`` of samples, spread through it, are ``value``."""
    x = _tone(rate, 2.0)
    bad = np.random.default_rng(3).permutation(x.size)[:int(share * x.size)]
    x[bad] = value
    return x


def test_scattered_nan_and_inf_read_as_silence(tmp_path: Path) -> None:
    """A few samples that are no numbers (a glitch in a float WAV) become 0 (inf full
    scale); the rest of the take is used."""
    x = _with_non_numbers(16000, 0.01)
    x[5] = float("inf")
    p = _write(tmp_path / "glitch.wav", x, 16000, subtype="FLOAT")
    a = load_audio(p)
    assert np.all(np.isfinite(a.samples))
    assert a.samples[np.isnan(x)].max() == 0.0 and a.samples[5] == 1.0
    assert np.array_equal(load_resampled(p, 16000)[0].samples, a.samples)


@pytest.mark.parametrize(("share", "value"), [(1.0, float("nan")), (1.0, float("-inf")),
                                              (0.6, float("nan"))])
def test_audio_mostly_not_numbers_is_refused_as_damaged(tmp_path: Path, share: float,
                                                        value: float) -> None:
    """Audio with no (or few) real samples was read as silence, and detection said "no
    speech": the file is damaged, and every way of reading it says so, naming it."""
    from speechcal_core.audio.envelope import EnvelopePyramid

    p = _write(tmp_path / "mic.wav", _with_non_numbers(16000, share, value), 16000,
               subtype="FLOAT")
    said = "all" if share == 1.0 else "60%"
    for read in (lambda: load_audio(p), lambda: load_audio(p, rate=8000),
                 lambda: load_resampled(p, 8000), lambda: EnvelopePyramid.from_file(p)):
        with pytest.raises(AudioError) as err:
            read()
        assert str(err.value).startswith(f"{p}: the audio is damaged: {said} of its ")
        assert "NaN or infinite" in str(err.value)
