"""A session whose recording moved: which of its files are gone, and the files to open it
with once the operator shows where one of them went (its review work is kept: opening a
recording of the same names with the session points it there, see ``loading``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from speechcal_core.errors import SpeechCalError, UsageError
from speechcal_core.session.store import load_session


@dataclass(frozen=True)
class MovedRecording:
    """The session file at ``session_path``, whose recording files ``missing`` are gone."""

    session_path: Path
    missing: tuple[str, ...]

    @property
    def names(self) -> str:
        """The missing files' names, for a dialog ("recording.bag")."""
        return ", ".join(Path(p).name for p in self.missing)


def moved_recording(session_path: str | Path) -> MovedRecording | None:
    """What of the session's recording is gone (None: all of it is there, or the file is
    no readable session)."""
    try:
        session = load_session(session_path)
    except (SpeechCalError, OSError):
        return None
    missing = tuple(p for p in session.recording if not Path(p).exists())
    return MovedRecording(Path(session_path), missing) if missing else None


def relocated_inputs(session_path: str | Path, chosen: str | Path) -> tuple[list[str],
                                                                            str | None]:
    """The recording and audio to open the session at ``session_path`` with, its recording
    now where ``chosen`` shows: one of its files or folders (a ROS2 bag folder, or a file
    in it such as its ``metadata.yaml``), or the folder holding them. Files of the same
    names there are taken; the audio too where the session's is gone and one of its name
    lies beside them (else the session's own). UsageError naming what is not there."""
    session = load_session(session_path)
    chosen = Path(chosen)
    names = [Path(p).name for p in session.recording]
    if chosen.name in names:
        folder = chosen.parent
    elif chosen.parent.name in names:  # a file inside a ROS2 bag folder (metadata.yaml)
        folder = chosen.parent.parent
    elif chosen.is_dir():
        folder = chosen
    else:
        folder = chosen.parent
    recording = [folder / name for name in names]
    absent = [p.name for p in recording if not p.exists()]
    if absent:
        raise UsageError(f"{folder} holds no {', '.join(absent)}: choose the session's "
                         f"recording ({', '.join(names)}) where it is now")
    audio = session.audio
    if audio and not Path(audio).exists() and (folder / Path(audio).name).exists():
        audio = str(folder / Path(audio).name)
    return [str(p) for p in recording], audio


def relocated_audio(audio: str, chosen: str | Path) -> str:
    """The audio file to open a session with, its audio ``audio`` now at ``chosen`` (the
    same file name: another file would be another recording, to be processed into a
    session of its own). UsageError saying what to choose."""
    name = Path(audio).name
    if Path(chosen).name != name:
        raise UsageError(f"{chosen} is not {name}, the session's audio: choose {name} where "
                         "it is now (another audio file is processed into a new session)")
    return str(chosen)
