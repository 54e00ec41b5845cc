"""``speechcal demo``: make a synthetic session and open it in the review window."""

from __future__ import annotations

import argparse
from pathlib import Path

from speechcal_core.cli._output import StageProgress, progress
from speechcal_core.cli._paths import SCREENSHOT, path_arg
from speechcal_core.text import counted


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("demo", help="open a synthetic demo session")
    p.add_argument("--workdir", metavar="DIR", type=path_arg("the demo's folder"),
                   help="where to write the demo session (default: ~/.cache/speechcal/demo)")
    p.add_argument("--screenshot", metavar="PNG", type=SCREENSHOT,
                   help="render the window to PNG and exit")
    return p


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from app.main import check_screenshot_path, has_display, run_review
    from speechcal_core.synth.demo import check_demo_folder, default_demo_dir, ensure_demo_session

    if args.screenshot:
        check_screenshot_path(args.screenshot)  # before minutes of making the session
    workdir = Path(args.workdir) if args.workdir else default_demo_dir()
    check_demo_folder(workdir)  # before announcing a demo that would not be made
    if not (workdir / "truth.json").exists():
        progress(f"making a synthetic demo session in {workdir} …")
    else:
        # a --workdir given may hold the user's own work beside a synthetic session
        fresh = ("remove that folder for a new one" if not args.workdir
                 else "give --workdir a new or empty folder for a new one")
        progress(f"using the synthetic session in {workdir} ({fresh})")
    recording, audio = ensure_demo_session(workdir)
    if has_display() or args.screenshot:
        return run_review(recording=[recording], audio=audio, screenshot=args.screenshot)
    progress("no display here (DISPLAY is not set): running the pipeline headless instead")
    from speechcal_core.review.loading import load_for_review

    inputs = load_for_review(recording=[recording], audio=audio,
                             progress=StageProgress())
    session = inputs.session
    inputs.close()
    progress(f"{counted(len(session.sets), 'frame set')} found; "
             f"session file: {inputs.session_path}")
    shot = workdir / "demo-window.png"
    progress(f"rendering the review window to {shot}")
    code = run_review(session_path=str(inputs.session_path), screenshot=str(shot))
    if code == 0:
        progress(f"on a screen, review it with: speechcal review {inputs.session_path}")
    return code
