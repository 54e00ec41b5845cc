"""What an export may replace when forced: an empty folder or an earlier export, as its
manifest lists it, and nothing the operator put there besides."""

from __future__ import annotations

import json
from pathlib import Path

from speechcal_core.text import listed

#: files every export writes beside the frames (target.yaml: kalibr only; corners.json
#: and corners.vnl: the image formats)
EXPORT_OWN = frozenset({"manifest.json", "manifest.csv", "target.yaml", "corners.json",
                        "corners.vnl"})
FORMATS = ("kalibr", "folders", "rosbag1", "rosbag2")


def not_replaceable(out: Path) -> str:
    """Why an existing ``out`` must not be replaced by an export even when forced ("" if
    it may): a file, a folder that is no earlier export, or an earlier export holding files
    it did not write (a calibration result, notes). A link may go: replacing it leaves what
    it points to."""
    if out.is_symlink() or not out.exists():
        return ""
    if not out.is_dir():
        return "this is a file, not an export folder"
    names = sorted(child.name for child in out.iterdir())
    if not names:
        return ""
    written = export_files(out / "manifest.json")
    if written is None:
        return (f"this folder holds files that are not an export ({listed(names)}), and an "
                "export never replaces those")
    extra = [rel for rel in _files_under(out)
             if not any(rel == w or rel.startswith(w + "/") for w in written)]
    if extra:
        return (f"this earlier export also holds files it did not write ({listed(extra)}), "
                "and an export never replaces those")
    return ""


def enclosing_export(out: Path) -> Path | None:
    """The earlier export ``out`` would lie inside, or None: a calibration tool reading
    that export would take the new one's frames too (a Kalibr camera folder is read with
    everything under it), and that export could no longer be replaced."""
    for folder in Path(out).absolute().parents:
        if (folder / "manifest.json").is_file() and \
                export_files(folder / "manifest.json") is not None:
            return folder
    return None


def export_files(manifest: Path) -> set[str] | None:
    """The paths (relative, with ``/``) an export wrote, from its ``manifest.json``; None
    when that is not the manifest of an export."""
    try:
        document = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not (isinstance(document, dict) and document.get("format") in FORMATS
            and isinstance(document.get("sets"), list)):
        return None
    written = set(EXPORT_OWN)
    for frame_set in document["sets"]:
        for frame in frame_set.get("frames", []) if isinstance(frame_set, dict) else []:
            if isinstance(frame, dict) and isinstance(frame.get("file"), str):
                written.add(frame["file"].strip("/"))
    return written


def _files_under(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*")
                  if not p.is_dir())

