"""Audio recorded inside a ROS1 bag: decoding, and the sync that stamped chunks give."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speechcal_core.audio import AudioError
from speechcal_core.audio.bag_audio import (
    AUDIO_DATA,
    AUDIO_INFO,
    AUDIO_STAMPED,
    audio_types,
    load_bag_audio,
)
from speechcal_core.sync.sources import load_sync_audio
from speechcal_core.sync.stamped import stamped_sync, stamps_problem

RATE = 16000
CHUNK = 1600  # 100 ms
T0_NS = 1_700_000_000_000_000_000


def _write_bag(path: Path, samples: np.ndarray, *, stamped: bool, drift: float = 0.0,
               sample_format: str = "S16LE", unset_stamps: bool = False) -> None:
    from rosbags.rosbag1 import Writer

    store = audio_types()
    types = store.types
    header_t, time_t = types["std_msgs/msg/Header"], types["builtin_interfaces/msg/Time"]
    if sample_format == "F32LE":  # float samples as they are, NaN and inf too
        pcm = samples.astype("<f4")
    else:
        pcm = (np.clip(samples, -1, 1) * 32767).astype("<i2")
    with Writer(path) as w:
        info_c = w.add_connection("/audio/audio_info", AUDIO_INFO, typestore=store)
        kind = AUDIO_STAMPED if stamped else AUDIO_DATA
        data_c = w.add_connection("/audio/audio", kind, typestore=store)
        info = types[AUDIO_INFO](channels=1, sample_rate=RATE, sample_format=sample_format,
                                 bitrate=0, coding_format="wave")
        w.write(info_c, T0_NS, store.serialize_ros1(info, AUDIO_INFO))
        for k, i in enumerate(range(0, pcm.size, CHUNK)):
            chunk = np.frombuffer(pcm[i:i + CHUNK].tobytes(), np.uint8).copy()
            end_s = (i + chunk.size // pcm.itemsize) / RATE  # stamped when the buffer is full
            stamp = T0_NS + round(end_s * (1 + drift) * 1e9) + 300_000 * (k % 3)  # latency
            data = types[AUDIO_DATA](data=chunk)
            if stamped:
                sec, nanosec = (0, 0) if unset_stamps else divmod(stamp, 10**9)
                hdr = header_t(seq=k, stamp=time_t(sec=sec, nanosec=nanosec), frame_id="mic")
                msg = types[AUDIO_STAMPED](header=hdr, audio=data)
            else:
                msg = data
            w.write(data_c, stamp, store.serialize_ros1(msg, kind))


def _tone(seconds: float) -> np.ndarray:
    t = np.arange(int(RATE * seconds)) / RATE
    return (0.3 * np.sin(2 * np.pi * 440 * t)).astype(np.float32)


def test_stamped_audio_decodes_and_gives_offset_and_drift(tmp_path: Path) -> None:
    x = _tone(20.0)
    bag = tmp_path / "a.bag"
    _write_bag(bag, x, stamped=True, drift=30e-6)
    ba = load_bag_audio([bag])
    assert ba.topic == "/audio/audio" and ba.audio.rate == RATE
    assert np.allclose(ba.audio.samples, x, atol=1e-4)
    result = stamped_sync(ba)
    assert result is not None and result.model.source == "stamped"
    assert abs(result.model.offset_ns - T0_NS) < 300_000
    assert result.model.drift == pytest.approx(30e-6, abs=3e-6)
    audio, sync = load_sync_audio("/audio/audio", [bag])
    assert sync is not None and audio.samples.size == x.size


def test_unstamped_audio_has_no_sync_and_missing_topic_is_named(tmp_path: Path) -> None:
    bag = tmp_path / "b.bag"
    _write_bag(bag, _tone(2.0), stamped=False)
    ba = load_bag_audio([bag])
    assert stamped_sync(ba) is None and ba.audio.duration_s == pytest.approx(2.0)
    with pytest.raises(AudioError, match="/nope"):
        load_sync_audio("/nope", [bag])


def test_bag_audio_mostly_not_numbers_is_refused_as_damaged(tmp_path: Path) -> None:
    x = _tone(2.0)
    x[: int(0.6 * x.size)] = np.nan
    x[-10:] = np.inf
    bag = tmp_path / "nan.bag"
    _write_bag(bag, x, stamped=True, sample_format="F32LE")
    with pytest.raises(AudioError, match=r"nan\.bag: audio topic /audio/audio: the audio is "
                                         r"damaged: 60% of its samples are not numbers"):
        load_bag_audio([bag])


def test_bag_audio_scattered_not_numbers_read_as_silence(tmp_path: Path) -> None:
    x = _tone(2.0)
    bad = np.arange(5, x.size, 997)
    x[bad] = np.nan
    x[7] = np.inf
    bag = tmp_path / "glitch.bag"
    _write_bag(bag, x, stamped=False, sample_format="F32LE")
    samples = load_bag_audio([bag]).audio.samples
    assert np.isfinite(samples).all()
    assert (samples[bad] == 0).all() and samples[7] == 1.0
    keep = np.ones(x.size, bool)
    keep[bad] = keep[7] = False
    assert np.allclose(samples[keep], x[keep])


def test_audio_topic_of_a_bag_cut_short_says_to_reindex(tmp_path: Path) -> None:
    """The images of a bag cut short are read (``index --scan``), its audio topic only by
    rosbags, from a whole bag: the topic was said not to be in the recording."""
    whole = tmp_path / "whole.bag"
    _write_bag(whole, _tone(5.0), stamped=True)
    cut = tmp_path / "cut.bag"
    data = whole.read_bytes()
    cut.write_bytes(data[:int(0.6 * len(data))])
    with pytest.raises(AudioError) as exc:
        load_sync_audio("/audio/audio", [cut])
    message = str(exc.value)
    assert message.startswith("/audio/audio: audio file not found, and the recording's "
                              "audio topics cannot be read (cut.bag: ")
    assert "`rosbag reindex` a ROS1 bag cut short" in message and "\n" not in message


@pytest.mark.parametrize(("unset", "drift", "says"), [
    (True, 0.0, "its chunks' header stamps are unset (0), so they cannot time the audio; "
                "the clap does"),
    (False, -0.5, "its chunks' header stamps advance 0.5 s per second of audio, so they "
                  "cannot time it; the clap does"),
])
def test_stamps_that_cannot_time_the_audio_leave_it_to_the_clap(tmp_path: Path, unset: bool,
                                                                drift: float, says: str
                                                                ) -> None:
    """A driver that leaves the header unset: taken as they were, its stamps gave an offset
    of 0 and a drift of -1000000 ppm, and every word fell outside the recording."""
    bag = tmp_path / "unset.bag"
    _write_bag(bag, _tone(12.0), stamped=True, drift=drift, unset_stamps=unset)
    ba = load_bag_audio([bag])
    assert ba.chunk_stamps_ns is not None and stamped_sync(ba) is None
    assert stamps_problem(ba) == f"/audio/audio: {says}"
    notes: list[str] = []
    audio, sync = load_sync_audio("/audio/audio", [bag], notes=notes)
    assert sync is None and notes == [f"/audio/audio: {says}"]
    assert audio.duration_s == pytest.approx(12.0)


def test_stamps_with_latency_and_drift_time_the_audio(tmp_path: Path) -> None:
    bag = tmp_path / "good.bag"
    _write_bag(bag, _tone(3.0), stamped=True, drift=100e-6)
    assert stamps_problem(load_bag_audio([bag])) is None


def test_float_topic_audio_is_kept_as_a_float_wav_and_reused_when_the_same(
        tmp_path: Path) -> None:
    """FLAC holds integers only: float samples are kept exactly in a float WAV file (a
    glitch's non-numbers as the processing read them, silence), written once."""
    import soundfile as sf

    from speechcal_core.audio.topic_file import keep_topic_audio

    x = _tone(1.0)
    x[100] = np.nan
    bag = tmp_path / "float.bag"
    _write_bag(bag, x, stamped=True, sample_format="F32LE")
    topic = load_bag_audio([bag], all_channels=True)
    path, written = keep_topic_audio(topic, tmp_path / "s.json")
    assert (path.name, written) == ("s.audio.wav", True)
    assert sf.info(str(path)).subtype == "FLOAT"
    kept, rate = sf.read(str(path), dtype="float32")
    assert rate == RATE and np.array_equal(kept, topic.audio.samples) and kept[100] == 0
    assert keep_topic_audio(topic, tmp_path / "s.json") == (path, False)
    assert [p.name for p in tmp_path.iterdir() if p.suffix != ".bag"] == ["s.audio.wav"]
