"""Folders of ``<stamp_ns>.png|jpg`` images, one sub-folder per camera (Kalibr layout)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from speechcal_core.sources.base import RawFrame, StreamInfo
from speechcal_core.sources.common import StreamTable
from speechcal_core.sources.decode import decode_compressed
from speechcal_core.sources.errors import BadFrameError, SourceError
from speechcal_core.sources.stats import MAX_STAMP_NS, stamp_stats

IMAGE_SUFFIXES = {".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg"}
#: a camera's frames lie further apart than this (10 kHz); names closer are no stamps_ns
MIN_PERIOD_NS = 100_000


def _stamped_images(folder: Path) -> list[tuple[int, str]]:
    """The ``<stamp_ns>.<image suffix>`` files in ``folder`` as (stamp, name), in stamp
    order: a file name carries no recording order, so none is out of order (the
    folder's listing order is arbitrary)."""
    out: list[tuple[int, str]] = []
    with os.scandir(folder) as it:
        for entry in it:
            stem, suffix = os.path.splitext(entry.name)
            if suffix.lower() in IMAGE_SUFFIXES and stem.isdigit() and entry.is_file():
                out.append((int(stem), entry.name))
    return sorted(out)


def _first_readable_size(
    folder: Path, names: list[str]
) -> tuple[tuple[int, int], list[tuple[int, str]]]:
    """(height, width) of the first image in ``names`` that decodes ((0, 0) when none
    does), and the (index, reason) of the ones before it that do not."""
    unreadable: list[tuple[int, str]] = []
    for i, name in enumerate(names):
        try:
            img = decode_compressed((folder / name).read_bytes())
        except BadFrameError as exc:
            unreadable.append((i, str(exc)))
            continue
        except OSError as exc:
            raise SourceError(f"{folder / name}: cannot read ({exc.strerror})") from None
        return (int(img.shape[0]), int(img.shape[1])), unreadable
    return (0, 0), unreadable


def _unreadable_note(folder: Path, names: list[str], unreadable: list[tuple[int, str]]) -> str:
    """What to tell about the images that cannot be read, naming the first few."""
    shown = ", ".join(f"{names[i]} ({why})" for i, why in unreadable[:3])
    more = f" and {len(unreadable) - 3} more" if len(unreadable) > 3 else ""
    if len(unreadable) == len(names):
        return (f"{folder}: none of its {len(names)} images can be read: {shown}{more}; "
                "marked as bad frames (re-copy or re-export the camera's images)")
    many = len(unreadable) > 1
    return (f"{folder}: {len(unreadable)} image{'s' * many} cannot be read: {shown}{more}; "
            f"marked as {'bad frames' if many else 'a bad frame'} (re-copy or re-export "
            f"{'them' if many else 'it'} to use {'them' if many else 'it'})")


class ImageFolderSource(StreamTable):
    """``ROOT/cam0/<stamp_ns>.png``... (or images directly in ROOT: one stream)."""

    def __init__(self, root: Path) -> None:
        super().__init__()
        self.root = Path(root)
        if not self.root.is_dir():
            raise SourceError(f"{self.root}: folder not found")
        self._files: dict[str, tuple[Path, list[str]]] = {}
        folders = [p for p in sorted(self.root.iterdir()) if p.is_dir()]
        candidates = [(p.name, p) for p in folders]
        if _stamped_images(self.root):
            candidates.insert(0, (self.root.name, self.root))
        for name, folder in candidates:
            items = _stamped_images(folder)
            if items:
                self._add_folder(name, folder, items)
        if not self._infos:
            inside = _recordings_in(self.root)
            raise SourceError(
                f"{self.root}: no <stamp_ns>.png/.jpg images in it or its sub-folders "
                "(expected the Kalibr layout cam0/<stamp_ns>.png, cam1/...)"
                + (f"; it holds {inside[0].name}: give that "
                   f"{'ROS2 bag folder' if inside[0].is_dir() else 'file'}" if inside else "")
            )

    def _add_folder(self, name: str, folder: Path, items: list[tuple[int, str]]) -> None:
        if items[-1][0] >= MAX_STAMP_NS:  # sorted: the last is the largest
            raise SourceError(
                f"{folder}: its image {items[-1][1]} is named beyond any header stamp; name "
                "each image by its header stamp in nanoseconds since 1970 (<stamp_ns>.png, "
                "e.g. 1700000000000000000.png)")
        st = stamp_stats([np.array([s for s, _ in items], np.int64)])
        if 0 < st.median_period_ns < MIN_PERIOD_NS:
            raise SourceError(
                f"{folder}: its images' names ({items[0][1]}, {items[1][1]}, …) lie "
                f"{st.median_period_ns} ns apart: frame numbers (or milli- or microseconds), "
                "not header stamps in nanoseconds; name each image by its header stamp in "
                "nanoseconds (<stamp_ns>.png, as Kalibr's bag extractor writes them)")
        names = [items[k][1] for k in st.order]
        (height, width), unreadable = _first_readable_size(folder, names)
        if unreadable:
            self.notes.append(_unreadable_note(folder, names, unreadable))
        kinds = {IMAGE_SUFFIXES[os.path.splitext(n)[1].lower()] for n in names}
        info = StreamInfo(
            name=name,
            msgtype="file",
            encoding="/".join(sorted(kinds)),
            width=int(width),
            height=int(height),
            count=len(names),
            first_ns=int(st.stamps[0]),
            last_ns=int(st.stamps[-1]),
            median_period_ns=st.median_period_ns,
            nominal_rate_hz=st.nominal_rate_hz,
            dropped=st.dropped,
            stamp_problems=st.problems,
            bad_frames=tuple(i for i, _ in unreadable),
        )
        self._files[name] = (folder, names)
        self._add_stream(info, st.stamps)

    def _path(self, stream: str, i: int) -> Path:
        self._check(stream, i)
        folder, names = self._files[stream]
        return folder / names[i]

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded image file i; ``BadFrameError`` (and marked bad) if it is corrupt."""
        path = self._path(stream, i)
        try:
            return decode_compressed(path.read_bytes())
        except BadFrameError as exc:
            self._mark_bad(stream, i)
            raise BadFrameError(f"{path}: {exc}; frame marked bad") from None
        except OSError as exc:
            raise SourceError(f"{path}: cannot read ({exc.strerror})") from None

    def raw(self, stream: str, i: int) -> RawFrame:
        """The image file's bytes."""
        path = self._path(stream, i)
        info = self._infos[stream]
        return RawFrame(
            stream=stream,
            msgtype="file",
            rawdata=path.read_bytes(),
            serialization="file",
            stamp_ns=int(self._stamps[stream][i]),
            log_time_ns=int(self._stamps[stream][i]),
            width=info.width,
            height=info.height,
            suffix=path.suffix.lower(),
        )


def _recordings_in(folder: Path) -> list[Path]:
    """The recording files directly in ``folder`` (a session's folder given instead of
    its bag), then its ROS2 bag folders (with their ``metadata.yaml``), in name order."""
    from speechcal_core.sources import VIDEO_SUFFIXES

    kinds = {".bag", ".mcap", ".db3", *VIDEO_SUFFIXES}
    items = sorted(folder.iterdir())
    return [p for p in items if p.is_file() and p.suffix.lower() in kinds] + \
        [p for p in items if p.is_dir() and (p / "metadata.yaml").is_file()]
