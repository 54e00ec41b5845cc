"""``speechcal demo``: make a synthetic session and open it in the review window."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

from speechcal_core.cli._output import progress

DEMO_SEED = 7


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the subcommand and its options."""
    p = subparsers.add_parser("demo", help="open a synthetic demo session")
    p.add_argument("--workdir", metavar="DIR",
                   help="where to write the demo session (default: ~/.cache/speechcal/demo)")
    p.add_argument("--screenshot", metavar="PNG", help="render the window to PNG and exit")
    return p


def default_workdir() -> Path:
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(cache) / "speechcal" / "demo"


def ensure_demo_session(workdir: Path) -> Path:
    """Generate the demo recording once; later runs reuse it (and the review work in it)."""
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    truth = workdir / "truth.json"
    if truth.exists():
        progress(f"using the demo session in {workdir}")
        return workdir
    progress(f"making a synthetic demo session in {workdir} …")
    options = SynthOptions(cameras=4, fisheye=1, duration=45.0, seed=DEMO_SEED, claps=2)
    generate_session(workdir, options, force=workdir.exists(),
                     progress=lambda stage, f: None)
    return workdir


def run(args: argparse.Namespace) -> int:
    """Run the subcommand."""
    from app.main import has_display, run_review

    workdir = Path(args.workdir) if args.workdir else default_workdir()
    ensure_demo_session(workdir)
    truth = json.loads((workdir / "truth.json").read_text())
    recording = str(workdir / truth["recording"])
    audio = str(workdir / truth["audio"])
    if has_display() or args.screenshot:
        return run_review(recording=[recording], audio=audio, screenshot=args.screenshot)
    progress("no display here (DISPLAY is not set): running the pipeline headless instead")
    from speechcal_core.review.loading import load_for_review

    inputs = load_for_review(recording=[recording], audio=audio,
                             progress=lambda text, f: progress(f"{text} ({f:.0%})"))
    session = inputs.session
    inputs.close()
    progress(f"{len(session.sets)} frame sets found; session file: {inputs.session_path}")
    shot = workdir / "demo-window.png"
    progress(f"rendering the review window to {shot}")
    return run_review(session_path=str(inputs.session_path), screenshot=str(shot))
