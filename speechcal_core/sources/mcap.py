"""MCAP files (ROS2 profile, none/lz4/zstd chunks): index stamps reading only record heads."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

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
from speechcal_core.sources.msgparse import STAMP_PREFIX, stamp_cdr
from speechcal_core.sources.scan import FileScan, TopicCollector, TopicScan, image_msgtype
from speechcal_core.sources.sniff import looks_like

if TYPE_CHECKING:
    from collections.abc import Callable

MAGIC = b"\x89MCAP0\r\n"
OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK, OP_DATA_END, OP_FOOTER = 3, 4, 5, 6, 0x0F, 2
OP_MESSAGE_INDEX = 7
_OPLEN = struct.Struct("<BQ")
_MSG = struct.Struct("<HIQQ")
_U16 = struct.Struct("<H")
_U32 = struct.Struct("<I")
_CHUNK = struct.Struct("<QQQI")


class _Buf:
    """Cursor over one record's content."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0

    def u16(self) -> int:
        (v,) = _U16.unpack_from(self.data, self.pos)
        self.pos += 2
        return v

    def u32(self) -> int:
        (v,) = _U32.unpack_from(self.data, self.pos)
        self.pos += 4
        return v

    def string(self) -> str:
        n = self.u32()
        s = self.data[self.pos : self.pos + n].decode("utf-8", "replace")
        self.pos += n
        return s

    def strmap(self) -> dict[str, str]:
        end = self.pos + 4 + self.u32()
        out: dict[str, str] = {}
        while self.pos < end:
            key = self.string()
            out[key] = self.string()
        return out


