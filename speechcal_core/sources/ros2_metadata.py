"""What a ROS2 bag folder's metadata.yaml says of its storage files, and which are gone.

The folder's files are read whatever the metadata says (a folder without it is read
too), so a split bag copied without one of its parts read as a shorter recording without
a word; its metadata still lists the part.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


def listed_files(folder: Path) -> list[str]:
    """The storage files ``folder``'s metadata.yaml lists (``relative_file_paths`` of
    ``rosbag2_bagfile_information``); [] without readable metadata."""
    from ruamel.yaml import YAML, YAMLError

    try:
        data = YAML(typ="safe").load((folder / "metadata.yaml").read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, YAMLError):
        return []
    info = data.get("rosbag2_bagfile_information") if isinstance(data, dict) else None
    names = info.get("relative_file_paths") if isinstance(info, dict) else None
    return [str(n) for n in names if n] if isinstance(names, list) else []


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
