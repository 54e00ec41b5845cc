"""The recording, its audio and its streams, from a command's inputs and options."""

from __future__ import annotations

import argparse
from pathlib import Path

from speechcal_core.errors import UsageError
from speechcal_core.fsutil import same_file
from speechcal_core.sources.selection import StreamChoice


def stream_name(value: str) -> str:
    """An argparse ``type`` for a stream's name: an empty one (an unset shell variable)
    is bad usage, refused before the recording is indexed."""
    if value.strip() == "":
        raise argparse.ArgumentTypeError(
            "an empty stream name; give a topic, video or image folder as `speechcal "
            "index RECORDING` lists them (is a shell variable unset?)")
    return value


def add_stream_options(p: argparse.ArgumentParser) -> None:
    """``--stream`` and ``--skip-stream``: which of the recording's streams are cameras."""
    p.add_argument("--stream", action="append", metavar="TOPIC", type=stream_name,
                   help="use only this stream (topic, video or image folder) of the "
                        "recording; repeat for more (default: all; `speechcal index` lists "
                        "them)")
    p.add_argument("--skip-stream", action="append", metavar="TOPIC", type=stream_name,
                   help="leave this stream out (one camera recorded twice, a depth or "
                        "infrared topic); repeat for more. An existing session leaves it "
                        "out too, keeping its review work")


def stream_choice(args: argparse.Namespace) -> StreamChoice | None:
    """The streams ``--stream`` and ``--skip-stream`` choose (None: all)."""
    choice = StreamChoice(tuple(args.stream or ()), tuple(args.skip_stream or ()))
    return choice or None


def recording_and_audio(inputs: list[str], audio: str | None, command: str
                        ) -> tuple[list[str], str | None]:
    """The recording's paths and the audio file: ``audio`` (``--audio``), or the one input
    named as audio (``recording.bag mic.ogg``, as a drop on the window opens them), or
    None when neither gives one. Audio without a recording is refused, naming ``command``
    in the advice."""
    from speechcal_core.audio import AUDIO_SUFFIXES

    sounds = [p for p in inputs if p.lower().endswith(AUDIO_SUFFIXES)]
    others = [p for p in inputs if p not in sounds]
    if audio:
        extra = [p for p in sounds if not same_file(p, audio)]
        if extra:
            raise UsageError(f"two audio files given, {extra[0]} and --audio {audio}: "
                             "give only the microphone's")
        return others, audio
    if len(sounds) == 1 and others:
        return others, sounds[0]
    if len(sounds) > 1:
        raise UsageError(f"{' and '.join(sounds)} are audio files: give only the "
                         f"microphone's (speechcal {command} RECORDING --audio AUDIO)")
    if sounds:
        if Path(sounds[0]).is_dir():  # a ROS2 bag folder with an odd name, or a typo
            raise UsageError(f"{sounds[0]} is a folder, not an audio file: give the recording "
                             f"and its audio (speechcal {command} RECORDING --audio AUDIO)")
        raise UsageError(f"{sounds[0]} is an audio file: give the recording too "
                         f"(speechcal {command} RECORDING --audio {sounds[0]})")
    return inputs, None
