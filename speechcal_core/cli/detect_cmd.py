"""``speechcal detect``: trigger words with start, end, t and score in audio seconds."""

from __future__ import annotations

import argparse

from speechcal_core.cli._output import emit_json, progress
from speechcal_core.cli._paths import AUDIO, TRANSCRIPT, path_arg
from speechcal_core.cli._speech_options import (
    add_channel_option,
    add_trigger_options,
    pronunciations,
    sensitivity,
)
from speechcal_core.errors import UsageError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("detect", help="find trigger words in an audio file")
    p.add_argument("audio", metavar="AUDIO", type=AUDIO)
    add_channel_option(p)
    add_trigger_options(p)
    p.add_argument("--backend", default="pocketsphinx",
                   help="pocketsphinx (default), faster-whisper, whisperx or example")
    p.add_argument("--transcript", metavar="F", type=TRANSCRIPT,
                   help="take words from a transcript file")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--model-dir", metavar="DIR", type=path_arg("the model folder"),
                   help="local model folder for Whisper backends")
    p.add_argument("--example", action="append", default=[], metavar="START:END",
                   help="a marked instance (audio seconds) for --backend example")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from speechcal_core.speech import detect_triggers

    detection = detect_triggers(
        args.audio, args.trigger or ["capture"], backend=args.backend,
        transcript=args.transcript, sensitivity=sensitivity(args),
        pronunciations=pronunciations(args), model_dir=args.model_dir,
        examples=[_span(s) for s in args.example], channel=args.channel,
    )
    for note in detection.notes:
        progress(f"note: {note}")
    if args.json:
        emit_json(detection.to_json())
    else:
        for w in detection.triggers:
            print(f"{w.t:10.3f}  {w.word:<12} {w.start_s:.3f}-{w.end_s:.3f}  score {w.score:.2f}")
    return 0


def _span(text: str) -> tuple[float, float]:
    a, sep, b = text.partition(":")
    try:
        start, end = float(a), float(b)
    except ValueError:
        start = end = -1.0
    if sep and 0 <= end <= start:
        raise UsageError(f"--example {text!r}: the end ({b}) must come after the start ({a}); "
                         "write START:END in audio seconds, e.g. 12.3:12.9")
    if not sep or not 0 <= start < end:
        raise UsageError(f"--example {text!r}: write START:END in audio seconds, e.g. 12.3:12.9")
    return start, end
