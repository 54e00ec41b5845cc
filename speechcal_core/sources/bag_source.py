"""A ``FrameSource`` over one or more bag files, merging topics of the same name."""

from __future__ import annotations

import threading
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.sources import index_cache
from speechcal_core.sources.base import (
    COMPRESSED_MSGTYPE,
    ClosingContext,
    RawFrame,
    StreamInfo,
    stream_order,
)
from speechcal_core.sources.decode import (
    compressed_kind,
    decode_compressed,
    decode_raw,
    is_supported,
    raw_size_problem,
)
from speechcal_core.sources.errors import BadFrameError, SourceError
from speechcal_core.sources.msgparse import ImageMsg, parse_image
from speechcal_core.sources.stats import nearest_index, stamp_stats

if TYPE_CHECKING:
    from collections.abc import Sequence

    from speechcal_core.sources.base import FrameSource
    from speechcal_core.sources.scan import FileScan, MessageFile, TopicScan

_MAX_VERIFY = 2000


#: words of a scan's notes saying the file is cut short or damaged
BROKEN_WORDS = ("truncated", "cut off", "damaged", "end early")


@dataclass
class _Stream:
    info: StreamInfo
    compressed: bool
    serialization: str
    connection: dict[str, str]
    stamps: np.ndarray
    log_times: np.ndarray
    files: np.ndarray
    offsets: np.ndarray
    chunks: np.ndarray
    sizes: np.ndarray


def fill_meta(t: TopicScan, f: MessageFile) -> None:
    """Encoding and resolution of a topic from its first readable message."""
    compressed = t.msgtype == COMPRESSED_MSGTYPE
    cdr = t.serialization == "cdr"
    for k in range(min(len(t.stamps), 5)):
        off, chunk, size = int(t.offsets[k]), int(t.chunks[k]), int(t.sizes[k])
        try:
            if not compressed:
                msg = parse_image(f.head(off, chunk, min(size, 4096)), cdr, False, header_only=True)
                t.encoding, t.width, t.height = msg.encoding, msg.width, msg.height
                return
            msg = parse_image(f.read(off, chunk, size), cdr, True)
            img = decode_compressed(msg.data)
            t.encoding = compressed_kind(msg.encoding, msg.data)
            t.height, t.width = img.shape[:2]
            return
        except BadFrameError:
            continue


def same_frames_notes(stamps: dict[str, np.ndarray]) -> list[str]:
    """Notes on a topic under another (``image_raw/compressed`` under ``image_raw``) whose
    header stamps match its own one for one: one camera recorded twice, taken as two
    cameras. (Hardware-triggered cameras share stamps too, under names of their own.)"""
    notes = []
    for a in stamps:
        for b in stamps:
            if (b.startswith(a.rstrip("/") + "/") and stamps[a].size
                    and np.array_equal(stamps[a], stamps[b])):
                notes.append(
                    f"{b} has the same header stamps as {a}, frame for frame: one camera "
                    "recorded twice (raw and compressed?) is taken as two cameras in one "
                    "place; a calibration of both fails or is meaningless: leave one out "
                    f"(speechcal process or review ... --skip-stream {b}, or the review "
                    "window's Edit ▸ Leave a camera out…)")
    return notes


def twin_notes(source: FrameSource, streams: Sequence[str] | None = None) -> list[str]:
    """:func:`same_frames_notes` over ``streams`` of an opened ``source`` (default: all of
    them): said again wherever a session holding both twins is opened or exported."""
    names = [s.name for s in source.streams] if streams is None else list(streams)
    return same_frames_notes({name: source.stamps(name) for name in names})


