"""Audio recorded inside a bag (audio_common_msgs AudioData / AudioDataStamped + AudioInfo)."""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import soundfile as sf

from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.loader import Audio, NumberCheck

if TYPE_CHECKING:
    from rosbags.typesys.store import Typestore

AUDIO_DATA = "audio_common_msgs/msg/AudioData"
AUDIO_STAMPED = "audio_common_msgs/msg/AudioDataStamped"
AUDIO_INFO = "audio_common_msgs/msg/AudioInfo"
MSG_DEFS = {
    AUDIO_DATA: "uint8[] data\n",
    AUDIO_STAMPED: "std_msgs/Header header\naudio_common_msgs/AudioData audio\n",
    AUDIO_INFO: ("uint8 channels\nuint32 sample_rate\nstring sample_format\n"
                 "uint32 bitrate\nstring coding_format\n"),
}
PCM_FORMATS = {"S8": "i1", "U8": "u1", "S16LE": "<i2", "S16BE": ">i2", "S24LE": "S24",
               "S32LE": "<i4", "S32BE": ">i4", "F32LE": "<f4", "F32BE": ">f4", "F64LE": "<f8"}


@dataclass(frozen=True, eq=False)
class BagAudio:
    """Audio from a bag topic; for stamped audio the stamp of each chunk and its first sample."""

    audio: Audio
    topic: str
    chunk_stamps_ns: np.ndarray | None  # header stamp per chunk (stamped topics only)
    chunk_starts: np.ndarray | None  # first sample index of each chunk
    #: every channel as the topic holds them (frames x channels, float32, non-numbers
    #: replaced as in ``audio``), read only when asked (``load_bag_audio(all_channels=)``)
    frames: np.ndarray | None = None
    #: the raw samples' format as AudioInfo names it (``"S16LE"``), "" for coded audio
    sample_format: str = ""


