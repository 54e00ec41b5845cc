"""The target corners found in each exported image, for tools that do not find them.

``corners.json`` gives OpenCV what ``cv2.calibrateCamera`` takes: per image the corner
ids and pixel positions, and the board's 3-D corner positions indexed by id (Kalibr's
order). ``corners.vnl`` is mrcal's corners cache (``mrcal-calibrate-cameras
--corners-cache``): mrcal models a board as a regular grid, so a checkerboard gives every
inner corner and an AprilGrid the first corner (Kalibr's lower left) of each tag, which lie
one tag pitch apart. A corner not found is listed with '-' (mrcal leaves it out), an image
without the board as one line of '-'.

The corners are the ones the session found on each chosen frame; they are written only
for frames whose stored detection counts as many corners as the frame's figure says (and
was found in that very frame, where the session says which: ``stamp_ns``), and
only for sessions that name the board they were found on (sessions made before they did
get no corners files, and a note says so). A checkerboard's corners are numbered from
the end nearer the image's top left (``upright_checkerboard``), sessions made before
that included.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from typing import TYPE_CHECKING, Any

import numpy as np

from speechcal_core.calibration.collect import detections_from_details
from speechcal_core.frames.detect import Detection, upright_checkerboard
from speechcal_core.fsutil import atomic_write_text
from speechcal_core.target import TargetSpec

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Outcome, Plan
    from speechcal_core.session.model import Session
    from speechcal_core.sources.base import FrameSource

CORNERS_JSON = "corners.json"
CORNERS_VNL = "corners.vnl"


def corners_board(session: Session, export_target: TargetSpec) -> TargetSpec | None:
    """The board the corner ids refer to: the one the session's frames were checked
    against, with the export's size when the export describes the same layout (a size
    measured after processing); None when the session names no board."""
    checked = TargetSpec.from_session(session.extra)[0]
    if checked is None:
        return None
    same = (checked.kind, checked.rows, checked.cols) == \
        (export_target.kind, export_target.rows, export_target.cols)
    return export_target if same else checked


def corners_problem(session: Session) -> str:
    """Why no corners files can be written for ``session`` ("" when they can)."""
    details = session.extra.get("frame_details")
    entries = [entry for d in details.values() if isinstance(d, dict)
               for entry in (d.get("frames") or {}).values() if isinstance(entry, dict)] \
        if isinstance(details, dict) else []
    if not entries:
        return ("no corners.json or corners.vnl: the session holds no found corners "
                "(process the recording again to have them)")
    if not any("ids" in entry for entry in entries):
        return ("no corners.json or corners.vnl: no target corners were found in the "
                "session's frames (the board too small or blurred in them, or another "
                "board than the one looked for: see the calibration check)")
    if TargetSpec.from_session(session.extra)[0] is None:
        return ("no corners.json or corners.vnl: the session does not name the board its "
                "corners were found on (process the recording again, with --target)")
    return ""


def mrcal_grid(board: TargetSpec) -> tuple[np.ndarray, float]:
    """The corner ids mrcal's regular grid lists (row by row, ``board.cols`` wide) and the
    grid's spacing in metres."""
    n = board.rows * board.cols
    if board.kind == "aprilgrid":
        return np.arange(n) * 4, board.pitch  # each tag's first corner
    return np.arange(n), board.size


def write_corners(source: FrameSource, plan: Plan, outcome: Outcome, root: Path,
                  session: Session, board: TargetSpec) -> list[str]:
    """Write ``corners.json`` and ``corners.vnl`` for the images ``outcome`` holds; the
    names written."""
    details = session.extra.get("frame_details")
    detections = detections_from_details(details) if isinstance(details, dict) else {}
    sizes = {s.name: (s.width, s.height) for s in source.streams}
    grid_ids, spacing = mrcal_grid(board)
    images: list[dict[str, Any]] = []
    rows = ["# filename x y level"]
    for frame in plan.frames:
        key = (frame.frame_set.id, frame.choice.stream)
        file = outcome.files.get(key)
        if file is None:
            continue  # not written (undecodable frame): named in the manifest
        if _found_in(details, key) not in (None, frame.choice.stamp_ns):
            det = None  # found in another frame than the one exported
        else:
            det = _stored_detection(detections.get(key), frame.choice.corners, board)
        images.append({
            "file": file, "stream": frame.choice.stream, "set_id": frame.frame_set.id,
            "image_size": list(sizes.get(frame.choice.stream, (0, 0))),
            "ids": det.ids.tolist() if det is not None else [],
            "points": np.round(det.points, 3).tolist() if det is not None else [],
        })
        rows += _vnl_rows(file, det, grid_ids)
    target = asdict(board)
    if board.kind != "aprilgrid":
        del target["spacing"]  # a tag gap: nothing on a checkerboard
    document = {
        "schema": 1,
        "target": target,
        "object_points": np.round(board.object_points(), 6).tolist(),
        "mrcal": {"object_spacing": round(spacing, 6), "object_width_n": board.cols,
                  "object_height_n": board.rows,
                  "points": "each tag's first corner" if board.kind == "aprilgrid"
                  else "every inner corner"},
        "images": images,
    }
    atomic_write_text(root / CORNERS_JSON, json.dumps(document, indent=1) + "\n")
    atomic_write_text(root / CORNERS_VNL, "\n".join(rows) + "\n")
    return [CORNERS_JSON, CORNERS_VNL]


def _found_in(details: object, key: tuple[int, str]) -> int | None:
    """The stamp of the frame a set's stored corners were found in (None: not stored,
    as in sessions made before it was)."""
    try:
        stamp = details[str(key[0])]["frames"][key[1]]["stamp_ns"]  # type: ignore[index]
    except (KeyError, TypeError):
        return None
    return int(stamp) if isinstance(stamp, int) else None


def _stored_detection(det: Detection | None, corners: int | None,
                      board: TargetSpec) -> Detection | None:
    """The stored detection when it is the chosen frame's (same corner count) and names
    corners of ``board``; a whole checkerboard numbered from its top-left end."""
    n = board.object_points().shape[0]
    if det is None or corners is None or det.count != corners or det.count == 0 \
            or int(det.ids.max()) >= n or int(det.ids.min()) < 0:
        return None
    if board.kind == "checkerboard" and det.count == n and \
            np.array_equal(det.ids, np.arange(n)):
        return Detection(upright_checkerboard(det.points), det.ids)
    return det


def _vnl_rows(file: str, det: Detection | None, grid_ids: np.ndarray) -> list[str]:
    """mrcal corners-cache lines of one image: one per grid point, or one of '-'."""
    if det is None:
        return [f"{file} - - -"]
    found = {int(i): p for i, p in zip(det.ids, det.points, strict=True)}
    if not any(int(i) in found for i in grid_ids):
        return [f"{file} - - -"]
    out = []
    for i in grid_ids:
        p = found.get(int(i))
        out.append(f"{file} {p[0]:.3f} {p[1]:.3f} 0" if p is not None else f"{file} - - -")
    return out
