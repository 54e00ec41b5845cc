"""``speechcal export``: write the accepted frame sets for a calibration tool."""

from __future__ import annotations

import argparse

from speechcal_core.cli._output import StageProgress, emit_json, progress
from speechcal_core.cli._paths import SESSION, TARGET, path_arg
from speechcal_core.text import counted


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser(
        "export", help="export accepted frame sets",
        description="Write the accepted frame sets of a session: kalibr (cam0/<t_ns>.png... "
                    "+ target.yaml), folders (one folder per camera topic, same file names), "
                    "rosbag1 (DIR/calibration.bag + target.yaml) or rosbag2 "
                    "(DIR/calibration/ + target.yaml), each with manifest.json and "
                    "manifest.csv. <t_ns> is the set's time (the "
                    "trigger word on the camera clock), the same name in every camera's "
                    "folder so calibration tools pair them; the manifests give each frame's "
                    "own header stamp. kalibr and folders add the corners found "
                    "(corners.json, and corners.vnl for mrcal). Sets the review left waiting "
                    "for re-scoring (after an offset edit or an added set) get their best "
                    "still frames first, saved to the session file.")
    p.add_argument("session", metavar="SESSION.json", type=SESSION)
    p.add_argument("--format", required=True, choices=("kalibr", "folders", "rosbag1", "rosbag2"),
                   help="kalibr: for Kalibr (kalibr_bagcreater makes its bag); folders: for "
                        "calib.io, mrcal and OpenCV (images per camera with corners.vnl); "
                        "rosbag1 / rosbag2: a bag for Kalibr or ROS tools")
    p.add_argument("--out", required=True, metavar="DIR",
                   type=path_arg("the folder to write the export to"),
                   help="output folder: a new one (an earlier export only with --force)")
    p.add_argument("--force", action="store_true",
                   help="replace an earlier export (or an empty folder) at DIR; a file or a "
                        "folder holding anything else is never replaced")
    p.add_argument("--include-undecided", action="store_true",
                   help="export undecided sets too (rejected sets never are)")
    p.add_argument("--target", metavar="TARGET.yaml", type=TARGET,
                   help="the board's Kalibr target yaml: the export's target.yaml and "
                        "corners describe it (default: the session's target, else the 6x6 "
                        "AprilGrid that process assumes)")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand: progress on stderr, the folder appears only when complete."""
    from speechcal_core.export import export_session_file
    from speechcal_core.target import TargetSpec

    target = TargetSpec.from_kalibr_yaml(args.target) if args.target else None
    report = StageProgress(item_prefixes=("writing ", "reading "))

    result = export_session_file(
        args.session, args.format, args.out, force=args.force,
        include_undecided=args.include_undecided, target=target, progress=report,
    )
    if result.rescored:
        n = result.rescored
        progress(f"re-scored {n} frame set{'' if n == 1 else 's'} (best still frames, saved "
                 f"to {args.session})")
    for line in result.skipped:
        progress(f"left out: {line}")
    for note in result.notes:
        progress(f"note: {note}")
    if args.json:
        emit_json(result.to_dict())
    else:
        print(f"exported {counted(result.sets, 'frame set')} ({counted(result.frames, 'frame')}, "
                 f"{result.files} files) to {result.out}")
    return 0