def audio_types() -> Typestore:
    """A typestore that knows the audio_common_msgs types (registered from their .msg text)."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = {}
    for name, text in MSG_DEFS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    return store


def audio_topics(paths: Sequence[str | Path]) -> dict[str, str]:
    """Audio topics in the bag(s): topic -> message type."""
    from rosbags.highlevel import AnyReader

    try:
        with AnyReader([Path(p) for p in paths], default_typestore=audio_types()) as reader:
            return {c.topic: c.msgtype for c in reader.connections
                    if c.msgtype in (AUDIO_DATA, AUDIO_STAMPED)}
    except Exception as exc:  # rosbags raises several unrelated types for unreadable bags
        raise AudioError(f"{Path(paths[0]).name}: cannot read audio from the bag ({exc})") from exc


def load_bag_audio(paths: Sequence[str | Path], topic: str | None = None, *,
                   channel: int | None = None, all_channels: bool = False) -> BagAudio:
    """Decode the audio topic (the only one, when ``topic`` is None) of a bag; samples
    that are not numbers are taken as in an audio file (:class:`NumberCheck`). With
    ``all_channels`` the result keeps every channel too (``BagAudio.frames``), to be
    written to a file."""
    from rosbags.highlevel import AnyReader

    bag = Path(paths[0]).name
    with AnyReader([Path(p) for p in paths], default_typestore=audio_types()) as reader:
        conns = [c for c in reader.connections if c.msgtype in (AUDIO_DATA, AUDIO_STAMPED)]
        if topic is not None:
            conns = [c for c in conns if c.topic == topic]
        names = sorted({c.topic for c in conns})
        if not names:
            what = f"audio topic {topic}" if topic else "audio topic"
            raise AudioError(f"{bag}: no {what} (audio_common_msgs AudioData or "
                             "AudioDataStamped); give the microphone file with --audio")
        if len(names) > 1:
            raise AudioError(f"{bag}: several audio topics ({', '.join(names)}); "
                             "name one with --audio TOPIC")
        info = _info(reader, names[0])
        chunks: list[bytes] = []
        stamps: list[int] = []
        for conn, _t, raw in reader.messages(connections=conns):
            # rosbags builds the message classes at run time: it can only say ``object``
            msg: Any = reader.deserialize(raw, conn.msgtype)
            if conn.msgtype == AUDIO_STAMPED:
                stamps.append(int(msg.header.stamp.sec) * 1_000_000_000
                              + int(msg.header.stamp.nanosec))
                data = msg.audio.data
            else:
                data = msg.data
            chunks.append(bytes(np.asarray(data, dtype=np.uint8)))
    if not chunks or not any(chunks):
        raise AudioError(f"{bag}: audio topic {names[0]} holds no samples")
    frames, rate, starts, fmt = _decode(chunks, info, bag)
    channels = int(frames.shape[1])
    samples = _mono(frames, channel, bag)
    numbers = NumberCheck(f"{bag}: audio topic {names[0]}")
    samples = numbers.clean(samples)
    numbers.check()
    kept = np.nan_to_num(frames, nan=0.0, posinf=1.0, neginf=-1.0) if all_channels else None
    del frames
    audio = Audio(samples, rate, Path(paths[0]), channels, rate, channel)
    stamped = np.array(stamps, dtype=np.int64) if stamps else None
    return BagAudio(audio, names[0], stamped, starts, kept, fmt)


def _info(reader, topic: str) -> dict:
    """The AudioInfo published beside ``topic`` (same namespace preferred), or {}."""
    conns = [c for c in reader.connections if c.msgtype == AUDIO_INFO]
    if not conns:
        return {}
    ns = topic.rsplit("/", 1)[0]
    conns.sort(key=lambda c: c.topic.rsplit("/", 1)[0] != ns)
    for conn, _t, raw in reader.messages(connections=conns[:1]):
        m = reader.deserialize(raw, conn.msgtype)
        return {"channels": int(m.channels), "sample_rate": int(m.sample_rate),
                "sample_format": str(m.sample_format), "coding_format": str(m.coding_format)}
    return {}


def _decode(chunks: list[bytes], info: dict, bag: str
            ) -> tuple[np.ndarray, int, np.ndarray | None, str]:
    """Float32 samples (frames x channels), rate, each chunk's first sample and the raw
    samples' format ("" for coded audio)."""
    coding = info.get("coding_format", "").lower()
    blob = b"".join(chunks)
    if coding in ("wave", "wav", "pcm", "raw") or (not coding and info):
        channels = max(1, info.get("channels", 1))
        rate = info.get("sample_rate", 0)
        fmt = info.get("sample_format", "S16LE").upper()
        if rate <= 0 or fmt not in PCM_FORMATS:
            raise AudioError(f"{bag}: AudioInfo says {rate} Hz, format {fmt!r}; "
                             "cannot decode raw audio like that")
        x = _pcm(blob, fmt)
        frame = channels
        x = x[: x.size - x.size % frame].reshape(-1, channels)
        width = len(blob) / max(1, x.size)  # bytes per sample
        lengths = np.array([len(c) for c in chunks])
        starts = (np.concatenate([[0], np.cumsum(lengths)[:-1]]) / (width * channels))
        return x, rate, starts.astype(np.int64), fmt
    # compressed (mp3, or unknown: let libsndfile guess from the bytes)
    try:
        data, rate = sf.read(io.BytesIO(blob), dtype="float32", always_2d=True)
    except (sf.LibsndfileError, RuntimeError, TypeError) as exc:
        raise AudioError(f"{bag}: cannot decode the bag's audio (coding {coding or '?'}); "
                         "export it to a WAV/FLAC file and pass that with --audio") from exc
    return data, int(rate), None, ""


def _pcm(blob: bytes, fmt: str) -> np.ndarray:
    if fmt == "S24LE":
        b = np.frombuffer(blob[: len(blob) - len(blob) % 3], np.uint8).reshape(-1, 3)
        v = (b[:, 0].astype(np.int32) | (b[:, 1].astype(np.int32) << 8)
             | (b[:, 2].astype(np.int32) << 16))
        v = np.where(v >= 1 << 23, v - (1 << 24), v)
        return (v / float(1 << 23)).astype(np.float32)
    dt = np.dtype(PCM_FORMATS[fmt])
    v = np.frombuffer(blob[: len(blob) - len(blob) % dt.itemsize], dt)
    if dt.kind == "f":
        return v.astype(np.float32)
    if dt.kind == "u":
        return ((v.astype(np.float32) - 128.0) / 128.0).astype(np.float32)
    return (v.astype(np.float32) / float(2 ** (8 * dt.itemsize - 1))).astype(np.float32)


def _mono(x: np.ndarray, channel: int | None, bag: str) -> np.ndarray:
    if channel is not None:
        if not 0 <= channel < x.shape[1]:
            raise AudioError(f"{bag}: the bag's audio has {x.shape[1]} channel(s), "
                             f"channel {channel} asked")
        return np.ascontiguousarray(x[:, channel], dtype=np.float32)
    return x.mean(axis=1).astype(np.float32)
