"""Kalibr layout: ``cam0/<t_ns>.png``, ``cam1/<t_ns>.png``… and ``target.yaml``.

Cameras are numbered in the recording's stream order (the manifest names each ``camN``'s
topic). ``kalibr_bagcreater --folder OUT --output-bag calib.bag`` turns the folder into a
bag whose ``/camN/image_raw`` messages of one set share a stamp.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from speechcal_core.export.earlier import TARGET_FILE
from speechcal_core.export.images import Progress, write_image_folders
from speechcal_core.fsutil import atomic_write_text

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Outcome, Plan
    from speechcal_core.sources.base import FrameSource
    from speechcal_core.target import TargetSpec



def kalibr_folders(plan: Plan) -> dict[str, str]:
    """Stream -> ``camN`` for the exported cameras (:func:`kalibr_camera`)."""
    return {stream: kalibr_camera(plan, stream) for stream in plan.streams}


def kalibr_camera(plan: Plan, stream: str) -> str:
    """``camN``, N the stream's place in the recording: a camera without frames in the
    export leaves its number free rather than shifting the others' (an earlier camchain
    keeps matching)."""
    return f"cam{plan.recording_streams.index(stream)}"


def write_kalibr(
    source: FrameSource, plan: Plan, root: Path, target: TargetSpec, progress: Progress
) -> Outcome:
    """Images per camera folder plus the Kalibr target description."""
    out = write_image_folders(source, plan, root, kalibr_folders(plan), progress)
    write_target_file(root, target, out)
    return out


def write_target_file(root: Path, target: TargetSpec, out: Outcome) -> None:
    """``root/target.yaml``, the board as ``kalibr_calibrate_cameras --target`` reads it,
    listed among ``out``'s files."""
    atomic_write_text(root / TARGET_FILE, target.to_kalibr_yaml())
    out.written.append(TARGET_FILE)
