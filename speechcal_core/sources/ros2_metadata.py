"""What a ROS2 bag folder's metadata.yaml says of its storage files, and which are gone.

The folder's files are read whatever the metadata says (a folder without it is read
too), so a split bag copied without one of its parts read as a shorter recording without
a word; its metadata still lists the part.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

KEY = "relative_file_paths:"


def listed_files(folder: Path) -> list[str]:
    """The storage files ``folder``'s metadata.yaml lists (``relative_file_paths``, block
    or flow style, as rosbag2 and rosbags write it); [] without metadata."""
    try:
        lines = (folder / "metadata.yaml").read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return []
    for k, line in enumerate(lines):
        head, _, rest = line.strip().partition(" ")
        if head != KEY:
            continue
        rest = rest.strip()
        if rest.startswith("["):  # flow style: [a.mcap, b.mcap]
            return [_plain(n) for n in rest.strip("[]").split(",") if _plain(n)]
        names = []
        for item in lines[k + 1:]:
            entry = item.strip()
            if not entry.startswith("- "):
                break
            names.append(_plain(entry[2:]))
        return names
    return []


def _plain(text: str) -> str:
    return text.strip().strip("'\"")


def missing_part_notes(paths: Sequence[Path]) -> list[str]:
    """A note for each ROS2 bag folder among ``paths`` whose metadata lists storage files
    the folder does not hold (a split bag copied without some of its parts)."""
    notes = []
    for folder in (p for p in paths if p.is_dir()):
        missing = [n for n in listed_files(folder) if not (folder / n).is_file()]
        if missing:
            shown = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more"
                                              if len(missing) > 3 else "")
            notes.append(f"{folder}: its metadata.yaml lists {shown}, not in the folder: "
                         "that part of the recording is missing (a split bag copied in "
                         "part?); copy the bag folder again whole")
    return notes
