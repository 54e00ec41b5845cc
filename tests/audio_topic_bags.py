"""Bags with the microphone recorded into them (audio_common_msgs), made from a synthetic
session's recording and audio file: for tests of audio topics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import soundfile as sf

#: the topic the microphone is recorded on
TOPIC = "/audio/audio"
#: seconds of audio a chunk (message) holds
CHUNK_S = 0.1


def with_audio_topic(bag: Path, audio: Path, out: Path, offset_ns: int, *,
                     stamped: bool = True, unset: bool = False,
                     mic_channel: int | None = None) -> np.ndarray:
    """``bag`` with the microphone file ``audio`` recorded into it on TOPIC as S16LE chunks
    (AudioDataStamped stamped when each chunk is full, or AudioData), its AudioInfo beside
    it; with ``mic_channel`` as one channel of two (the other silent). Returns the
    samples as the topic holds them (frames x channels, int16)."""
    from rosbags.rosbag1 import Reader, Writer

    from speechcal_core.audio.bag_audio import (
        AUDIO_DATA,
        AUDIO_INFO,
        AUDIO_STAMPED,
        audio_types,
    )

    samples, rate = sf.read(str(audio), dtype="int16")
    if mic_channel is not None:
        both = np.zeros((samples.size, 2), np.int16)
        both[:, mic_channel] = samples
        samples = both
    frames = samples.reshape(samples.shape[0], -1)
    store = audio_types()
    types = store.types
    header_t, time_t = types["std_msgs/msg/Header"], types["builtin_interfaces/msg/Time"]
    kind = AUDIO_STAMPED if stamped else AUDIO_DATA
    chunk = int(rate * CHUNK_S)
    with Reader(bag) as reader, Writer(out) as writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, typestore=store)
                 for c in reader.connections}
        for conn, t, raw in reader.messages():
            writer.write(conns[conn.id], t, raw)
        info_c = writer.add_connection("/audio/audio_info", AUDIO_INFO, typestore=store)
        data_c = writer.add_connection(TOPIC, kind, typestore=store)
        info = types[AUDIO_INFO](channels=frames.shape[1], sample_rate=rate,
                                 sample_format="S16LE", bitrate=0, coding_format="wave")
        writer.write(info_c, offset_ns, store.serialize_ros1(info, AUDIO_INFO))
        for k, i in enumerate(range(0, frames.shape[0], chunk)):
            block = frames[i:i + chunk]
            stamp = offset_ns + round((i + block.shape[0]) / rate * 1e9)
            data = types[AUDIO_DATA](data=np.frombuffer(block.astype("<i2").tobytes(),
                                                        np.uint8).copy())
            if stamped:
                sec, nanosec = (0, 0) if unset else divmod(stamp, 10**9)
                header = header_t(seq=k, stamp=time_t(sec=sec, nanosec=nanosec),
                                  frame_id="mic")
                msg = types[AUDIO_STAMPED](header=header, audio=data)
            else:
                msg = data
            writer.write(data_c, stamp, store.serialize_ros1(msg, kind))
    return frames


def true_words(truth: dict, path: Path) -> Path:
    """A transcript (CSV word,start,end) of the synthetic session's true trigger words."""
    path.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    return path
