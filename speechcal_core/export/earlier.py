"""What an export may replace when forced: an empty folder or an earlier export, as its
manifest lists it, and nothing the operator put there besides."""

from __future__ import annotations

import json
from pathlib import Path

from speechcal_core.target import TargetError, TargetSpec
from speechcal_core.text import listed

#: files every export writes beside the frames (target.yaml: TARGET_FORMATS; corners.json
#: and corners.vnl: the image formats)
EXPORT_OWN = frozenset({"manifest.json", "manifest.csv", "target.yaml", "corners.json",
                        "corners.vnl"})
FORMATS = ("kalibr", "folders", "rosbag1", "rosbag2")
TARGET_FILE = "target.yaml"  # Kalibr's target description, beside the frames
#: formats whose export describes the board in TARGET_FILE: everything
#: ``kalibr_calibrate_cameras`` needs is then in one folder (``--bag`` and ``--target``)
TARGET_FORMATS = ("kalibr", "rosbag1", "rosbag2")


def not_replaceable(out: Path, board: TargetSpec | None = None) -> str:
    """Why an existing ``out`` must not be replaced by an export even when forced ("" if
    it may): a file, a folder that is no earlier export, an earlier export holding files
    it did not write (a calibration result, notes), or one whose ``target.yaml`` now
    describes another board than it wrote and than ``board`` (the one the new export
    writes, if known): the operator measured the board. A link may go: replacing it
    leaves what it points to."""
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
    return edited_target(out, board)


def edited_target(out: Path, board: TargetSpec | None = None) -> str:
    """Why the earlier export ``out`` is kept for its ``target.yaml`` ("" if not): the file
    describes another board than the manifest says the export wrote (an edited tag size)
    and than ``board``; or it no longer reads as a target."""
    path = out / TARGET_FILE
    wrote = _written_board(out / "manifest.json")
    if wrote is None or not path.is_file():
        return ""
    keep = (f"and an export never replaces that; to export for that board, give {path} "
            "as the target (speechcal export --target, or Target file… in the window's "
            f"export dialog), or move {TARGET_FILE} away")
    try:
        now = TargetSpec.from_kalibr_yaml(path)
    except TargetError:
        return f"its {TARGET_FILE} was changed and no longer reads as a target, {keep}"
    if now in (wrote, board):
        return ""
    return (f"its {TARGET_FILE} was changed after the export wrote it: it describes a "
            f"{now.describe()}, the export wrote a {wrote.describe()}, {keep}")


def _written_board(manifest: Path) -> TargetSpec | None:
    """The board an export's ``target.yaml`` described when written (its manifest's
    ``"target"``), or None (no such export, or not Kalibr's)."""
    document = _manifest(manifest)
    board = document.get("target") if document is not None else None
    if not isinstance(board, dict):
        return None
    try:
        return TargetSpec(str(board["kind"]), int(board["rows"]), int(board["cols"]),
                          float(board["size"]), float(board["spacing"]))
    except (KeyError, TypeError, ValueError, TargetError):
        return None


def enclosing_export(out: Path) -> Path | None:
    """The earlier export ``out`` would lie inside, or None: a calibration tool reading
    that export would take the new one's frames too (a Kalibr camera folder is read with
    everything under it), and that export could no longer be replaced."""
    for folder in Path(out).absolute().parents:
        if (folder / "manifest.json").is_file() and \
                export_files(folder / "manifest.json") is not None:
            return folder
    return None


def _manifest(manifest: Path) -> dict | None:
    """An export's ``manifest.json`` as a dict; None when that is not one."""
    try:
        document = json.loads(manifest.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not (isinstance(document, dict) and document.get("format") in FORMATS
            and isinstance(document.get("sets"), list)):
        return None
    return document


def export_files(manifest: Path) -> set[str] | None:
    """The paths (relative, with ``/``) an export wrote, from its ``manifest.json``; None
    when that is not the manifest of an export."""
    document = _manifest(manifest)
    if document is None:
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

