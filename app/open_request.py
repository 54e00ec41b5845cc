"""What the review window is asked to open: :meth:`ReviewWindow.open`'s arguments, and
those for files dropped on it."""

from __future__ import annotations

from typing import TYPE_CHECKING, TypedDict

from speechcal_core.audio import AUDIO_SUFFIXES
from speechcal_core.session.backups import named_as_session
from speechcal_core.session.store import SessionFileError, load_session

if TYPE_CHECKING:
    from speechcal_core.sources.selection import StreamChoice
    from speechcal_core.speech.matching import TriggerSpec
    from speechcal_core.target import TargetSpec


class OpenRequest(TypedDict, total=False):
    """:meth:`ReviewWindow.open` arguments, as ``load_for_review`` takes them."""

    session_path: str | None
    recording: list[str] | None
    audio: str | None
    new_session_path: str | None
    triggers: TriggerSpec | None
    channel: int | None
    target: TargetSpec | None
    streams: StreamChoice | None


def drop_request(paths: list[str]) -> OpenRequest | None:
    """What to open for dropped files, as :meth:`ReviewWindow.open` arguments; None if
    nothing fits.

    A dropped session file is opened (it names its recording and audio). A recording
    dropped with its audio is opened (the loader picks up a session file beside it)
    whatever other JSON comes with them (``speechcal synth`` writes a truth.json beside
    the two); a JSON that is no session is opened, to say why, only when there is no pair.
    """
    jsons = [p for p in paths if named_as_session(p)]
    audio = [p for p in paths if p.lower().endswith(AUDIO_SUFFIXES)]
    recording = [p for p in paths if p not in jsons and p not in audio]
    sessions = [p for p in jsons if is_session_file(p)]
    if sessions:
        return {"session_path": sessions[0]}
    if recording and audio:
        return {"recording": recording, "audio": audio[0]}
    if jsons:
        return {"session_path": jsons[0]}
    return None


def is_session_file(path: str) -> bool:
    """Whether ``path`` reads as a SpeechCal session file."""
    try:
        load_session(path)
    except SessionFileError:
        return False
    return True
