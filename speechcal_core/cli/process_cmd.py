"""``speechcal process``: sync, detect, frame sets and quality into a session file."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.cli._inputs import add_stream_options, recording_and_audio, stream_choice
from speechcal_core.cli._output import StageProgress, emit_json, progress
from speechcal_core.cli._paths import AUDIO, RECORDING, SESSION, TARGET, TRANSCRIPT
from speechcal_core.cli._speech_options import (
    add_channel_option,
    add_trigger_options,
    pronunciations,
    sensitivity,
)
from speechcal_core.errors import UsageError
from speechcal_core.fsutil import OutputExistsError, overlap
from speechcal_core.session.backups import free_name, review_work_in
from speechcal_core.session.model import STREAMS_KEY

if TYPE_CHECKING:
    from speechcal_core.session.model import Session


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("process", help="build a session file from recording and audio")
    p.add_argument("recording", metavar="RECORDING", nargs="+", type=RECORDING,
                   help="ROS1/ROS2 bags, MCAP files, a video or an image folder (a split "
                        "bag: all its parts); the audio file may be given among them")
    p.add_argument("--audio", metavar="AUDIO", type=AUDIO,
                   help="the microphone's audio file (wav, flac, ogg...), or an audio topic "
                        "inside the recording (its audio is kept beside the session file, "
                        "as SESSION.audio.flac)")
    add_channel_option(p)
    add_stream_options(p)
    p.add_argument("--target", metavar="TARGET.yaml", type=TARGET, help="Kalibr target yaml")
    add_trigger_options(p)
    p.add_argument("--transcript", metavar="F", type=TRANSCRIPT,
                   help="take the words from a transcript (WhisperX JSON, Audacity labels, "
                        "whisper TSV, CSV word,start,end) instead of detecting them")
    p.add_argument("--offset-ns", type=int, metavar="N",
                   help="the audio's start in the cameras' clock, instead of finding the clap")
    p.add_argument("-o", "--output", required=True, metavar="SESSION.json", type=SESSION,
                   help="the session file to write")
    p.add_argument("--force", action="store_true",
                   help="replace an existing session file, and no other file (its review "
                        "decisions are lost; the old file is kept as SESSION.json.bak, "
                        "unless that .bak holds review work and the old file none; an "
                        "older .bak holding review work too moves to SESSION.json.bak.1)")
    p.add_argument("--json", action="store_true",
                   help="print what was written as JSON on stdout (session, sets, sync, notes, "
                        "streams: the streams chosen, null for all)")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand: progress lines on stderr, the session file written atomically."""
    from speechcal_core.audio.topic_file import TOPIC_KEY, topic_description
    from speechcal_core.pipeline import process_recording
    from speechcal_core.session.store import check_session_target, save_session, session_file
    from speechcal_core.target import TargetSpec

    args.recording, args.audio = recording_and_audio(args.recording, args.audio, "process")
    # -o through a link writes its target (the link stays), and is checked as that file
    args.output = str(session_file(args.output))
    if args.audio is None:
        raise UsageError("a recording needs its audio: add --audio AUDIO")
    _refuse_to_write_over_inputs(args)
    if Path(args.output).exists() and not args.force:
        raise OutputExistsError(
            f"{args.output} already exists and may hold review decisions; "
            "choose another -o or pass --force"
        )
    if Path(args.output).exists():
        _refuse_to_replace_other_files(Path(args.output))
    check_session_target(args.output)  # a bad -o fails now, not after all the work
    words, level = pronunciations(args), sensitivity(args)
    target = TargetSpec.from_kalibr_yaml(args.target) if args.target else None
    report = StageProgress()
    session = process_recording(
        args.recording,
        args.audio,
        trigger_words=tuple(args.trigger or ("capture",)),
        transcript=args.transcript,
        pronunciations=words,
        sensitivity=level,
        offset_ns=args.offset_ns,
        channel=args.channel,
        target=target,
        streams=stream_choice(args),
        progress=report,
        session_path=args.output,
    )
    out = Path(args.output)
    replaced = out.exists()
    bak = out.with_name(out.name + ".bak")
    # a .bak holding review work is not given up for a file that holds none (a second
    # --force would otherwise lose the decisions the first one kept)
    bak_work = review_work_in(bak) if replaced and bak.exists() else ""
    kept = bak_work if bak_work and not review_work_in(out) else ""
    # both hold review work: the older .bak moves aside rather than being replaced
    older_work = bak_work if not kept else ""
    older = free_name(bak) if older_work else None
    if older is not None:
        os.replace(bak, older)
    save_session(session, out, backup=not kept)
    if kept:
        progress(f"{bak} is left as it was: it holds review work ({kept}) and the file "
                 "replaced held none")
    elif replaced:
        progress(f"the file it replaced is kept as {bak}")
    if older is not None:
        progress(f"the earlier {bak}, which holds review work too ({older_work}), is kept "
                 f"as {older}")
    notes = [*session.sync_evidence.get("warnings", []),
             *session.extra.get("detection_notes", [])]
    topic = session.extra.get(TOPIC_KEY)
    if topic:
        progress(f"the audio of {topic_description(topic, args.recording)} is kept as "
                 f"{session.audio}")
    for note in notes:
        progress(f"note: {note}")
    progress(f"{_summary(session)}; wrote {args.output}")
    if args.json:
        emit_json({"session": str(Path(args.output).absolute()), "sets": len(session.sets),
                   "sync": session.sync.to_dict(), "notes": notes, "replaced": replaced,
                   "streams": session.extra.get(STREAMS_KEY), "audio": session.audio,
                   "audio_topic": topic})
    return 0


