"""Per-camera folders (calib.io, mrcal, multical): one folder per topic, same file names.

``/cam0/image_raw`` becomes ``cam0_image_raw/``; each set's images are ``<t_ns>.png`` in
every camera's folder.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from speechcal_core.export.images import Progress, write_image_folders
from speechcal_core.export.plan import unique_safe_names

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Outcome, Plan
    from speechcal_core.sources.base import FrameSource


def topic_folders(plan: Plan) -> dict[str, str]:
    """Stream -> filesystem-safe folder name, unique within the export."""
    return unique_safe_names(plan.streams)


def write_folders(source: FrameSource, plan: Plan, root: Path, progress: Progress) -> Outcome:
    """Images in one folder per camera topic."""
    return write_image_folders(source, plan, root, topic_folders(plan), progress)
