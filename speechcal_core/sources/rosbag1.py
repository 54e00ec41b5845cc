"""ROS1 bags (v2.0, none/bz2/lz4 chunks): index header stamps reading only record headers."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.fsutil import shell_quoted
from speechcal_core.sources.errors import SourceError
from speechcal_core.sources.filebase import (
    STREAMED,
    IndexedFile,
    PFile,
    StreamedChunk,
    Window,
    decompress,
)
from speechcal_core.sources.msgparse import STAMP_PREFIX, stamp_ros1
from speechcal_core.sources.scan import FileScan, TopicCollector, TopicScan, image_msgtype
from speechcal_core.sources.sniff import looks_like

if TYPE_CHECKING:
    from collections.abc import Callable

MAGIC = b"#ROSBAG V2.0\n"
OP_MSG, OP_BAGHEADER, OP_INDEX, OP_CHUNK, OP_CHUNKINFO, OP_CONN = 2, 3, 4, 5, 6, 7
_U32 = struct.Struct("<I")
_U64 = struct.Struct("<Q")
_TIME = struct.Struct("<II")


def parse_fields(buf: bytes | memoryview) -> dict[str, bytes]:
    """A ROS1 record header (or connection data): ``len name=value`` fields."""
    fields: dict[str, bytes] = {}
    pos, end = 0, len(buf)
    while pos + 4 <= end:
        (n,) = _U32.unpack_from(buf, pos)
        pos += 4
        if n > end - pos:
            raise ValueError("field runs past the header")
        item = bytes(buf[pos : pos + n])
        pos += n
        name, sep, value = item.partition(b"=")
        if sep:
            fields[name.decode("ascii", "replace")] = value
    return fields


def _u32(fields: dict[str, bytes], key: str) -> int:
    return _U32.unpack(fields[key][:4])[0]


def _time(value: bytes) -> int:
    sec, nsec = _TIME.unpack(value[:8])
    return sec * 1_000_000_000 + nsec


class _Reader:
    """Reads records from the file (``Window``) or from a decompressed chunk (bytes)."""

    def __init__(self, get: Callable[[int, int], bytes | None]) -> None:
        self.get = get

    def record(self, pos: int) -> tuple[dict[str, bytes], int, int] | None:
        """(header fields, data position, data length) of the record at pos, None if cut."""
        head = self.get(pos, 4)
        if head is None:
            return None
        (hlen,) = _U32.unpack(head)
        if hlen > 1 << 24:
            raise ValueError(f"implausible record header length {hlen} at byte {pos}")
        raw = self.get(pos + 4, hlen + 4)
        if raw is None:
            return None
        fields = parse_fields(raw[:hlen])
        (dlen,) = _U32.unpack_from(raw, hlen)
        return fields, pos + 8 + hlen, dlen


class Ros1Bag(IndexedFile):
    """One ROS1 bag file; ``scan`` indexes its image topics, ``read`` fetches a message."""

    def __init__(self, path: Path, *, scan: bool = False) -> None:
        self.path = Path(path)
        self.allow_scan = scan
        self.f = PFile(self.path)
        self.name = self.f.name
        try:
            head = self.f.pread(0, len(MAGIC))
        except SourceError:
            head = b""
        if head != MAGIC:
            self.f.close()
            seen = looks_like(self.path)
            raise SourceError(
                f"{self.path}: not a ROS1 bag ("
                + (f"the file is {seen}" if seen else "it does not start as a v2.0 bag does")
                + "); give the recording's .bag file")
        rec = _Reader(Window(self.f).get).record(len(MAGIC))
        if rec is None or rec[0].get("op") != bytes([OP_BAGHEADER]):
            self.f.close()
            raise SourceError(f"{self.path}: ROS1 bag header is damaged")
        fields, dpos, dlen = rec
        self.index_pos = _U64.unpack(fields["index_pos"][:8])[0]
        # a bag closed without any message (no camera published) has none of either, and
        # its (empty) index section starts at the file's end
        self.empty = all(len(fields.get(k, b"")) >= 4 and _u32(fields, k) == 0
                         for k in ("conn_count", "chunk_count"))
        self.first_record = dpos + dlen
        self.conns: dict[int, dict[str, str]] = {}
        self.chunk_infos: list[tuple[int, set[int], int]] = []  # position, conns, messages

    # -- reading -----------------------------------------------------------------------

    def attach(self, scan: FileScan) -> None:
        """Use an index for reads."""
        super().attach(scan)
        self.f.advise_normal()

    # -- indexing ----------------------------------------------------------------------

    def _unindexed(self, why: str) -> SourceError:
        return SourceError(
            f"{self.path}: ROS1 bag is not indexed ({why}; recording was interrupted); "
            f"run `rosbag reindex {shell_quoted(self.path)}`, or "
            f"`speechcal index {shell_quoted(self.path)} --scan` "
            f"(the other commands then use the recovered index)"
        )

    def _add_conn(self, cid: int, data: bytes | memoryview, topic: str) -> None:
        f = parse_fields(data)
        self.conns[cid] = {
            "topic": f.get("topic", topic.encode()).decode(),
            "source_msgtype": f.get("type", b"").decode(),
            "md5sum": f.get("md5sum", b"").decode(),
            "msgdef": f.get("message_definition", b"").decode("utf-8", "replace"),
            "callerid": f.get("callerid", b"").decode(),
            "latching": f.get("latching", b"0").decode() or "0",
        }

    def _read_index_section(self) -> bool:
        """Connections and chunk infos from the index at the end; False if unusable."""
        if self.empty and self.index_pos == self.f.size >= self.first_record:
            return True  # whole, and nothing in it
        if self.index_pos < self.first_record or self.index_pos >= self.f.size:
            return False
        reader = _Reader(Window(self.f, 65536).get)
        pos = self.index_pos
        try:
            while pos < self.f.size:
                rec = reader.record(pos)
                if rec is None:
                    return False
                fields, dpos, dlen = rec
                op = fields.get("op", b"\0")[0]
                if op == OP_CONN:
                    data = self.f.pread(dpos, dlen)
                    self._add_conn(_u32(fields, "conn"), data, fields.get("topic", b"").decode())
                elif op == OP_CHUNKINFO:
                    data = self.f.pread(dpos, dlen)
                    pairs = [_U32.unpack_from(data, k)[0] for k in range(0, len(data) - 3, 4)]
                    ids, total = set(pairs[0::2]), sum(pairs[1::2])
                    self.chunk_infos.append((_U64.unpack(fields["chunk_pos"][:8])[0], ids, total))
                pos = dpos + dlen
        except (ValueError, KeyError, struct.error, SourceError):
            return False
        return bool(self.conns) or not self.chunk_infos

    def scan(self) -> FileScan:
        """Index the image topics; unindexed bags need ``scan=True``."""
        self.f.advise_random()
        result = FileScan(topics=[])
        collectors: dict[int, TopicCollector] = {}
        indexed = self._read_index_section()
        try:
            if indexed:
                self._make_collectors(collectors)
                wanted = set(collectors)
                infos = sorted(self.chunk_infos)
                todo = [(pos, total) for pos, ids, total in infos if ids & wanted]
                self._walk_chunks(todo, collectors, result)
            else:
                why = "no index section" if self.index_pos == 0 else "index section missing"
                if not self.allow_scan:
                    raise self._unindexed(why)
                self._scan_all(collectors, result)
                result.notes.append(f"{self.name}: {why}; recovered by scanning the chunks")
        finally:
            self.f.advise_normal()
        result.other_topics = sorted(
            f"{c['topic']} [{c['source_msgtype']}]"
            for c in self.conns.values()
            if image_msgtype(c["source_msgtype"]) is None
        )
        result.topics = [c.finish() for c in collectors.values() if c.rows]
        result.empty_topics = [c.scan.topic for c in collectors.values() if not c.rows]
        return result

    def _walk_chunks(
        self, todo: list[tuple[int, int]], collectors: dict[int, TopicCollector], result: FileScan
    ) -> None:
        """Index the listed (chunk position, message count) in file order.

        One after another: threads did not help here (bz2 is CPU-bound on a shared machine,
        and uncompressed chunks need only a few small reads each).
        """
        for chunk_pos, total in todo:
            try:
                self._walk_chunk(chunk_pos, collectors, result, learn=False, total=total)
            except SourceError:
                if not self.allow_scan:
                    raise
                # recovering (--scan): the index still finds every other chunk
                lost = "its message is" if total == 1 else f"its {total} messages are"
                result.notes.append(f"{self.path}: chunk at byte {chunk_pos} is damaged; "
                                    f"{lost} skipped")

    def _make_collectors(self, collectors: dict[int, TopicCollector]) -> None:
        for cid, conn in self.conns.items():
            if cid in collectors:
                continue
            msgtype = image_msgtype(conn["source_msgtype"])
            if msgtype is not None:
                collectors[cid] = TopicCollector(
                    TopicScan(conn["topic"], msgtype, "ros1", dict(conn))
                )

    def _scan_all(self, collectors: dict[int, TopicCollector], result: FileScan) -> None:
        reader = _Reader(Window(self.f).get)
        pos = self.first_record
        if pos >= self.f.size:
            result.notes.append(f"{self.name}: the file ends at byte {self.f.size}, before "
                                "its first record (truncated)")
        while pos < self.f.size:
            try:
                rec = reader.record(pos)
            except (ValueError, struct.error):
                rec = None
            if rec is None:
                result.notes.append(f"{self.name}: records end early at byte {pos} (truncated)")
                return
            fields, dpos, dlen = rec
            op = fields.get("op", b"\0")[0]
            if op == OP_CHUNK:
                self._walk_chunk(pos, collectors, result, learn=True)
            elif op == OP_CONN and dpos + dlen <= self.f.size:
                cid = _u32(fields, "conn")
                self._add_conn(cid, self.f.pread(dpos, dlen), fields.get("topic", b"").decode())
                self._make_collectors(collectors)
            pos = dpos + dlen

    def _walk_chunk(
        self,
        chunk_pos: int,
        collectors: dict[int, TopicCollector],
        result: FileScan,
        *,
        learn: bool,
        total: int = -1,
    ) -> None:
        """Index one chunk; with ``total`` (messages in it) a compressed chunk is decompressed
        only up to its last message head."""
        window = Window(self.f)
        try:
            rec = _Reader(window.get).record(chunk_pos)
        except (ValueError, struct.error):
            rec = None
        if rec is None or rec[0].get("op") != bytes([OP_CHUNK]):
            raise SourceError(
                f"{self.path}: chunk at byte {chunk_pos} is damaged; "
                f"run `rosbag reindex {shell_quoted(self.path)}`, or "
            f"`speechcal index {shell_quoted(self.path)} --scan` "
                f"(the other commands then use the recovered index)"
            )
        fields, dpos, dlen = rec
        compression = fields.get("compression", b"none").decode()
        usize = _u32(fields, "size")
        truncated = dpos + dlen > self.f.size
        if compression == "none":
            end = min(dpos + dlen, self.f.size)
            seen = self._walk_records(_Reader(window.get), dpos, end, -1, collectors, learn, total)
            if truncated:
                result.notes.append(f"{self.name}: last chunk is cut off at byte "
                                    f"{self.f.size} (truncated); its complete messages are read")
        elif truncated:
            result.notes.append(f"{self.name}: last {compression} chunk is cut off; skipped")
            return
        else:
            key = len(result.chunk_compression)
            result.chunk_compression.append(compression)
            result.chunk_rows.append((dpos, dlen, usize))
            if total >= 0 and compression in STREAMED:
                reader = _Reader(StreamedChunk(self.f, compression, dpos, dlen).get)
            else:
                data = decompress(self.name, compression, self.f.pread(dpos, dlen), usize)
                mem = memoryview(data)

                def get(pos: int, n: int) -> bytes | None:
                    return bytes(mem[pos : pos + n]) if pos + n <= len(mem) else None

                reader = _Reader(get)
            seen = self._walk_records(reader, 0, usize, key, collectors, learn, total)
        if total >= 0 and seen < total:
            result.notes.append(
                f"{self.path}: chunk at byte {chunk_pos} is damaged; "
                f"{total - seen} of its {total} messages are unreadable"
            )

    def _walk_records(
        self,
        reader: _Reader,
        start: int,
        end: int,
        chunk: int,
        collectors: dict[int, TopicCollector],
        learn: bool,
        limit: int = -1,
    ) -> int:
        """Index the message records in [start, end); returns how many were read whole."""
        pos = start
        seen = 0
        while pos < end and seen != limit:
            try:
                rec = reader.record(pos)
                if rec is None:
                    return seen
                fields, dpos, dlen = rec
                op = fields.get("op", b"\0")[0]
                if op == OP_MSG:
                    col = collectors.get(_u32(fields, "conn"))
                    if dpos + dlen > end:
                        return seen  # cut off by truncation
                    if col is not None:
                        head = reader.get(dpos, STAMP_PREFIX) if dlen >= STAMP_PREFIX else None
                        if head is None:
                            return seen
                        col.add(stamp_ros1(head), _time(fields["time"]), dpos, chunk, dlen)
                    seen += 1
                elif op == OP_CONN and learn:
                    cid = _u32(fields, "conn")
                    if cid not in self.conns:
                        data = reader.get(dpos, dlen)
                        if data is None:
                            return seen
                        self._add_conn(cid, data, fields.get("topic", b"").decode())
                        self._make_collectors(collectors)
            except (ValueError, KeyError, struct.error):
                return seen
            pos = dpos + dlen
        return seen
