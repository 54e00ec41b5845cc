"""MP3 files joined byte by byte (``cat a.mp3 b.mp3 > c.mp3``): libsndfile trusts the
first file's Xing/Info header and decodes only the first take; each take is read after
the other instead, and where that cannot be done the operator is told."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf

from speechcal_core.audio import load_audio
from speechcal_core.audio.loader import cut_short_note, load_resampled
from speechcal_core.audio.mp3_join import joined_mp3_note, mp3_layout
from speechcal_core.audio.playback import PlaybackAudio
from speechcal_core.cli import main

RATE = 48000


def _mp3(seconds: float, seed: int, *, rate: int = RATE, title: str | None = None,
         **kwargs: object) -> bytes:
    """An MP3 file soundfile writes (LAME: a Xing/Info header in its first frame); with
    ``title`` libsndfile adds an ID3v1 tag at its end."""
    noise = 0.1 * np.random.default_rng(seed).standard_normal(int(seconds * rate))
    buf = io.BytesIO()
    with sf.SoundFile(buf, "w", rate, 1, format="MP3", **kwargs) as f:
        if title is not None:
            f.title = title
        f.write(noise.astype(np.float32))
    return buf.getvalue()


def _id3v2(payload: bytes = b"TIT2\x00\x00\x00\x05\x00\x00\x00take",
           padding: int = 100) -> bytes:
    """An ID3v2.3 tag holding ``payload`` and ``padding`` zero bytes, as taggers leave
    (its size in 7-bit bytes)."""
    n = len(payload) + padding
    size = bytes((n >> s) & 0x7F for s in (21, 14, 7, 0))
    return b"ID3\x03\x00\x00" + size + payload + bytes(padding)


def _decoded(data: bytes) -> np.ndarray:
    return sf.read(io.BytesIO(data), dtype="float32")[0]


@pytest.fixture(scope="module")
def takes() -> tuple[bytes, bytes]:
    return _mp3(3, 1), _mp3(5, 2)


def test_joined_takes_decode_whole(tmp_path: Path, takes: tuple[bytes, bytes]) -> None:
    first, second = takes
    joined = tmp_path / "mic.mp3"
    joined.write_bytes(first + second)
    audio = load_audio(joined)
    want = np.concatenate([_decoded(first), _decoded(second)])
    assert audio.duration_s == pytest.approx(8.0)
    # the same samples (mpg123 rounds the last bit of a float alike by the block read)
    np.testing.assert_allclose(audio.samples, want, atol=1e-6)
    assert audio.header_s == pytest.approx(8.0)
    assert cut_short_note(audio) == ""
    resampled, size_in = load_resampled(joined, 16000)
    assert size_in == want.size and resampled.duration_s == pytest.approx(8.0)
    player = PlaybackAudio(joined)
    assert player.duration_s == pytest.approx(8.0)
    np.testing.assert_allclose(player.samples.read(4 * RATE, 5 * RATE),
                               want[4 * RATE:5 * RATE], atol=1e-6)


def test_three_tagged_takes_decode_whole(tmp_path: Path) -> None:
    parts = [_id3v2() + _mp3(2, 3, title="one"), _mp3(1, 4, title="two"),
             _id3v2(padding=20000) + _mp3(2, 5)]  # a tag as long as cover art
    joined = tmp_path / "mic.mp3"
    joined.write_bytes(b"".join(parts))
    audio = load_audio(joined)
    np.testing.assert_allclose(audio.samples,
                               np.concatenate([_decoded(p) for p in parts]), atol=1e-6)
    assert cut_short_note(audio) == ""


def test_takes_at_different_rates_get_a_note(tmp_path: Path) -> None:
    first = _mp3(3, 1)
    joined = tmp_path / "mic.mp3"
    joined.write_bytes(first + _mp3(5, 2, rate=44100))
    audio = load_audio(joined)
    assert audio.duration_s == pytest.approx(3.0)
    note = cut_short_note(audio)
    assert note == joined_mp3_note(joined, audio.duration_s)
    assert note.startswith(f"{joined}: only the first 3.0 s decode, but the file holds "
                           "roughly ")
    rough = float(note.split("roughly ")[1].split(" s")[0])
    assert 6 <= rough <= 10
    assert "cat a.mp3 b.mp3" in note and "convert each take on its own" in note


def test_detect_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    joined = tmp_path / "mic.mp3"
    joined.write_bytes(_mp3(3, 1) + _mp3(5, 2, rate=44100))
    assert main(["detect", str(joined), "--json"]) == 0
    err = capsys.readouterr().err
    assert f"note: {joined}: only the first 3.0 s decode" in err


@pytest.mark.parametrize("kind", ["vbr", "cbr", "id3v1", "id3v2", "long_id3v2", "ape"])
def test_a_single_mp3_gets_no_note(tmp_path: Path, kind: str) -> None:
    data = {
        "vbr": lambda: _mp3(4, 6),
        "cbr": lambda: _mp3(4, 6, bitrate_mode="CONSTANT", compression_level=0.5),
        "id3v1": lambda: _mp3(4, 6, title="take"),
        "id3v2": lambda: _id3v2() + _mp3(4, 6, title="take"),
        "long_id3v2": lambda: _id3v2(padding=20000) + _mp3(4, 6),
        "ape": lambda: _mp3(4, 6) + _ape(),
    }[kind]()
    path = tmp_path / "mic.mp3"
    path.write_bytes(data)
    audio = load_audio(path)
    assert audio.duration_s == pytest.approx(4.0)
    layout = mp3_layout(path)
    assert layout is not None and len(layout.takes) == 1 and not layout.joined
    assert cut_short_note(audio) == ""
    assert joined_mp3_note(path, audio.duration_s) == ""


def _ape() -> bytes:
    """An APEv2 tag (header, one 6 KB item, footer): more than the slack on its own."""
    item = struct.pack("<II", 6000, 0) + b"Comment\x00" + bytes(6000)
    size = len(item) + 32

    def head(flags: int) -> bytes:
        return b"APETAGEX" + struct.pack("<IIII", 2000, size, 1, flags) + bytes(8)

    return head(0xA0000000) + item + head(0x80000000)


def test_not_an_mp3_file(tmp_path: Path) -> None:
    path = tmp_path / "mic.flac"
    sf.write(path, np.zeros(RATE, dtype=np.float32), RATE)
    assert mp3_layout(path) is None
    assert joined_mp3_note(path, 1.0) == ""


def test_joined_constant_rate_takes_decode_whole(tmp_path: Path) -> None:
    parts = [_mp3(2, 7, bitrate_mode="CONSTANT", compression_level=0.5),
             _mp3(3, 8, bitrate_mode="CONSTANT", compression_level=0.5)]
    joined = tmp_path / "mic.mp3"
    joined.write_bytes(b"".join(parts))
    audio = load_audio(joined)
    assert audio.duration_s == pytest.approx(5.0)
    np.testing.assert_allclose(audio.samples,
                               np.concatenate([_decoded(p) for p in parts]), atol=1e-6)
