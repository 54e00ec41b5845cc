"""The processing facade the CLI and the GUI share: recording + audio -> a session.

Steps: index the recording, load the audio, find the clap (or take a known offset), find
the trigger words, choose every camera's best still frame for each trigger, find the target's
corners, and check a calibration per camera.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.session.model import (
    PRONUNCIATIONS_KEY,
    SENSITIVITY_KEY,
    STREAMS_KEY,
    FrameSet,
    Session,
    Trigger,
)
from speechcal_core.speech.matching import DEFAULT_SENSITIVITY
from speechcal_core.sync.model import SyncModel

if TYPE_CHECKING:
    from speechcal_core.audio import Audio
    from speechcal_core.audio.bag_audio import BagAudio
    from speechcal_core.frames.detect import Target
    from speechcal_core.frames.sets import FrameSetOptions
    from speechcal_core.sources.base import FrameSource
    from speechcal_core.sources.selection import StreamChoice

Progress = Callable[[str, float], None]


def _noop(_text: str, _fraction: float) -> None:
    pass


def detect_trigger_words(audio: Audio, trigger_words: Sequence[str],
                         transcript: str | None = None, *,
                         pronunciations: Mapping[str, str] | None = None,
                         sensitivity: float = DEFAULT_SENSITIVITY,
                         ) -> tuple[list[Trigger], list[str]]:
    """Trigger words in ``audio`` (an :class:`~speechcal_core.audio.Audio`), or in a
    transcript file when one is given; returns the triggers and the detector's notes.
    ``pronunciations`` gives words missing from the dictionary (WORD -> ARPAbet phones);
    a higher ``sensitivity`` (0..1) finds more words and more false alarms."""
    from speechcal_core.speech import detect_triggers

    detection = detect_triggers(audio, tuple(trigger_words), transcript=transcript,
                                pronunciations=pronunciations, sensitivity=sensitivity)
    triggers = [Trigger(w.word, w.start_s, w.end_s, w.score, w.source or detection.backend)
                for w in detection.triggers]
    notes = list(detection.notes)
    duration = getattr(audio, "duration_s", None)
    if transcript is not None and duration is not None:
        late = sum(1 for t in triggers if t.start_s > duration)
        if late:
            words = "trigger word lies" if late == 1 else "trigger words lie"
            notes.append(f"{transcript}: {late} {words} past the audio's end "
                         f"({duration:.1f} s); is it this audio's transcript?")
    return triggers, notes


def process_recording(
    recording: Sequence[str],
    audio: str,
    *,
    trigger_words: Sequence[str] = ("capture",),
    transcript: str | None = None,
    pronunciations: Mapping[str, str] | None = None,
    sensitivity: float = DEFAULT_SENSITIVITY,
    offset_ns: int | None = None,
    target: Target | None = None,
    frame_options: FrameSetOptions | None = None,
    progress: Progress | None = None,
    channel: int | None = None,
    streams: StreamChoice | None = None,
    session_path: str | Path | None = None,
) -> Session:
    """Sync, detect and build frame sets; returns a new, undecided session.

    ``audio`` is the microphone's file, or an audio topic of the recording (e.g.
    ``/audio/audio``, as ``speechcal sync`` takes it): its samples are then kept beside
    the session file ``session_path`` (:func:`~speechcal_core.audio.topic_file.
    keep_topic_audio`), which becomes the session's audio, and its chunks' header stamps
    time it where they can (else the clap does, and a note says why).

    ``target`` defaults to Kalibr's 6x6 AprilGrid (the session's ``"target_assumed"``
    says whether it was); ``frame_options`` sets the search window (or turns the
    best-still-frame search off); ``channel`` the audio file's channel to use (0-based;
    None mixes them), kept in the session for the review's waveform, sound and search;
    ``streams`` the recording's streams to use (kept in the session too).
    """
    from speechcal_core.sources import open_recording

    report = progress or _noop
    report("indexing the recording", 0.02)
    with open_recording(list(recording), streams=streams) as source:
        report("reading the audio", 0.1)
        sound, topic = load_process_audio(audio, recording, channel=channel)
        return process_loaded(
            source, sound, recording, audio, trigger_words=trigger_words,
            transcript=transcript, pronunciations=pronunciations, sensitivity=sensitivity,
            offset_ns=offset_ns, target=target,
            frame_options=frame_options, progress=report, streams=streams,
            topic=topic, session_path=session_path,
        )


def load_process_audio(audio: str, recording: Sequence[str], *, channel: int | None = None
                       ) -> tuple[Audio, BagAudio | None]:
    """The audio to process: of a file, or of an audio topic of ``recording`` (then the
    topic's audio too, every channel of it kept to be written beside the session)."""
    from speechcal_core.audio import load_audio
    from speechcal_core.audio.topic_file import is_audio_topic
    from speechcal_core.sync.sources import load_topic_audio

    if not is_audio_topic(audio):
        return load_audio(audio, channel=channel), None
    topic = load_topic_audio(audio, recording, channel=channel, all_channels=True)
    return topic.audio, topic


def process_loaded(
    source: FrameSource,
    sound: Audio,
    recording: Sequence[str],
    audio: str,
    *,
    trigger_words: Sequence[str] = ("capture",),
    transcript: str | None = None,
    pronunciations: Mapping[str, str] | None = None,
    sensitivity: float = DEFAULT_SENSITIVITY,
    offset_ns: int | None = None,
    target: Target | None = None,
    frame_options: FrameSetOptions | None = None,
    progress: Progress | None = None,
    streams: StreamChoice | None = None,
    topic: BagAudio | None = None,
    session_path: str | Path | None = None,
) -> Session:
    """:func:`process_recording` on a recording and audio the caller already opened
    (the review keeps both for display instead of reading them twice); ``streams`` is
    the choice ``source`` was opened with, kept in the session. ``topic`` is the audio
    topic ``sound`` was read from (``load_process_audio``; ``audio`` names it), whose
    samples are written beside the session file ``session_path`` once the session is
    made."""
    from speechcal_core.frames.analysis import analyse_frames
    from speechcal_core.frames.unseen_cameras import unseen_camera_notes
    from speechcal_core.frames.word_stillness import moving_words_note, word_stillness
    from speechcal_core.session.store import session_file
    from speechcal_core.sync.pipeline import sync_recording
    from speechcal_core.target import TargetSpec

    report = progress or _noop
    _check_encodings(source)
    evidence: dict = {}
    from speechcal_core.sources.base import header_span_ns

    span = header_span_ns(source)
    if offset_ns is not None:
        _check_offset(int(offset_ns), sound.duration_s, span)
        sync = SyncModel(int(offset_ns), 0.0, "manual")
    else:
        from speechcal_core.sync.stamped import stamped_sync, stamps_problem

        stamped = stamped_sync(topic) if topic is not None else None
        if stamped is not None:  # the topic's chunks are stamped in the cameras' clock
            result = stamped
        else:
            report("finding the clap", 0.2)
            result = sync_recording(source, sound,
                                    progress=lambda text: report(f"clap: {text}", 0.3))
        problem = stamps_problem(topic) if topic is not None else None
        if problem:  # said first, as ``speechcal sync`` says it
            result = replace(result, warnings=(problem, *result.warnings))
        sync = result.model
        evidence = {k: v for k, v in result.to_dict().items()
                    if k not in ("offset_ns", "drift", "source")}
    report("finding the trigger words", 0.45)
    triggers, notes = detect_trigger_words(sound, trigger_words, transcript,
                                           pronunciations=pronunciations,
                                           sensitivity=sensitivity)

    def frames_progress(stage: str, fraction: float) -> None:
        start, span = {"windows": (0.6, 0.2), "corners": (0.8, 0.1)}.get(stage, (0.9, 0.1))
        report(f"frames: {stage}", start + span * fraction)

    report("choosing frames", 0.6)
    assumed = target is None
    target = target or TargetSpec()
    analysis = analyse_frames(source, sync, triggers, target,
                              options=frame_options, progress=frames_progress)
    outside = outside_recording_note(analysis.sets, span, sync)
    named = audio  # what the notes call the audio
    if topic is not None:
        from speechcal_core.audio.topic_file import topic_description

        named = f"the audio {topic_description(topic.topic, recording)}"
    short = audio_ends_early_note(named, sound.duration_s, span, sync)
    moving = moving_words_note(
        word_stillness(analysis.sets, analysis.extra.get("frame_details") or {}), named,
        transcript)
    unseen = target_not_found_note(analysis.sets, target, assumed)
    # what is wrong with the recording's files comes first: it may explain the rest
    notes = [*recording_notes(source), *notes,
             *(n for n in (outside, short, moving, unseen) if n),
             *unseen_camera_notes(analysis.sets, target)]
    # what the review's "find trigger words" starts from (a transcript has no settings)
    settings = {} if transcript is not None else {
        SENSITIVITY_KEY: float(sensitivity),
        **({PRONUNCIATIONS_KEY: dict(pronunciations)} if pronunciations else {})}
    audio_file, from_topic = audio, {}
    if topic is not None:  # the window and export read a file: the topic's is kept as one
        from speechcal_core.audio.topic_file import TOPIC_KEY, keep_topic_audio

        if session_path is None:
            raise ValueError("an audio topic's samples are kept beside the session file: "
                             "give session_path")
        report("keeping the topic's audio", 0.98)
        audio_file = str(keep_topic_audio(topic, session_file(session_path))[0])
        from_topic = {TOPIC_KEY: topic.topic}
    session = Session(
        recording=[str(Path(p).absolute()) for p in recording],
        audio=str(Path(audio_file).absolute()),
        audio_channel=sound.channel,
        sync=sync,
        sets=analysis.sets,
        triggers_word=list(trigger_words),
        sync_evidence=evidence,
        calibration=analysis.calibration,
        extra={**analysis.extra, "target": asdict(target),
               "target_assumed": assumed, **settings, **_audio_file(audio_file),
               **from_topic,
               **({STREAMS_KEY: [s.name for s in source.streams]} if streams else {}),
               **({"detection_notes": notes} if notes else {})},
    )
    report("done", 1.0)
    return session


def _audio_file(audio: str) -> dict:
    """The session's record of its audio file (``audio.identity``), to tell a moved copy
    from another take of the same name; nothing for audio soundfile does not read."""
    from speechcal_core.audio.identity import AUDIO_FILE_KEY, audio_identity

    found = audio_identity(audio)
    return {AUDIO_FILE_KEY: found} if found is not None else {}


def recording_notes(source: FrameSource) -> list[str]:
    """What indexing found wrong with each stream's stamps ("... of one file fall among
    another's": two recordings given as one) and with the files (a truncated bag read in
    part, a part of a split bag given alone), as ``speechcal index`` prints it."""
    return [*(f"{s.name}: {s.stamp_problems}" for s in source.streams if s.stamp_problems),
            *getattr(source, "notes", [])]


def _check_encodings(source: FrameSource) -> None:
    """A stream of raw images in an encoding no camera frame is read from (a 32-bit depth
    topic recorded with the cameras) is refused before any work, by reading its first
    frame: the SourceError names the file and says how to leave the stream out."""
    from speechcal_core.sources.decode import is_supported
    from speechcal_core.sources.errors import BadFrameError

    for s in source.streams:
        if s.msgtype.endswith("/Image") and s.count and s.encoding \
                and not is_supported(s.encoding):
            with contextlib.suppress(BadFrameError):  # a damaged frame: read as usual
                source.frame(s.name, 0)


def _check_offset(offset_ns: int, audio_s: float, span: tuple[int, int] | None) -> None:
    """A hand-given offset must put some of the audio inside the recording (a typo gives
    sets without a frame): UsageError naming both ranges otherwise."""
    from speechcal_core.errors import UsageError

    if span is None:
        return
    end_ns = offset_ns + round(audio_s * 1e9)
    if end_ns < span[0] or offset_ns > span[1]:
        raise UsageError(
            f"--offset-ns {offset_ns} puts the audio (0 to {audio_s:.3f} s) at {offset_ns} to "
            f"{end_ns} ns, outside the recording's header stamps ({span[0]} to {span[1]} ns); "
            "it is the header time of the audio's start")


#: a recording running on this long after its audio ends gets a note (a cut-short file)
AUDIO_ENDS_EARLY_S = 5.0


def audio_ends_early_note(audio: str, duration_s: float, span: tuple[int, int] | None,
                          sync: SyncModel) -> str:
    """A note when the recording runs on well past the audio's end ("" otherwise): trigger
    words said then are not found, and a cut-short audio file looks just like that."""
    if span is None:
        return ""
    missing_s = (span[1] - int(sync.to_session(duration_s))) / 1e9
    if missing_s < AUDIO_ENDS_EARLY_S:
        return ""
    return (f"{audio}: the audio ends after {duration_s:.1f} s, {missing_s:.1f} s before the "
            "recording's last frame: trigger words said after that are not found; is the "
            "audio file complete?")


def target_not_found_note(sets: Sequence[FrameSet], target: Target,
                          assumed: bool) -> str:
    """A note when no camera found the target in any frame of any set ("" otherwise):
    the board filmed is most likely another one than the target looked for."""
    frames = [f for s in sets for f in s.frames]
    if not frames or any(f.corners for f in frames):
        return ""
    given = ("no --target was given, so Kalibr's default board was looked for." if assumed
             else "is --target the board filmed?")
    return (f"the {target.describe()} was not found in any frame of any camera "
            f"({len(frames)} frames of {len(sets)} frame sets): {given} Process again with "
            "--target TARGET.yaml (the board's Kalibr target yaml) into a new session file")


def outside_recording_note(sets: Sequence[FrameSet], span: tuple[int, int] | None,
                           sync: SyncModel) -> str:
    """A note on trigger words said before the recording's first frame or after its
    last ("" when none): a recording cut short, or a wrong offset."""
    if span is None:
        return ""
    before = sum(1 for s in sets if not s.has_frames and s.t_ns < span[0])
    after = sum(1 for s in sets if not s.has_frames and s.t_ns > span[1])
    parts = []
    if before:
        parts.append(f"{before} before its first frame ({sync.to_audio(span[0]):.1f} s into "
                     "the audio)")
    if after:
        parts.append(f"{after} after its last frame ({sync.to_audio(span[1]):.1f} s into "
                     "the audio)")
    if not parts:
        return ""
    return (f"trigger words said outside the recording: {' and '.join(parts)}; is the "
            "recording cut short, or the offset wrong (the clap, or --offset-ns)?")
