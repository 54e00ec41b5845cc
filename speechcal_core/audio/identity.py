"""What tells one audio file from another of the same name (every take's audio may be
``mic.wav``): its length, sample rate and channels as its header gives them."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import soundfile as sf

from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.loader import header_frames, sound_file

#: where a session keeps its audio file's identity (``Session.extra``)
AUDIO_FILE_KEY = "audio_file"
#: lengths closer than this are the same file's (a header's frame count is exact)
SAME_LENGTH_S = 0.01


def audio_identity(path: str | Path) -> dict | None:
    """``{"seconds", "rate", "channels"}`` of the audio file ``path`` from its header, or
    None when it is no sound file soundfile reads (a bag's audio topic, a missing file)
    or its header does not know its length."""
    try:
        with sound_file(path) as f:
            frames, rate, channels = header_frames(f), int(f.samplerate), int(f.channels)
    except (OSError, RuntimeError, TypeError, ValueError, sf.LibsndfileError, AudioError):
        return None
    if rate <= 0 or frames is None:
        return None  # no rate, or a length the header does not know
    return {"seconds": round(frames / rate, 6), "rate": rate, "channels": channels}


def identity_difference(stored: object, found: dict | None) -> str:
    """How the file ``found`` describes differs from the one a session ``stored``, in
    words ("it lasts 61.20 s at 48000 Hz, the session's audio 59.00 s at 44100 Hz"); ""
    when they agree or either is unknown."""
    if not isinstance(stored, dict) or found is None:
        return ""
    try:
        seconds, rate = float(stored["seconds"]), int(stored["rate"])
        channels = int(stored["channels"])
    except (KeyError, TypeError, ValueError):
        return ""
    if (abs(seconds - found["seconds"]) < SAME_LENGTH_S and rate == found["rate"]
            and channels == found["channels"]):
        return ""
    return (f"it lasts {_described(found['seconds'], found['rate'], found['channels'])}, "
            f"the session's audio {_described(seconds, rate, channels)}")


def words_beyond(ends_s: Iterable[float], seconds: float) -> str:
    """Why an audio of ``seconds`` cannot hold words ending at ``ends_s`` (audio seconds)
    in words, "" when it can: for sessions that keep no :func:`audio_identity`."""
    last = max(ends_s, default=0.0)
    if last <= seconds + SAME_LENGTH_S:
        return ""
    return f"it lasts {seconds:.2f} s, but the session's words run to {last:.2f} s"


def _described(seconds: float, rate: int, channels: int) -> str:
    return f"{seconds:.2f} s at {rate} Hz, {channels} channel{'' if channels == 1 else 's'}"
