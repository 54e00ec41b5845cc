"""Recording sources: every input kind behind one ``FrameSource`` keyed by header stamp."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.sources.base import FrameSource, RawFrame, StreamInfo
from speechcal_core.sources.errors import BadFrameError, SourceError
from speechcal_core.sources.ros2_metadata import missing_part_notes
from speechcal_core.sources.selection import StreamChoice

if TYPE_CHECKING:
    from collections.abc import Sequence

    from speechcal_core.sources.scan import MessageFile

__all__ = [
    "BadFrameError",
    "FrameSource",
    "RawFrame",
    "SourceError",
    "StreamChoice",
    "StreamInfo",
    "open_recording",
]

VIDEO_SUFFIXES = {".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v"}


def _bag_files(path: Path, scan: bool) -> list[MessageFile]:
    from speechcal_core.sources.mcap import McapFile
    from speechcal_core.sources.rosbag1 import Ros1Bag
    from speechcal_core.sources.rosbag2 import Sqlite3File, ros2_folder_files

    if path.is_dir():
        return [*ros2_folder_files(path, scan=scan)]
    suffix = path.suffix.lower()
    if suffix in (".bag", ".active") or path.name.endswith(".bag.active"):
        return [Ros1Bag(path, scan=scan)]
    if suffix == ".db3":
        return [Sqlite3File(path)]
    if suffix == ".mcap":
        return [McapFile(path, scan=scan)]
    from speechcal_core.sources.sniff import looks_like

    seen = looks_like(path)
    raise SourceError(
        f"{path}: " + (f"this is {seen}, not a recording" if seen else
                       "unknown recording kind")
        + "; expected a ROS1 .bag, a ROS2 bag folder, .db3, .mcap, a video file or a "
        "folder of <stamp_ns>.png images"
    )


def open_recording(
    paths: Sequence[str | Path] | str | Path,
    *,
    use_cache: bool = True,
    scan: bool = False,
    video_start_ns: int | None = None,
    streams: StreamChoice | None = None,
) -> FrameSource:
    """Open a recording (one or several files) as a ``FrameSource``.

    ``paths``: ROS1 ``.bag`` files, ROS2 bag folders, bare ``.db3``/``.mcap`` files (all
    bags are merged by topic), video files (one stream each), or a folder of per-camera
    image folders; different kinds together give one source with all their streams.
    ``scan`` recovers unindexed ROS1 bags and truncated MCAP files by walking their chunks.
    Indexes (bags, videos) are cached beside each file, or under the user cache dir when
    that folder is not writable, keyed by size and mtime; ``use_cache=False`` rebuilds
    them. A recovered index is cached too, with its ``notes``.
    ``video_start_ns`` is the header stamp of a video's first frame (default: a
    ``<video>.start_ns`` text file beside it, else an integer file name, else 0).
    ``streams`` chooses some of its streams (``selection.StreamChoice``; a name the
    recording lacks is a SourceError).
    """
    if isinstance(paths, (str, Path)):
        paths = [paths]
    items = [Path(p) for p in paths]
    if not items:
        raise SourceError("no recording given")
    for p in items:
        if not p.exists():
            raise SourceError(f"{p}: file not found; check the path")
    items = _distinct(items)  # one file named twice (a shell glob and the name) is read once
    videos = [p for p in items if p.is_file() and p.suffix.lower() in VIDEO_SUFFIXES]
    sources: list[FrameSource] = []
    files: list[MessageFile] = []
    try:
        for p in items:
            if p in videos:
                from speechcal_core.sources.video import VideoSource

                start = video_start_ns if len(videos) == 1 else None
                sources.append(VideoSource(p, start_ns=start, use_cache=use_cache))
            elif p.is_dir() and not _is_ros2_folder(p):
                from speechcal_core.sources.image_folder import ImageFolderSource

                sources.append(ImageFolderSource(p))
            else:
                files.extend(_bag_files(p, scan))
        if files:
            from speechcal_core.sources.bag_source import BagSource

            bags = BagSource(files, use_cache=use_cache)
            files = []
            bags.notes.extend(split_part_notes(items))
            bags.notes.extend(missing_part_notes(items))
            sources.insert(0, bags)
        from speechcal_core.sources.selection import select_streams

        if len(sources) == 1:
            return select_streams(sources[0], streams)
        from speechcal_core.sources.combined import CombinedSource

        return select_streams(CombinedSource(sources), streams)
    except BaseException:
        for f in files:
            f.close()
        for src in sources:
            src.close()
        raise


def split_part_notes(paths: Sequence[Path]) -> list[str]:
    """A note for each ROS2 bag folder of which some storage files were given, not all:
    a split bag's part opened alone holds only part of the recording."""
    given = {p.resolve() for p in paths if p.is_file()}
    notes = []
    for folder in dict.fromkeys(p.parent for p in given):
        if not (folder / "metadata.yaml").is_file():
            continue
        parts = sorted(p.resolve() for p in folder.iterdir() if p.suffix in (".db3", ".mcap"))
        mine = [k + 1 for k, p in enumerate(parts) if p in given]
        if len(parts) > 1 and len(mine) < len(parts):
            which = ", ".join(str(k) for k in mine)
            notes.append(f"{folder}: part{'s' * (len(mine) > 1)} {which} of the {len(parts)} "
                         "files of this split ROS2 bag given, so only part of the recording "
                         f"is read; give the folder {folder} for all of it")
    return notes


def _distinct(paths: list[Path]) -> list[Path]:
    """``paths`` in order, without the ones naming a file or folder named before, and
    without files inside a folder also given (a ROS2 bag folder and its own .db3)."""
    real = [p.resolve() for p in paths]
    folders = [r for r in real if r.is_dir()]
    out: list[Path] = []
    for p, r in zip(paths, real, strict=True):
        inside = any(q in r.parents for q in folders)
        if not inside and not any(p.samefile(q) for q in out):
            out.append(p)
    return out


def _is_ros2_folder(path: Path) -> bool:
    return (path / "metadata.yaml").is_file() or any(
        p.suffix in (".db3", ".mcap") for p in path.iterdir()
    )
