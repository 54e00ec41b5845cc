"""``speechcal sync``: clap times in both clocks, offset and drift."""

from __future__ import annotations

import argparse
from dataclasses import replace
from typing import TYPE_CHECKING

from speechcal_core.cli._output import emit_json, progress
from speechcal_core.cli._paths import AUDIO, RECORDING
from speechcal_core.cli._speech_options import add_channel_option

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("sync", help="find the clap and the audio-to-camera offset")
    p.add_argument("recording", metavar="RECORDING", nargs="+", type=RECORDING)
    p.add_argument("--audio", required=True, metavar="AUDIO", type=AUDIO,
                   help="microphone file, or an audio topic inside the recording")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    add_channel_option(p)
    p.add_argument("--search-s", type=float, default=20.0, metavar="S",
                   help="look for the clap in this many seconds from each camera's start")
    p.add_argument("--audio-clap", type=float, default=None, metavar="SECONDS",
                   help="the clap's time in the audio, set by hand")
    p.add_argument("--video-clap-ns", type=int, default=None, metavar="NS",
                   help="the clap's header stamp in the cameras, set by hand")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from speechcal_core.errors import UsageError

    if not args.search_s > 0 or args.search_s == float("inf"):  # nan fails the first
        raise UsageError(f"--search-s must be a positive number of seconds, got "
                         f"{args.search_s:g}")
    # the readers and the clap search only once the options are good (a usage error at once)
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.manual import manual_sync
    from speechcal_core.sync.pipeline import sync_recording, sync_with_video_clap
    from speechcal_core.sync.sources import load_sync_audio

    with open_recording(args.recording) as source:
        # what is wrong with the files given (a part of a split bag) explains the rest
        for note in getattr(source, "notes", []):
            progress(f"note: {note}")
        audio_notes: list[str] = []  # the audio topic's stamps unusable: the clap times it
        audio, stamped = load_sync_audio(args.audio, args.recording, channel=args.channel,
                                         notes=audio_notes)
        _check_hand_set_clap(args, audio.duration_s, source)
        if stamped is not None and args.audio_clap is None and args.video_clap_ns is None:
            result = stamped
        elif args.audio_clap is not None and args.video_clap_ns is not None:
            result = manual_sync([(args.audio_clap, args.video_clap_ns)])
        elif args.video_clap_ns is not None:
            span = (min(s.first_ns for s in source.streams),
                    max(s.last_ns for s in source.streams))
            result = sync_with_video_clap(audio, args.video_clap_ns, span)
        else:
            result = sync_recording(source, audio, search_s=args.search_s,
                                    audio_clap_s=args.audio_clap, progress=progress)
    result = replace(result, warnings=(*audio_notes, *result.warnings))
    for note in result.warnings:  # notes, as every command says them (README)
        progress(f"note: {note}")
    doc = result.to_dict()
    if args.json:
        emit_json(doc)
    else:
        print(f"offset_ns {doc['offset_ns']}  drift {round(doc['drift_ppm'], 2) + 0.0:+.2f} ppm  "
              f"({doc['source']})")
        for c in doc["claps"]:
            print(f"clap  audio {c['audio_s']:.6f} s  session {c['session_ns']} ns")
        for cam in doc["cameras"]:
            print(f"{cam['name']}  clap {cam['clap_ns']} ns  "
                  f"residual {cam['residual_ns'] / 1e6:+.2f} ms")
    return 0


def _check_hand_set_clap(args: argparse.Namespace, audio_s: float,
                         source: FrameSource) -> None:
    """A clap set by hand must lie inside the audio and the recording (a typo there gives an
    offset that picks no frame at all): UsageError naming the range otherwise."""
    from speechcal_core.errors import UsageError
    from speechcal_core.sources.base import header_span_ns

    if args.audio_clap is not None and not 0.0 <= args.audio_clap <= audio_s:
        raise UsageError(f"--audio-clap {args.audio_clap:g} lies outside the audio "
                         f"({args.audio} holds 0 to {audio_s:.3f} s)")
    span = header_span_ns(source) if args.video_clap_ns is not None else None
    if span is not None:
        first, last = span
        if not first <= args.video_clap_ns <= last:
            raise UsageError(f"--video-clap-ns {args.video_clap_ns} lies outside the "
                             f"recording's header stamps ({first} to {last} ns)")
