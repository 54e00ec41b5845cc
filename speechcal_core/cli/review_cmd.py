"""``speechcal review``: the review window."""

from __future__ import annotations

import argparse

from speechcal_core.cli._inputs import add_stream_options, recording_and_audio, stream_choice
from speechcal_core.cli._paths import AUDIO, SCREENSHOT, SESSION, TARGET, path_arg
from speechcal_core.cli._speech_options import (
    add_channel_option,
    add_trigger_options,
    detection_options_given,
    pronunciations,
    sensitivity,
)
from speechcal_core.errors import UsageError
from speechcal_core.session.backups import named_as_session
from speechcal_core.speech.matching import DEFAULT_TRIGGERS, TriggerSpec


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("review", help="open the review window")
    p.add_argument("inputs", nargs="*", metavar="SESSION.json | RECORDING",
                   type=path_arg("a session file or a recording"))
    p.add_argument("--audio", metavar="AUDIO", type=AUDIO,
                   help="the microphone recording of a RECORDING not processed yet, or "
                        "an audio topic inside it (kept beside the new session as a file; a "
                        "session file knows its audio)")
    p.add_argument("--session", metavar="SESSION.json", type=SESSION,
                   help="where a recording's session is kept (default: beside the recording, "
                        "RECORDING.speechcal.json); opened if it exists")
    p.add_argument("--screenshot", metavar="PNG", type=SCREENSHOT,
                   help="render the window to PNG and exit")
    p.add_argument("--target", metavar="TARGET.yaml", type=TARGET,
                   help="the board, as a Kalibr target yaml, of a recording processed into "
                        "a new session (default: Kalibr's 6x6 AprilGrid)")
    add_trigger_options(p)  # for a recording processed into a new session
    add_channel_option(p)
    add_stream_options(p)  # a new session's streams; an existing one leaves them out
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    session_path = None
    recording = None
    triggers = None
    if len(args.inputs) == 1 and named_as_session(args.inputs[0]):
        session_path = args.inputs[0]
        if args.audio or args.session:
            raise UsageError("--audio and --session go with a recording, not with a session "
                             "file")
        if detection_options_given(args) or args.target:
            raise UsageError("--trigger, --sensitivity, --pronounce, --channel and --target go "
                             "with a recording the review processes, not with a session "
                             "file: speechcal review RECORDING --audio AUDIO --trigger W")
    elif (args.session or args.target) and not args.inputs:
        raise UsageError(f"{'--session' if args.session else '--target'} goes with a "
                         "recording: RECORDING --audio AUDIO "
                         f"{'--session SESSION.json' if args.session else '--target T.yaml'}")
    elif sessions := [p for p in args.inputs if named_as_session(p)]:
        raise UsageError(f"{sessions[0]} is a session file: open it alone (speechcal review "
                         f"{sessions[0]}), it knows its recording and audio; a recording's "
                         "session file goes with --session")
    elif args.inputs:
        recording, audio = _recording_and_audio(args.inputs, args.audio, args.session)
        args.audio = audio
        if detection_options_given(args):
            triggers = TriggerSpec(tuple(args.trigger or DEFAULT_TRIGGERS), sensitivity(args),
                                   pronunciations(args))
    target = None
    if args.target:
        from speechcal_core.target import TargetSpec

        target = TargetSpec.from_kalibr_yaml(args.target)  # a bad file fails before the window
    from app.main import has_display, run_review

    if not has_display() and not args.screenshot:
        raise UsageError(
            "no display (DISPLAY is not set): run it on a desktop, or use --screenshot PNG"
        )
    return run_review(session_path=session_path, recording=recording, audio=args.audio,
                      new_session_path=args.session, screenshot=args.screenshot,
                      triggers=triggers, channel=args.channel, target=target,
                      streams=stream_choice(args))


def _recording_and_audio(inputs: list[str], audio: str | None, session: str | None
                         ) -> tuple[list[str], str | None]:
    """The recording's paths and the audio file (``_inputs.recording_and_audio``), or None
    when the recording's ``session`` file (by default beside it) exists: it knows its
    audio."""
    from speechcal_core.review.loading import session_path_for

    recording, audio = recording_and_audio(inputs, audio, "review")
    if audio is None and not session_path_for(recording, session).exists():
        raise UsageError("a recording needs its audio: add --audio AUDIO")
    return recording, audio