class McapFile(IndexedFile):
    """One MCAP file; ``scan`` indexes its image channels, ``read`` fetches a message."""

    def __init__(self, path: Path, *, scan: bool = False) -> None:
        self.path = Path(path)
        self.allow_scan = scan
        self.f = PFile(self.path)
        self.name = self.f.name
        if self.f.size < 8 or self.f.pread(0, 8) != MAGIC:
            self.f.close()
            seen = looks_like(self.path)
            raise SourceError(
                f"{self.path}: not an MCAP file ("
                + (f"the file is {seen}" if seen else "it does not start as MCAP does")
                + "); give the recording's .mcap file")
        self.truncated = self.f.size < 16 or self.f.pread(self.f.size - 8, 8) != MAGIC
        self.schemas: dict[int, tuple[str, str]] = {}
        self.channels: dict[int, dict[str, str]] = {}


    def scan(self) -> FileScan:
        """Walk the data section, reading only record heads in uncompressed chunks.

        A truncated file is walked only when scanning was allowed; its index, once
        cached, then opens it without (as for an unindexed ROS1 bag).
        """
        if self.truncated and not self.allow_scan:
            raise SourceError(
                f"{self.path}: MCAP file is truncated (no footer; recording was interrupted); "
                f"run `speechcal index {shell_quoted(self.path)} --scan` to read the "
                f"complete chunks "
                f"(the other commands then use the recovered index), or "
                f"`mcap recover {shell_quoted(self.path)} -o fixed.mcap`"
            )
        self.f.advise_random()
        result = FileScan(topics=[])
        collectors: dict[int, TopicCollector] = {}
        try:
            self._walk(Window(self.f).get, 8, self.f.size, -1, collectors, result, top=True)
        finally:
            self.f.advise_normal()
        if self.truncated:
            result.notes.append(f"{self.name}: truncated; read the complete chunks only")
        result.other_topics = sorted(
            f"{c['topic']} [{c['source_msgtype']}]"
            for cid, c in self.channels.items()
            if cid not in collectors
        )
        result.topics = [c.finish() for c in collectors.values() if c.rows]
        result.empty_topics = [c.scan.topic for c in collectors.values() if not c.rows]
        return result

    def _channel(self, content: bytes, collectors: dict[int, TopicCollector]) -> None:
        b = _Buf(content)
        cid, sid = b.u16(), b.u16()
        topic, encoding = b.string(), b.string()
        meta = b.strmap()
        name, msgdef = self.schemas.get(sid, ("", ""))
        conn = {
            "topic": topic,
            "source_msgtype": name,
            "msgdef": msgdef,
            "offered_qos_profiles": meta.get("offered_qos_profiles", ""),
        }
        self.channels[cid] = conn
        kind = image_msgtype(name)
        if kind is not None and encoding == "cdr" and cid not in collectors:
            collectors[cid] = TopicCollector(TopicScan(topic, kind, "cdr", conn))

    def _walk(
        self,
        get: Callable[[int, int], bytes | None],
        pos: int,
        end: int,
        chunk: int,
        collectors: dict[int, TopicCollector],
        result: FileScan,
        *,
        top: bool,
        stop_after: int = -1,
    ) -> None:
        while pos + 9 <= end and (stop_after < 0 or pos <= stop_after):
            head = get(pos, 9 + 22 + STAMP_PREFIX) or get(pos, 9)
            if head is None:
                break
            op, length = _OPLEN.unpack_from(head)
            body = pos + 9
            if body + length > end:
                if top:
                    result.notes.append(f"{self.name}: last record cut off at byte {pos}")
                    if op == OP_CHUNK:  # complete messages of an uncompressed chunk survive
                        self._chunk(body, length, collectors, result)
                break
            if op == OP_MESSAGE:
                if len(head) >= 9 + 22 + STAMP_PREFIX and length >= 22 + STAMP_PREFIX:
                    cid, _seq, log_time, _pub = _MSG.unpack_from(head, 9)
                    col = collectors.get(cid)
                    if col is not None:
                        stamp = stamp_cdr(head[9 + 22 :])
                        col.add(stamp, log_time, body + 22, chunk, length - 22)
            elif op in (OP_SCHEMA, OP_CHANNEL):
                content = get(body, length)
                if content is None:
                    break
                b = _Buf(content)
                if op == OP_SCHEMA:
                    sid = b.u16()
                    name, _enc = b.string(), b.string()
                    self.schemas[sid] = (name, b.string())
                else:
                    self._channel(content, collectors)
            elif op == OP_CHUNK and top:
                self._chunk(body, length, collectors, result, self._last_offset(body + length))
            elif op in (OP_DATA_END, OP_FOOTER) and top:
                break
            pos = body + length

    def _last_offset(self, pos: int) -> int:
        """Offset of the chunk's last message, from the MessageIndex records after it (-1)."""
        last = -1
        try:
            while pos + 9 <= self.f.size:
                op, length = _OPLEN.unpack(self.f.pread(pos, 9))
                if op != OP_MESSAGE_INDEX:
                    break
                content = self.f.pread(pos + 9, length)
                (n,) = _U32.unpack_from(content, 2)
                offsets = np.frombuffer(content, "<u8", count=n // 8, offset=6)[1::2]
                if offsets.size:
                    last = max(last, int(offsets.max()))
                pos += 9 + length
        except (SourceError, ValueError, struct.error):
            return -1
        return last

    def _chunk(
        self,
        body: int,
        length: int,
        collectors: dict[int, TopicCollector],
        result: FileScan,
        last: int = -1,
    ) -> None:
        """Index one chunk; with ``last`` (its last message's offset) a compressed chunk is
        decompressed only up to that message's head."""
        try:
            head = self.f.pread(body, min(length, 28 + 4 + 64))
            _start, _end, usize, _crc = _CHUNK.unpack_from(head)
            (clen,) = _U32.unpack_from(head, 28)
            compression = head[32 : 32 + clen].decode()
            rstart = body + 32 + clen + 8
            (rlen,) = struct.unpack("<Q", self.f.pread(rstart - 8, 8))
        except (SourceError, struct.error):
            return  # chunk head cut off
        if compression == "":
            rend = min(rstart + rlen, self.f.size)
            self._walk(Window(self.f).get, rstart, rend, -1, collectors, result, top=False)
            return
        if rstart + rlen > self.f.size:
            return  # a cut-off compressed chunk cannot be read
        if last >= 0 and compression in STREAMED:
            key = len(result.chunk_compression)
            result.chunk_compression.append(compression)
            result.chunk_rows.append((rstart, rlen, usize))
            streamed = StreamedChunk(self.f, compression, rstart, rlen)
            self._walk(streamed.get, 0, usize, key, collectors, result, top=False, stop_after=last)
            return
        self.f.advise_normal()  # compressed chunks are read whole
        packed = self.f.pread(rstart, rlen)
        self.f.will_need(rstart + rlen, rlen + 4096)  # most likely the next chunk
        data = decompress(self.name, compression, packed, usize)
        key = len(result.chunk_compression)
        result.chunk_compression.append(compression)
        result.chunk_rows.append((rstart, rlen, usize))

        def get(pos: int, n: int) -> bytes | None:
            return data[pos : pos + n] if pos + n <= len(data) else None

        self._walk(get, 0, len(data), key, collectors, result, top=False)
