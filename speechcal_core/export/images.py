"""Lossless PNG frames in per-camera folders (shared by the Kalibr and folder layouts).

Each chosen frame is decoded by the frame source and encoded by ``cv2.imencode`` as PNG,
so the pixels are exactly what the source decodes: mono8 stays 8-bit grey, mono16 stays
16-bit grey, colour stays BGR; JPEG payloads are decoded once and kept losslessly; Bayer
images are demosaiced to BGR (what calibration tools read) by the source's decoder.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import cv2
import numpy as np

from speechcal_core.export.errors import ExportError
from speechcal_core.export.plan import Outcome, Progress
from speechcal_core.sources.errors import BadFrameError

if TYPE_CHECKING:
    from pathlib import Path

    from speechcal_core.export.plan import Plan
    from speechcal_core.sources.base import FrameSource



def write_png(path: Path, image: np.ndarray) -> None:
    """Write ``image`` (uint8/uint16 mono or BGR) as PNG; ``ExportError`` when it fails."""
    if image.dtype not in (np.uint8, np.uint16):
        raise ExportError(f"{path}: cannot write a {image.dtype} image as PNG")
    try:
        ok, encoded = cv2.imencode(".png", image, [cv2.IMWRITE_PNG_COMPRESSION, 3])
    except cv2.error as exc:
        raise ExportError(f"{path}: OpenCV could not encode the PNG ({exc})") from None
    if not ok:
        raise ExportError(f"{path}: OpenCV could not encode the PNG")
    # written here, not by cv2.imwrite: its libpng printed "libpng error: Write Error"
    # on a full disk and said no more than that it failed
    try:
        path.write_bytes(encoded.tobytes())
    except OSError as exc:
        raise ExportError(f"{path}: could not write the PNG ({exc.strerror}); check free "
                          "disk space") from None


def write_image_folders(
    source: FrameSource,
    plan: Plan,
    root: Path,
    folders: dict[str, str],
    progress: Progress,
) -> Outcome:
    """``root/<folders[stream]>/<name>.png`` for every planned frame.

    A frame the source cannot decode is left out (and named in ``Outcome.skipped``).
    """
    out = Outcome.empty()
    for stream in plan.streams:
        (root / folders[stream]).mkdir()
    total = max(len(plan.frames), 1)
    for k, pf in enumerate(plan.frames):
        key = (pf.frame_set.id, pf.choice.stream)
        rel = f"{folders[pf.choice.stream]}/{pf.name}.png"
        progress(f"writing {rel}", k / total)
        try:
            image = source.frame(pf.choice.stream, pf.index)
        except BadFrameError as exc:
            out.skipped[key] = str(exc)
            continue
        write_png(root / rel, image)
        out.files[key] = rel
        out.written.append(rel)
    return out
