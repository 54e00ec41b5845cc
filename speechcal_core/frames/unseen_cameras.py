"""Notes on cameras that found the target in none of their frames while others found it."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from speechcal_core.frames.detect import Target
    from speechcal_core.session.model import FrameSet

#: the AprilGrid tag side (px) under which OpenCV's marker search reads no tag: a 320x240
#: pinhole view that reads all 36 tags at 18-25 px reads none once shrunk to 12-13 px;
#: the fisheye cameras of a 320x240 synthetic session show the tags 9-10 px across
SMALLEST_TAG_PX = 13


def unseen_camera_notes(sets: Sequence[FrameSet], target: Target) -> list[str]:
    """One note per camera whose chosen frames all lack the target although other
    cameras found it in some of the same sets: the camera sees the board too small (a
    fisheye lens, a low resolution, the board held far) or not at all, and will get no
    calibration check. None when no camera found the target (``target_not_found_note``)."""
    seen = {s.id for s in sets if any(f.corners for f in s.frames if f.index >= 0)}
    if not seen:
        return []
    streams = list(dict.fromkeys(f.stream for s in sets for f in s.frames))
    notes = []
    for name in streams:
        mine = [(s.id, f) for s in sets for f in s.frames if f.stream == name and f.index >= 0]
        if not mine or any(f.corners for _, f in mine):
            continue
        others = sum(1 for i, _ in mine if i in seen)
        if not others:
            continue
        why = (f"its tags are likely under about {SMALLEST_TAG_PX} px across there, too small "
               "to read (a fisheye lens or a low resolution shows the board small)"
               if target.kind == "aprilgrid"
               else "the board likely shows too small there to find (a fisheye lens or a "
               "low resolution shows it small)")
        notes.append(f"{name}: the {target.describe()} was found in none of its "
                     f"{len(mine)} frames, though other cameras found it in {others} of the "
                     f"same sets; {why}, or it is out of the camera's view. This camera "
                     "gets no calibration check: hold the board closer to it, or record it "
                     "at a higher resolution")
    return notes