class BagSource(ClosingContext):
    """Image topics of bag files (ROS1, ROS2 sqlite3, MCAP) keyed by header stamp."""

    def __init__(self, files: Sequence[MessageFile], *, use_cache: bool = True) -> None:
        self._files = list(files)
        self._lock = threading.Lock()
        self._bad: dict[str, set[int]] = {}
        self.notes: list[str] = []  # what was recovered or found damaged while indexing
        scans: list[FileScan] = []
        try:
            for f in self._files:
                scan = index_cache.load(f.path) if use_cache else None
                if scan is None:
                    scan = f.scan()
                    f.attach(scan)
                    for t in scan.topics:
                        fill_meta(t, f)
                    index_cache.save(f.path, scan)
                else:
                    f.attach(scan)
                scans.append(scan)
                self.notes.extend(scan.notes)
            self._streams = self._merge(scans)
            empty = sorted({t for s in scans for t in s.empty_topics} - set(self._streams),
                           key=stream_order)
            self.notes.extend(f"{t}: an image topic without any message (its camera sent no "
                              "frame while recording): left out" for t in empty)
            self.notes.extend(same_frames_notes({t: s.stamps for t, s in self._streams.items()}))
        except BaseException:
            self.close()
            raise
        if not self._streams:
            names = ", ".join(str(f.path) for f in self._files)
            others = sorted({o for s in scans for o in s.other_topics})
            found = f" (found: {', '.join(others[:8])})" if others else ""
            broken = [n for n in self.notes if any(w in n for w in BROKEN_WORDS)]
            self.close()
            if empty and not broken:
                raise SourceError(f"{names}: its image topics hold no message "
                                  f"({', '.join(empty)}): the cameras sent no frame while "
                                  "recording; check them and record again")
            if broken and not others:  # cut off before its first image, not a camera-less bag
                raise SourceError(f"{names}: no image message could be read ("
                                  f"{'; '.join(broken)}); copy the recording again where "
                                  "it is whole")
            raise SourceError(
                f"{names}: no sensor_msgs/Image or CompressedImage topics{found}; "
                "record the camera image topics"
            )

    # -- building ------------------------------------------------------------------------

    def _refuse_copies(self, topic: str, parts: list[tuple[int, TopicScan]]) -> None:
        """Two files holding the same stamps of a topic are one recording given twice (a
        backup beside it, caught by ``*.bag``): its frames would all count double."""
        for k, (fa, a) in enumerate(parts):
            for fb, b in parts[k + 1:]:
                if a.stamps.size and np.array_equal(a.stamps, b.stamps):
                    raise SourceError(
                        f"{self._files[fb].path}: holds the same {topic} frames as "
                        f"{self._files[fa].path} (a copy of it?); give only one of them")

    def _merge(self, scans: list[FileScan]) -> dict[str, _Stream]:
        by_topic: dict[str, list[tuple[int, TopicScan]]] = {}
        for fi, scan in enumerate(scans):
            for t in scan.topics:
                by_topic.setdefault(t.topic, []).append((fi, t))
        streams: dict[str, _Stream] = {}
        for topic in sorted(by_topic, key=stream_order):
            parts = by_topic[topic]
            first = next((t for _, t in parts if t.encoding), parts[0][1])

            def cat(name: str, parts: list[tuple[int, TopicScan]] = parts) -> np.ndarray:
                return np.concatenate([getattr(t, name) for _, t in parts])

            self._refuse_copies(topic, parts)
            files = np.concatenate([np.full(len(t.stamps), fi, np.int32) for fi, t in parts])
            st = stamp_stats([t.stamps for _, t in parts], unset_out=True)
            o = st.order
            s = _Stream(
                info=StreamInfo(
                    name=topic,
                    msgtype=first.msgtype,
                    encoding=first.encoding,
                    width=first.width,
                    height=first.height,
                    count=int(st.stamps.size),
                    first_ns=int(st.stamps[0]) if st.stamps.size else 0,
                    last_ns=int(st.stamps[-1]) if st.stamps.size else 0,
                    median_period_ns=st.median_period_ns,
                    nominal_rate_hz=st.nominal_rate_hz,
                    dropped=st.dropped,
                    stamp_problems=st.problems,
                ),
                compressed=first.msgtype == COMPRESSED_MSGTYPE,
                serialization=first.serialization,
                connection=dict(first.connection),
                stamps=st.stamps,
                log_times=cat("log_times")[o],
                files=files[o],
                offsets=cat("offsets")[o],
                chunks=cat("chunks")[o],
                sizes=cat("sizes")[o],
            )
            self._bad[topic] = self._wrong_size_frames(s)
            streams[topic] = s
        return streams

    def _wrong_size_frames(self, s: _Stream) -> set[int]:
        """Raw frames whose message size differs from the usual one and cannot hold the image."""
        if s.compressed or s.sizes.size == 0:
            return set()
        values, counts = np.unique(s.sizes, return_counts=True)
        usual = values[np.argmax(counts)]
        candidates = np.flatnonzero(s.sizes != usual)[:_MAX_VERIFY]
        usual_first = np.flatnonzero(s.sizes == usual)[:1]
        bad: set[int] = set()
        cdr = s.serialization == "cdr"
        for i in (int(k) for k in np.concatenate([usual_first, candidates])):
            # the message head says how long the payload is: no need to read the pixels
            f = self._files[int(s.files[i])]
            size = int(s.sizes[i])
            try:
                head = f.head(int(s.offsets[i]), int(s.chunks[i]), min(size, 4096))
                msg = parse_image(head, cdr, False, header_only=True)
            except BadFrameError:
                bad.add(i)
                continue
            available = min(msg.data_len, size - msg.data_offset)
            if raw_size_problem(available, msg.encoding, msg.width, msg.height, msg.step):
                bad.add(i)
        return bad

    # -- FrameSource ---------------------------------------------------------------------

    @property
    def streams(self) -> list[StreamInfo]:
        """One entry per image topic, in name order (``stream_order``)."""
        with self._lock:
            return [
                replace(s.info, bad_frames=tuple(sorted(self._bad.get(name, ()))))
                for name, s in self._streams.items()
            ]

    def _stream(self, stream: str) -> _Stream:
        try:
            return self._streams[stream]
        except KeyError:
            known = ", ".join(self._streams)
            msg = f"no stream {stream!r} in this recording (streams: {known})"
            raise SourceError(msg) from None

    def stamps(self, stream: str) -> np.ndarray:
        """Sorted int64 header stamps."""
        return self._stream(stream).stamps

    def nearest(self, stream: str, t_ns: int) -> int:
        """Index of the nearest header stamp."""
        return nearest_index(self._stream(stream).stamps, t_ns)

    def _read(self, s: _Stream, i: int) -> bytes:
        if not 0 <= i < s.stamps.size:
            raise IndexError(f"{s.info.name}: frame {i} out of range 0..{s.stamps.size - 1}")
        f = self._files[int(s.files[i])]
        return f.read(int(s.offsets[i]), int(s.chunks[i]), int(s.sizes[i]))

    def _message(self, s: _Stream, i: int) -> ImageMsg:
        return parse_image(self._read(s, i), s.serialization == "cdr", s.compressed)

    def _where(self, s: _Stream, i: int) -> str:
        name = self._files[int(s.files[i])].path.name
        return f"{name}: {s.info.name} frame {i} (stamp {int(s.stamps[i])})"

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded frame i; ``BadFrameError`` (and the frame marked bad) if it is damaged."""
        s = self._stream(stream)
        try:
            msg = self._message(s, i)
            if s.compressed:
                return decode_compressed(msg.data)
            return decode_raw(
                msg.data, msg.encoding, msg.width, msg.height, msg.step, msg.is_bigendian
            )
        except BadFrameError as exc:
            with self._lock:
                self._bad.setdefault(stream, set()).add(i)
            raise BadFrameError(f"{self._where(s, i)}: {exc}; frame marked bad") from None
        except SourceError as exc:
            hint = "" if s.compressed or is_supported(s.info.encoding) else (
                "; no camera's frames are stored so (a depth or disparity topic?): leave "
                f"the stream out with --skip-stream {stream} (speechcal process or review), "
                "or name the cameras with --stream")
            raise SourceError(f"{self._where(s, i)}: {exc}{hint}") from None

    def raw(self, stream: str, i: int) -> RawFrame:
        """The serialized message, as stored, with its connection details."""
        s = self._stream(stream)
        return RawFrame(
            stream=stream,
            msgtype=s.info.msgtype,
            rawdata=self._read(s, i),
            serialization=s.serialization,
            stamp_ns=int(s.stamps[i]),
            log_time_ns=int(s.log_times[i]),
            width=s.info.width,
            height=s.info.height,
            connection=dict(s.connection),
        )

    def close(self) -> None:
        """Close every file."""
        for f in self._files:
            f.close()
