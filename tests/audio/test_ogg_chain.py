"""Chained Ogg files (whole streams one after another) read through every link.

libsndfile alone decodes the first link only and takes its length for the file's, so a
trigger said after a recorder resumed was lost without a word.
"""

from __future__ import annotations

import io
import itertools
from pathlib import Path

import numpy as np
import pytest
import soundfile as sf
from audio_files import write_chained_ogg, write_spliced_ogg

from speechcal_core.audio import AudioError, load_audio
from speechcal_core.audio.file_samples import FileSamples
from speechcal_core.audio.identity import audio_identity
from speechcal_core.audio.loader import cut_short_note, load_resampled
from speechcal_core.audio.ogg_chain import ogg_links
from speechcal_core.audio.playback import PlaybackAudio


def _noise(seconds: float, rate: int, seed: int, channels: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (int(seconds * rate), channels) if channels > 1 else (int(seconds * rate),)
    return (0.1 * rng.standard_normal(shape)).astype(np.float32)


def _decoded(data: np.ndarray, rate: int) -> np.ndarray:
    """``data`` as a single Ogg Vorbis file decodes (the codec is lossy)."""
    buf = io.BytesIO()
    sf.write(buf, data, rate, format="OGG", subtype="VORBIS")
    buf.seek(0)
    return sf.read(buf, dtype="float32")[0]


@pytest.fixture(scope="module")
def three_links(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, np.ndarray]:
    """A chained file of 3, 5 and 2 s at 16 kHz, and what its links decode to end to end."""
    parts = [_noise(s, 16000, seed) for seed, s in enumerate((3.0, 5.0, 2.0))]
    path = write_chained_ogg(tmp_path_factory.mktemp("chain") / "mic.ogg",
                             [(x, 16000) for x in parts])
    return path, np.concatenate([_decoded(x, 16000) for x in parts])


def test_the_links_are_found_where_each_stream_begins(three_links) -> None:
    path, _ = three_links
    links = ogg_links(path)
    assert len(links) == 3
    assert links[0][0] == 0 and links[-1][1] == path.stat().st_size
    assert all(a[1] == b[0] for a, b in itertools.pairwise(links))
    assert all(path.read_bytes()[start:start + 4] == b"OggS" for start, _ in links)


def test_every_link_loads_end_to_end(three_links) -> None:
    path, expected = three_links
    assert sf.info(str(path)).duration == pytest.approx(3.0)  # libsndfile alone: the first
    audio = load_audio(path)
    assert audio.samples.size == 10 * 16000
    np.testing.assert_array_equal(audio.samples, expected)
    assert audio_identity(path) == {"seconds": 10.0, "rate": 16000, "channels": 1}


def test_resampled_loading_reads_every_link(three_links) -> None:
    path, _ = three_links
    resampled, size_in = load_resampled(path, 8000)
    assert size_in == 10 * 16000
    np.testing.assert_allclose(resampled.samples, load_audio(path, rate=8000).samples,
                               atol=1e-6)


def test_stretches_across_a_joint_read_back_as_loaded(three_links) -> None:
    """Playback and the waveform read stretches on demand; one across the first joint
    (3 s) and one inside the last link equal the loaded samples."""
    path, expected = three_links
    reader = FileSamples(path, 16000, rate_in=16000, size_in=expected.size)
    for a, b in ((40000, 56000), (8 * 16000 + 5, 10 * 16000)):
        np.testing.assert_array_equal(reader.read(a, b), expected[a:b])
    assert PlaybackAudio(path).duration_s == pytest.approx(10.0)


def test_stereo_links_pick_a_channel(tmp_path: Path) -> None:
    parts = [_noise(1.5, 22050, 4, channels=2), _noise(2.0, 22050, 5, channels=2)]
    path = write_chained_ogg(tmp_path / "stereo.ogg", [(x, 22050) for x in parts])
    right = load_audio(path, channel=1)
    expected = np.concatenate([_decoded(x, 22050)[:, 1] for x in parts])
    np.testing.assert_array_equal(right.samples, expected)


def test_links_of_different_rates_are_refused_naming_them(tmp_path: Path) -> None:
    path = write_chained_ogg(tmp_path / "joined.ogg",
                             [(_noise(1.0, 16000, 1), 16000), (_noise(1.0, 48000, 2), 48000)])
    with pytest.raises(AudioError) as info:
        load_audio(path)
    assert str(info.value).startswith(
        f"{path}: holds 2 Ogg streams one after another in different formats "
        "(16000 Hz with 1 channel(s), 48000 Hz with 1 channel(s)); convert each")
    assert audio_identity(path) is None


def test_a_file_switching_streams_without_a_new_beginning_stays_one_link(
        tmp_path: Path) -> None:
    """Pages of another stream part way, with no beginning of its own (two programs wrote
    the file at once), are no chain: read as libsndfile reads them."""
    path = write_spliced_ogg(tmp_path / "spliced.ogg", 16000, 40.0, seed=3)
    assert ogg_links(path) == ((0, path.stat().st_size),)


@pytest.mark.parametrize("content", [b"RIFF" + bytes(40), b"OggS" + bytes(10)])
def test_other_and_cut_files_are_one_range(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "x.ogg"
    path.write_bytes(content)
    assert ogg_links(path) == ((0, len(content)),)



@pytest.mark.parametrize("gap", [False, True])
def test_a_link_damaged_part_way_keeps_the_next_link_in_its_place(
        tmp_path: Path, gap: bool) -> None:
    """libsndfile stops a read at a damaged page and goes on at the next read: the link
    is read to its end before the next link begins, not left part way. Bytes lost from
    it (``gap``: the pages stop making sense there) do not hide the links after it."""
    parts = [_noise(s, 16000, seed) for seed, s in enumerate((3.0, 5.0, 2.0))]
    path = write_chained_ogg(tmp_path / "mic.ogg", [(x, 16000) for x in parts])
    start, end = ogg_links(path)[1]
    data = bytearray(path.read_bytes())
    middle = (start + end) // 2
    if gap:
        del data[middle:middle + 2000]
    else:
        data[middle:middle + 300] = b"\x55" * 300
    path.write_bytes(bytes(data))

    assert len(ogg_links(path)) == 3
    audio = load_audio(path)
    assert audio.samples.size == 10 * 16000
    np.testing.assert_array_equal(audio.samples[-2 * 16000:], _decoded(parts[2], 16000))
    assert cut_short_note(audio) == ""


def test_a_link_cut_short_reads_as_silence_to_the_length_its_pages_give(
        tmp_path: Path) -> None:
    """The last link cut part way (a copy that stopped): what libsndfile does not decode
    of it is silence, as long as its whole pages say, with a note naming the file."""
    parts = [_noise(s, 16000, seed) for seed, s in enumerate((3.0, 5.0))]
    path = write_chained_ogg(tmp_path / "mic.ogg", [(x, 16000) for x in parts])
    start, end = ogg_links(path)[1]
    path.write_bytes(path.read_bytes()[:(start + end) // 2])

    audio = load_audio(path)
    assert 4.5 * 16000 < audio.samples.size < 6.0 * 16000
    np.testing.assert_array_equal(audio.samples[:3 * 16000], _decoded(parts[0], 16000))
    lost = round(audio.silent_s * 16000)
    assert lost > 0.1 * 16000 and not audio.samples[-lost:].any()
    note = cut_short_note(audio)
    assert note.startswith(f"{path}: ") and "do not decode" in note
    reader = FileSamples(path, 16000, rate_in=16000, size_in=audio.samples.size)
    np.testing.assert_array_equal(reader.read(audio.samples.size - lost - 100,
                                              audio.samples.size),
                                  audio.samples[-lost - 100:])
