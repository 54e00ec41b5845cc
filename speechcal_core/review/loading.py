"""Everything the review window needs, loaded (off the UI thread) from a session or recording."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.errors import SpeechCalError, UsageError
from speechcal_core.frames.nearest import stamped_index
from speechcal_core.fsutil import plain_absolute, same_file
from speechcal_core.review.summary import FIND_WORDS, FIND_WORDS_KEY, review_work
from speechcal_core.session.backups import (
    restored_name,
    restored_note,
    restoring_note,
    set_aside_backup_work,
)
from speechcal_core.session.model import SENSITIVITY_KEY, Session
from speechcal_core.session.store import (
    SessionFileError,
    check_recording_present,
    file_stamp,
    load_session,
    save_session,
    session_file,
)
from speechcal_core.speech.matching import TriggerSpec
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from speechcal_core.audio import Audio, EnvelopePyramid
    from speechcal_core.sources.base import FrameSource
    from speechcal_core.sources.selection import StreamChoice

Progress = Callable[[str, float], None]


@dataclass
class ReviewInputs:
    """An opened session: its recording, the audio envelope and where autosave writes."""

    session: Session
    source: FrameSource
    pyramid: EnvelopePyramid | None
    session_path: Path | None
    #: the claps heard in the audio (audio seconds): the first sets the offset, a second
    #: (at the end of the recording) the drift
    claps_audio_s: tuple[float, ...] = ()
    note: str = ""
    #: the session file as it was read or written here (``file_stamp``): a file that
    #: differs at the next save was changed by someone else meanwhile
    session_stamp: tuple[int, int, int] | None = None
    #: why the session's audio could not be read for the waveform ("" when it was)
    audio_problem: str = ""
    #: the kept previous version opened (SESSION.json.bak, .bak.N), which the first save
    #: restores as ``session_path`` (``save_session(..., keep_aside=True)``), else None
    restores: Path | None = None

    @property
    def no_waveform(self) -> str:
        """Why the waveform is empty ("" when it shows): the window says it there."""
        if self.pyramid is not None:
            return ""
        if not self.session.audio:
            return "this session has no audio file"
        return self.audio_problem or f"{self.session.audio} could not be read"

    def close(self) -> None:
        self.source.close()


def default_session_path(recording: Sequence[str]) -> Path:
    """Where a new session for this recording is saved: beside it, ``<name>.speechcal.json``."""
    first = Path(recording[0])
    stem = first.stem if first.suffix else first.name
    return first.absolute().parent / f"{stem}.speechcal.json"


def session_path_for(recording: Sequence[str], given: str | Path | None = None) -> Path:
    """The session file of ``recording``: ``given`` (``--session``), else the default."""
    return Path(given) if given else default_session_path(recording)


def load_for_review(
    *,
    session_path: str | Path | None = None,
    recording: Sequence[str] | None = None,
    audio: str | None = None,
    new_session_path: str | Path | None = None,
    triggers: TriggerSpec | None = None,
    channel: int | None = None,
    target: TargetSpec | None = None,
    progress: Progress | None = None,
    streams: StreamChoice | None = None,
    audio_at_start: bool = False,
) -> ReviewInputs:
    """Open a session file, or process ``recording`` + ``audio`` into a new session.

    A new session is saved at ``new_session_path``, by default beside the recording; an
    existing session there is opened instead of being overwritten. A new session detects
    ``triggers`` (default: "capture" at the default sensitivity) in the audio's
    ``channel`` (0-based; None mixes them), looks for the board ``target`` (default:
    Kalibr's 6x6 AprilGrid) and uses the recording's ``streams`` (default: all).
    ``audio_at_start`` takes no clap: the audio starts with the first frame (a recording
    without a clap heard, to align in the review).
    """
    from speechcal_core.audio.topic_file import TOPIC_KEY, is_audio_topic, topic_description
    from speechcal_core.pipeline import load_process_audio
    from speechcal_core.sources import open_recording
    from speechcal_core.sources.bag_source import twin_notes

    report = progress or (lambda _t, _f: None)
    note = ""
    source = sound = None
    made_new = False  # processed now: its streams are as asked
    restores = None
    if session_path is not None:
        report("reading session", 0.05)
        path = session_file(session_path)  # a link: its target, from now on
        stamp = file_stamp(path)  # before reading: a change while reading shows later
        session = load_session(path)
        restored = restored_name(path)
        if restored is not None:  # a kept previous version: saving restores it (backups)
            restores, path = path, session_file(restored)
            stamp = file_stamp(path)  # the file its first save replaces, as it is now
            note = restoring_note(restores, path)
        note = "; ".join(filter(None, [note, set_aside_backup_work(path, review_work(session))]))
    elif recording:
        path = session_file(session_path_for(recording, new_session_path))
        if path.exists():
            report(f"reading existing session {path.name}", 0.05)
            stamp = file_stamp(path)
            session = load_session(path)
            work = review_work(session)
            note = (f"opened the existing {path.name} ({work} kept)" if work else
                    f"opened the existing {path.name} (nothing decided in it yet)")
            note = "; ".join(filter(None, [note, set_aside_backup_work(path, work)]))
            if audio and is_audio_topic(audio) and session.extra.get(TOPIC_KEY) == audio:
                audio = session.audio  # the file the session kept of that topic
            audio = audio or session.audio  # the session knows its audio
            moved, source = _follow_moved_files(session, recording, audio)
            if moved:
                try:
                    save_session(session, path, expect=stamp)
                except BaseException:
                    if source is not None:
                        source.close()
                    raise
                stamp = file_stamp(path)
                note += f"; {moved}"
            if not any(same_file(r, kept) for r in recording for kept in session.recording):
                note += (f"; it is the session of {', '.join(session.recording)}, not of "
                         f"{', '.join(recording)}: give another session file to process these")
            elif session.audio and not same_file(audio, session.audio):
                given = audio if is_audio_topic(audio) else Path(audio).name
                note += (f"; it uses the audio {session.audio}, not {audio}: to process "
                         f"with {given}, move {path.name} away or give another "
                         f"session file")
            else:
                note += _settings_note(session, path, triggers, channel, target)
        else:
            from speechcal_core.pipeline import process_loaded

            if audio is None:
                raise UsageError("a recording needs its audio file: pass --audio AUDIO")
            _check_new_session_path(path)
            report("indexing the recording", 0.02)
            source = open_recording(list(recording), streams=streams)
            try:
                report("reading the audio", 0.1)
                sound, topic = load_process_audio(audio, list(recording), channel=channel)
                spec = triggers or TriggerSpec()
                offset_ns = None
                if audio_at_start:
                    from speechcal_core.sources.base import header_span_ns

                    span = header_span_ns(source)
                    offset_ns = span[0] if span is not None else 0
                session = process_loaded(source, sound, list(recording), audio,
                                         offset_ns=offset_ns,
                                         trigger_words=spec.words,
                                         sensitivity=spec.sensitivity,
                                         pronunciations=spec.pronunciations,
                                         target=target, streams=streams,
                                         topic=topic, session_path=path,
                                         progress=lambda t, f: report(t, 0.9 * f))
                if audio_at_start:  # no one chose this offset: the line says "assumed"
                    session.sync = session.sync.with_offset(session.sync.offset_ns,
                                                            ASSUMED_SOURCE)
                save_session(session, path)
                stamp = file_stamp(path)
            except BaseException:
                source.close()
                raise
            made_new = True
            note = f"new session saved as {path.name}"
            if topic is not None:  # the window reads stretches of the file kept of it
                note += (f"; audio from {topic_description(topic.topic, recording)}, kept "
                         f"as {Path(session.audio).name}")
                sound = replace(sound, path=Path(session.audio))
            if audio_at_start:
                note += f"; {AUDIO_AT_START_NOTE}"
            if session.sets:  # without sets the list itself says why (no_sets_hint)
                note += "".join(f"; {n}" for n in session.extra.get("detection_notes", []))
    else:
        raise UsageError("nothing to open: give a session file or a recording with --audio")

    if source is None:
        check_recording_present(session, path)
        report("indexing recording", 0.6)
        source = open_recording(session.recording, streams=session.stream_choice())
        # another take put in place of the recording (every take is recording.bag): the
        # window would show its frames under the session's sets, as export refuses to
        problem = frames_missing(session, source)
        if problem:
            source.close()
            raise SessionFileError(
                f"{path}: its recording {', '.join(session.recording)} is not the one this "
                f"session was made from ({problem}); put the session's own recording back "
                "there, or process this one into a new session file (speechcal process "
                "RECORDING --audio AUDIO -o NEW.json)")
    if not made_new:
        try:
            said, source, stamp = _leave_out(session, source, streams, path, stamp, restores)
            restores = None if said else restores  # saved: restored
        except BaseException:
            source.close()
            raise
        note = "; ".join(filter(None, [note, said, *twin_notes(source)]))
    claps = session.claps_audio_s()
    if session.audio and not Path(session.audio).exists():
        note = "; ".join(filter(None, [note, _topic_audio_again(session, path)]))
    if session.audio and sound is None and Path(session.audio).exists():
        changed = audio_differs(session, session.audio)
        if changed:
            note = "; ".join(filter(None, [note, (
                f"{session.audio} is not the audio this session was made from ({changed}): "
                "its words and waveform may not line up with the frames; put the session's "
                "own audio back there")]))
    try:  # a cancel (raised by ``progress``) from here on closes the recording too
        pyramid, problem = _waveform(session, sound, report)
        if problem:
            note = f"{note}; audio not shown: {problem}" if note else \
                f"audio not shown: {problem}"
        report("ready", 1.0)
    except BaseException:
        source.close()
        raise
    return ReviewInputs(session, source, pyramid, path, claps, note, stamp, problem, restores)


#: the sync source of a session opened with ``audio_at_start`` until its offset is edited
ASSUMED_SOURCE = "assumed"
#: what the window says of a session opened with ``audio_at_start``
AUDIO_AT_START_NOTE = (
    "no clap: the audio is taken to start with the first frame; move it with { } (a "
    "frame; held down, it repeats) and [ ] (1 ms), or drag the audio's start on the "
    "waveform, until the words fall where the board "
    "stops (of ten words or more, the line under the waveform warns while too few do)")


def _settings_note(session: Session, path: Path, triggers: TriggerSpec | None,
                   channel: int | None, target: TargetSpec | None = None) -> str:
    """Why an existing session does not follow the trigger words, channel or board asked
    for (its detection and corners are kept with its review work), or ""."""
    words = []
    if triggers is not None and not set(triggers.words) <= set(session.triggers_word):
        words.append(f"trigger word {', '.join(triggers.words)} (it has "
                     f"{', '.join(session.triggers_word)})")
    level = session.extra.get(SENSITIVITY_KEY)
    if triggers is not None and isinstance(level, (int, float)) \
            and abs(triggers.sensitivity - level) > 1e-9:
        words.append(f"sensitivity {triggers.sensitivity:g} (it has {level:g})")
    others = []
    if channel is not None and channel != session.audio_channel:
        had = "all channels mixed" if session.audio_channel is None \
            else f"channel {session.audio_channel}"
        others.append(f"audio channel {channel} (it has {had})")
    kept = TargetSpec.from_stored(session.extra.get("target")) or TargetSpec()
    if target is not None and target != kept:
        others.append(f"the board {target.describe()} (it has {kept.describe()})")
    if words and not others:  # other words can be looked for in the window
        return (f"; not detected again with {' and '.join(words)}: Edit ▸ {FIND_WORDS}… "
                f"({FIND_WORDS_KEY}) adds its sets and keeps the review work")
    if not others:
        return ""
    return (f"; not processed again with {' and '.join(words + others)}: move {path.name} "
            f"away or give another session file to process anew")


def _leave_out(session: Session, source: FrameSource, choice: StreamChoice | None,
               path: Path, stamp: tuple[int, int, int] | None, restores: Path | None = None
               ) -> tuple[str, FrameSource, tuple[int, int, int] | None]:
    """Narrow an existing session to the streams ``choice`` keeps of those it uses,
    keeping its review work and saving it (restoring the kept previous version
    ``restores`` opened, when given): what was said, the source of the streams left and
    the file's new stamp. A stream the session does not use cannot be taken in (that
    needs processing): UsageError."""
    from speechcal_core.session.streams import leave_out_streams
    from speechcal_core.sources.selection import (
        StreamChoice,
        chosen_streams,
        select_streams,
        stream_named,
    )

    if not choice:
        return "", source, stamp
    names = [s.name for s in source.streams]
    recorded = getattr(source, "recorded", names)
    chosen_streams(recorded, choice.only, choice.skip)  # a name not recorded at all: say so
    skip = [n for n in choice.skip if stream_named(names, n) is not None]  # not yet out
    try:
        kept = chosen_streams(names, choice.only, skip)
    except SpeechCalError as exc:
        raise UsageError(
            f"{path.name} uses the streams {', '.join(names)}; it can leave some of them "
            f"out but take in no other ({exc}); to use others, process the recording into "
            "another session file (--session)") from None
    left = [n for n in names if n not in kept]
    if not left:
        return "", source, stamp
    leave_out_streams(session, left, kept)
    aside = save_session(session, path, expect=stamp, keep_aside=restores is not None)
    whose = "its" if len(left) == 1 else "their"
    restored = f"; {restored_note(restores, path, aside)}" if restores is not None else ""
    return (f"left out {', '.join(left)} ({whose} frames, calibration and coverage; the "
            f"review work is kept){restored}",
            select_streams(source, StreamChoice(only=tuple(kept))), file_stamp(path))


def _waveform(session: Session, sound: Audio | None, report: Progress
              ) -> tuple[EnvelopePyramid | None, str]:
    """The session audio's envelope for the waveform (None without audio), and why the
    audio cannot be shown ("" when it can, or when the session has none)."""
    from speechcal_core.audio import EnvelopePyramid
    from speechcal_core.audio.file_samples import FileSamples

    if not session.audio:
        return None, ""
    report("reading audio", 0.92)
    try:
        if sound is None:  # block by block: the samples stay in the file
            return EnvelopePyramid.from_file(session.audio,
                                             channel=session.audio_channel), ""
        # read for processing: the pyramid reads its stretches from the file
        reader = FileSamples(sound.path or session.audio, sound.rate, rate_in=sound.rate,
                             size_in=sound.samples.size, channel=sound.channel)
        return EnvelopePyramid(sound.samples, sound.rate, source=reader), ""
    except SpeechCalError as exc:
        return None, str(exc)


def _follow_moved_files(session: Session, recording: Sequence[str], audio: str | None
                        ) -> tuple[str, FrameSource | None]:
    """Point ``session`` at ``recording`` and ``audio`` where its own files are gone and
    the given ones carry the same names (the folder was moved or copied): says what moved
    ("" when nothing did) and gives the recording opened to check it (None when it was
    not). The review's decisions stay with the session. A recording of the same name
    that does not hold the session's frames (every take is ``recording.bag``) is a
    UsageError: nothing is changed."""
    from speechcal_core.sources import open_recording

    said, source = [], None
    old = session.recording
    if (not all(Path(p).exists() for p in old) and len(recording) == len(old)
            and sorted(Path(p).name for p in old) == sorted(Path(r).name for r in recording)):
        source = open_recording(list(recording), streams=session.stream_choice())
        problem = frames_missing(session, source)
        if problem:
            source.close()
            raise UsageError(
                f"{', '.join(recording)} is not the recording this session was made from, "
                f"though its name is the same ({problem}); give the session's own "
                "recording, or process this one into another session file (--session)")
        session.recording = [str(plain_absolute(r)) for r in recording]
        said.append(f"its recording moved from {Path(old[0]).parent} and is now read from "
                    f"{Path(session.recording[0]).parent}")  # both plain: see load_session
    if (audio and session.audio and not Path(session.audio).exists()
            and Path(session.audio).name == Path(audio).name):
        problem = audio_differs(session, audio)
        if problem:
            if source is not None:
                source.close()
            raise UsageError(
                f"{audio} is not the audio this session was made from, though its name is "
                f"the same ({problem}); give the session's own audio, or process this one "
                "into another session file (--session)")
        session.audio = str(plain_absolute(audio))
        said.append(f"its audio is now read from {session.audio}")
    return "; ".join(said), source


def _topic_audio_again(session: Session, path: Path) -> str:
    """For a session whose audio came from an audio topic of its recording and whose
    file kept of it is gone (the session and the bag copied without it): the file written
    again from the topic beside the session file ``path``, and a note saying so ("" for
    other sessions, or where the topic cannot be read: the waveform says the audio is
    missing, as for any)."""
    from speechcal_core.audio.errors import AudioError
    from speechcal_core.audio.topic_file import TOPIC_KEY, keep_topic_audio, topic_description
    from speechcal_core.sync.sources import load_topic_audio

    topic = session.extra.get(TOPIC_KEY)
    if not isinstance(topic, str) or not all(Path(p).exists() for p in session.recording):
        return ""
    try:
        bag = load_topic_audio(topic, session.recording, all_channels=True)
        kept, written = keep_topic_audio(bag, path)
    except AudioError as exc:
        return f"its audio file was gone, and could not be written again ({exc})"
    if audio_differs(session, kept):  # not the audio it was made from: not taken
        if written:
            kept.unlink()
        return ""
    session.audio = str(kept)
    return (f"its audio file was gone: written again from "
            f"{topic_description(topic, session.recording)} as {kept.name}")


def audio_differs(session: Session, audio: str | Path) -> str:
    """How the audio file ``audio`` differs from the one ``session`` was made from, in
    words ("" when it matches or cannot be told): its length, rate and channels against
    the session's record of them, or, for a session without that record, its length
    against the session's trigger words."""
    from speechcal_core.audio.identity import (
        AUDIO_FILE_KEY,
        audio_identity,
        identity_difference,
        words_beyond,
    )

    found = audio_identity(audio)
    if found is None:
        return ""
    stored = session.extra.get(AUDIO_FILE_KEY)
    if stored is not None:
        return identity_difference(stored, found)
    return words_beyond((s.trigger.end_s for s in session.sets), found["seconds"])


def frames_missing(session: Session, source: FrameSource) -> str:
    """The first of the session's chosen frames ``source`` lacks, in words ("" when it
    has them all): its camera, or a frame of that header stamp."""
    streams = {s.name for s in source.streams}
    for frame_set in session.sets:
        for frame in frame_set.frames:
            if frame.index < 0:
                continue
            if frame.stream not in streams:
                return f"it has no camera {frame.stream}"
            if stamped_index(source.stamps(frame.stream), frame.stamp_ns) is None:
                return (f"{frame.stream} has no frame stamped {frame.stamp_ns}, set "
                        f"{frame_set.id}'s")
    return ""


def _check_new_session_path(path: Path) -> None:
    """Fail before processing if the new session cannot be saved at ``path``."""
    from speechcal_core.session.store import SessionFileError, check_session_target

    try:
        check_session_target(path)
    except SessionFileError as exc:
        raise SessionFileError(f"{exc} (from the command line: speechcal review RECORDING "
                               f"--audio AUDIO --session PATH)") from exc
