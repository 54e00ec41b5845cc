"""``speechcal index``: image streams of a recording with counts and stamp ranges."""

from __future__ import annotations

import argparse
from dataclasses import asdict

from speechcal_core.cli._output import emit_json
from speechcal_core.cli._paths import RECORDING


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("index", help="list image streams with header-stamp ranges")
    p.add_argument("recording", metavar="RECORDING", nargs="+", type=RECORDING)
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.add_argument("--no-cache", action="store_true", help="build the index afresh")
    p.add_argument(
        "--scan",
        action="store_true",
        help="recover unindexed ROS1 bags and truncated MCAP files by scanning their chunks",
    )
    p.add_argument(
        "--video-start-ns", type=int, default=None, help="header stamp of a video's first frame"
    )
    return p


def _fmt_ns(ns: int) -> str:
    """Nanoseconds as seconds with nine decimals (-5 ns is "-0.000000005")."""
    sign = "-" if ns < 0 else ""
    sec, frac = divmod(abs(ns), 1_000_000_000)
    return f"{sign}{sec}.{frac:09d}"


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from speechcal_core.sources import open_recording

    with open_recording(
        args.recording,
        use_cache=not args.no_cache,
        scan=args.scan,
        video_start_ns=args.video_start_ns,
    ) as src:
        streams = src.streams
        notes = list(getattr(src, "notes", []))
    if args.json:
        rows = []
        for s in streams:
            row = asdict(s)
            row["bad_frames"] = list(s.bad_frames)
            rows.append(row)
        emit_json({"streams": rows, "notes": notes})
        return 0
    header = ("stream", "encoding", "size", "count", "rate Hz", "dropped", "bad", "first", "last")
    table = [header] + [
        (
            s.name,
            s.encoding,
            f"{s.width}x{s.height}",
            str(s.count),
            f"{s.nominal_rate_hz:.2f}",
            str(s.dropped),
            str(len(s.bad_frames)),
            _fmt_ns(s.first_ns),
            _fmt_ns(s.last_ns),
        )
        for s in streams
    ]
    widths = [max(len(r[k]) for r in table) for k in range(len(header))]
    for r in table:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip())
    for s in streams:
        if s.stamp_problems:
            print(f"{s.name}: {s.stamp_problems}")
    for note in notes:
        print(f"note: {note}")
    return 0
