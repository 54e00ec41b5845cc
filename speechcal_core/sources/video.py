"""Video files (mp4/mkv/avi...): per-frame container timestamps plus a start stamp."""

from __future__ import annotations

import os
import threading
from pathlib import Path

import cv2
import numpy as np

from speechcal_core.errors import UsageError
from speechcal_core.sources import index_cache
from speechcal_core.sources.base import RawFrame, StreamInfo
from speechcal_core.sources.common import StreamTable
from speechcal_core.sources.errors import BadFrameError, SourceError
from speechcal_core.sources.scan import FileScan, TopicScan
from speechcal_core.sources.stats import MAX_STAMP_NS, STAMP_FORM, UNSET_STAMPS, stamp_stats

# FFmpeg writes its own lines ("moov atom not found") to stderr beside the one-line
# reason SpeechCal gives for a bad video; quiet unless the user set a level (read when
# the first capture opens)
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")


def start_stamp(path: Path, start_ns: int | None) -> tuple[int, str]:
    """The header stamp of the first frame and, when it is a guess, a note saying so.

    Explicit ``start_ns`` first, then ``<video>.start_ns`` (one integer) beside the video,
    then an integer file name (``1700000000000000000.mp4``), else 0.
    """
    if start_ns is not None:
        if abs(start_ns) >= MAX_STAMP_NS:
            raise UsageError(f"--video-start-ns {start_ns}: {_NO_STAMP}")
        return int(start_ns), ""
    sidecar = path.with_name(path.name + ".start_ns")
    if sidecar.is_file():
        text = sidecar.read_text().strip()
        try:
            start = int(text)
        except ValueError:
            msg = f"{sidecar}: expected one integer (ns), found {text[:40]!r}"
            raise SourceError(msg) from None
        if abs(start) >= MAX_STAMP_NS:
            raise SourceError(f"{sidecar}: {text[:40]} is {_NO_STAMP}")
        return start, ""
    if path.stem.isdigit() and int(path.stem) < MAX_STAMP_NS:
        return int(path.stem), ""
    return 0, f"no start stamp (write it to {sidecar.name}); stamps start at 0"


_NO_STAMP = f"no header stamp: give the first frame's time in {STAMP_FORM}"


class VideoSource(StreamTable):
    """One video file as one stream named after the file (``cam0.mp4`` -> ``cam0``)."""

    def __init__(self, path: Path, *, start_ns: int | None = None, use_cache: bool = True) -> None:
        super().__init__()
        self.path = Path(path)
        self.name = self.path.stem
        self._lock = threading.Lock()
        self._cap = cv2.VideoCapture(str(self.path))
        if not self._cap.isOpened():
            from speechcal_core.sources.sniff import looks_like

            seen = looks_like(self.path)
            raise SourceError(
                f"{self.path}: cannot open the video ("
                + (f"the file is {seen}" if seen else "unknown or damaged file")
                + "); copy it again where it is whole, or give the cameras' recording in "
                "another form (a bag, or a folder of <stamp_ns>.png images)")
        self._next = 0
        scan = index_cache.load(self.path) if use_cache else None
        if scan is None:
            scan = self._scan()
            index_cache.save(self.path, scan)
        (t,) = scan.topics
        self._fourcc = t.encoding
        self._start, note = start_stamp(self.path, start_ns)
        st = stamp_stats([t.stamps + self._start])
        # a video without its start stamp starts at 0: the note says so, in its own words
        told = [p for p in st.problems.split("; ") if p and not (note and p == UNSET_STAMPS)]
        problems = "; ".join(p for p in (*told, note, *scan.notes) if p)
        info = StreamInfo(
            name=self.name,
            msgtype="video",
            encoding=t.encoding,
            width=t.width,
            height=t.height,
            count=int(st.stamps.size),
            first_ns=int(st.stamps[0]),
            last_ns=int(st.stamps[-1]),
            median_period_ns=st.median_period_ns,
            nominal_rate_hz=st.nominal_rate_hz,
            dropped=st.dropped,
            stamp_problems=problems,
        )
        self._order = st.order
        self._add_stream(info, st.stamps)

    def _scan(self) -> FileScan:
        cap = self._cap
        fourcc = int(cap.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little")
        codec = fourcc.decode("ascii", "replace").strip("\0 ") or "video"
        width = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH))
        height = int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
        pts: list[int] = []
        while cap.grab():
            pts.append(round(cap.get(cv2.CAP_PROP_POS_MSEC) * 1e6))
        cap.set(cv2.CAP_PROP_POS_FRAMES, 0)
        self._next = 0
        if not pts:
            raise SourceError(f"{self.path}: the video has no readable frames")
        n = len(pts)
        stamps = np.array(pts, np.int64)
        t = TopicScan(
            self.name, "video", "", {"fourcc": codec}, codec, width, height,
            stamps, stamps.copy(), np.arange(n, dtype=np.int64),
            np.full(n, -1, np.int64), np.zeros(n, np.int64),
        )  # fmt: skip
        return FileScan(topics=[t])

    def _decode(self, stream: str, i: int) -> np.ndarray:
        self._check(stream, i)
        k = int(self._order[i])  # position in the file
        with self._lock:
            if k != self._next:
                self._cap.set(cv2.CAP_PROP_POS_FRAMES, k)
            ok, img = self._cap.read()
            self._next = k + 1 if ok else -1
        if not ok or img is None:
            self._mark_bad(stream, i)
            raise BadFrameError(f"{self.path.name}: frame {i} cannot be decoded; frame marked bad")
        return img

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded frame i as (H, W, 3) BGR uint8."""
        return self._decode(stream, i)

    def raw(self, stream: str, i: int) -> RawFrame:
        """The decoded pixels (a video frame has no lossless payload of its own)."""
        img = self._decode(stream, i)
        stamp = int(self._stamps[stream][i])
        return RawFrame(
            stream=stream,
            msgtype="video",
            rawdata=img.tobytes(),
            serialization="bgr8",
            stamp_ns=stamp,
            log_time_ns=stamp,
            width=img.shape[1],
            height=img.shape[0],
            connection={"fourcc": self._fourcc, "video": self.path.name},
        )

    def close(self) -> None:
        """Release the capture."""
        with self._lock:
            self._cap.release()
