"""An audio topic's samples kept as a sound file beside its session: the review shows,
plays and searches it, and relocation and export guard it, as they do a microphone's file."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import soundfile as sf

from speechcal_core.audio.bag_audio import BagAudio
from speechcal_core.audio.errors import AudioError
from speechcal_core.fsutil import written_atomically

#: key of ``Session.extra`` (top-level in the file): the audio topic of the recording the
#: session's audio file was written from
TOPIC_KEY = "audio_topic"
#: raw sample formats a FLAC file holds exactly, and the subtype that holds each
FLAC_SUBTYPES = {"S8": "PCM_S8", "U8": "PCM_S8", "S16LE": "PCM_16", "S16BE": "PCM_16",
                 "S24LE": "PCM_24"}
#: the integers written for a subtype, and the full scale the float samples are read at
_INTEGERS = {"PCM_S8": (np.int16, 2.0 ** 15), "PCM_16": (np.int16, 2.0 ** 15),
             "PCM_24": (np.int32, 2.0 ** 31)}
#: frames written or compared at a time
BLOCK = 1 << 16


def is_audio_topic(audio: str | Path) -> bool:
    """Whether an ``--audio`` value names an audio topic of the recording
    (``/audio/audio``) rather than a file: an absolute name without a suffix that is
    no file."""
    text = str(audio)
    path = Path(text)
    return text.startswith("/") and not path.suffix and not path.exists()


def topic_description(topic: str, recording: Sequence[str | Path]) -> str:
    """``topic /audio/audio of recording.bag``, as notes and the window say it."""
    names = ", ".join(Path(p).name for p in recording)
    return f"topic {topic} of {names}"


def keep_topic_audio(bag: BagAudio, session_path: str | Path) -> tuple[Path, bool]:
    """Write ``bag``'s samples (every channel, as the topic holds them) beside the session
    file ``session_path`` as ``<session stem>.audio.flac`` (``.audio.wav`` of float or
    coded samples, which FLAC cannot hold exactly), atomically. A file of that name
    holding the same audio is kept as it is, and one holding other audio is never
    replaced: the next free name is taken (``.audio.1.flac``, ...). Returns the file and
    whether it was written now (False: an equal one was there)."""
    if bag.frames is None:
        raise ValueError("load the topic with all_channels=True to keep its audio")
    session_path = Path(session_path)
    subtype = FLAC_SUBTYPES.get(bag.sample_format)
    suffix = ".flac" if subtype else ".wav"
    stem = session_path.parent / f"{session_path.stem}.audio"
    for n in range(10_000):
        path = Path(f"{stem}{'' if n == 0 else f'.{n}'}{suffix}")
        if not path.exists() and not path.is_symlink():
            _write(bag, path, subtype)
            return path, True
        if _holds(path, bag.frames, bag.audio.rate):
            return path, False
    raise AudioError(f"{stem}{suffix}: ten thousand files of that name already hold other "
                     "audio; give the session file (-o) another name")


def _holds(path: Path, frames: np.ndarray, rate: int) -> bool:
    """Whether the sound file ``path`` holds exactly ``frames`` at ``rate``."""
    try:
        with sf.SoundFile(str(path)) as f:
            if (f.samplerate, f.channels, f.frames) != (rate, frames.shape[1],
                                                        frames.shape[0]):
                return False
            for start in range(0, frames.shape[0], BLOCK):
                block = f.read(BLOCK, dtype="float32", always_2d=True)
                if not np.array_equal(block, frames[start:start + BLOCK]):
                    return False
    except (OSError, RuntimeError, TypeError, ValueError, sf.LibsndfileError):
        return False
    return True


def _write(bag: BagAudio, path: Path, subtype: str | None) -> None:
    """Write the samples to ``path`` through a temp file beside it (fsync, rename): a
    write failing midway leaves no file there."""
    assert bag.frames is not None
    frames = bag.frames
    if subtype:
        fmt = "FLAC"
    else:
        subtype = "FLOAT"
        fmt = "WAV" if frames.nbytes < 2 ** 32 - 2 ** 20 else "RF64"  # a WAV's size limit
    try:
        with written_atomically(path) as tmp, sf.SoundFile(
                str(tmp), "w", samplerate=bag.audio.rate, channels=frames.shape[1],
                subtype=subtype, format=fmt) as f:
            for start in range(0, frames.shape[0], BLOCK):
                f.write(_stored(frames[start:start + BLOCK], subtype))
            f.close()
            if path.exists():  # made meanwhile by someone else: theirs stays
                raise FileExistsError(f"{path} appeared while it was written")
    except (OSError, RuntimeError, sf.LibsndfileError) as exc:
        raise AudioError(f"{path}: cannot write the audio topic {bag.topic}'s samples "
                         f"there ({exc}); give a session file (-o, --session) in a "
                         "folder with room that can be written") from exc


def _stored(block: np.ndarray, subtype: str) -> np.ndarray:
    """``block`` as written: the integers the topic held for an integer ``subtype`` (the
    float samples are those integers over a power of two, so this is exact), else as
    it is."""
    if subtype not in _INTEGERS:
        return np.ascontiguousarray(block, dtype=np.float32)
    dtype, scale = _INTEGERS[subtype]
    info = np.iinfo(dtype)
    values = np.rint(block.astype(np.float64) * scale)
    return np.clip(values, info.min, info.max).astype(dtype)