def _refuse_to_write_over_inputs(args: argparse.Namespace) -> None:
    """-o must name a session file, never a folder or a file ``process`` reads (the
    recording, audio, transcript or target), --force or not: those are the operator's data."""
    from speechcal_core.audio.topic_file import is_audio_topic

    out = Path(args.output)
    if out.is_dir():
        raise OutputExistsError(f"{out} is a folder; give the session file's name, such as "
                                f"-o {out / 'session.json'}")
    inputs = {"recording": args.recording,
              "audio": [] if is_audio_topic(args.audio) else [args.audio],
              "transcript": [args.transcript] if args.transcript else [],
              "target": [args.target] if args.target else []}
    touched = overlap(out, {what: [Path(p) for p in paths] for what, paths in inputs.items()})
    if touched is not None:
        relation, what, p = touched
        where = f"is the {what} this reads" if relation == "is" else \
            f"lies inside the {what} {p} this reads"
        raise OutputExistsError(f"{out} {where}; write the session file elsewhere, such as "
                                "session.json beside it")


def _refuse_to_replace_other_files(out: Path) -> None:
    """--force replaces a session file, nothing else: a file that does not read as one
    (notes, another tool's JSON, a damaged session) is the operator's to move away."""
    from speechcal_core.session.store import SessionFileError, load_session

    try:
        load_session(out)
    except SessionFileError as exc:
        reason = str(exc).removeprefix(f"{out}: ").split(";")[0]  # not how to open it
        raise OutputExistsError(f"{out} exists and --force replaces only a session file, "
                                f"which this is not ({reason}); choose another -o, or move "
                                "it away first") from None


def _summary(session: Session) -> str:
    """Frame sets found and flagged, and the calibration check in the window's words."""
    from speechcal_core.review.checks import check_summary

    n = len(session.sets)
    flagged = sum(1 for s in session.sets if any(f.flags for f in s.frames))
    text = f"{n} frame set{'' if n == 1 else 's'} ({flagged} flagged)"
    frameless = sum(1 for s in session.sets if not s.has_frames)
    if frameless:
        text += (f"; {frameless} {'has' if frameless == 1 else 'have'} no frame in any camera "
                 "at the trigger time: check the offset (the clap, or --offset-ns)")
    from speechcal_core.sources.base import stream_order

    streams = sorted({f.stream for s in session.sets for f in s.frames}, key=stream_order)
    check = check_summary(session, streams) if streams else None
    return f"{text}; {check.line}" if check else text
