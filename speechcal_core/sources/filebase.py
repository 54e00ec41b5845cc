"""Positional reads, chunk decompression and a small decompressed-chunk cache for bag files."""

from __future__ import annotations

import bz2
import os
import threading
from collections import OrderedDict
from pathlib import Path
from typing import Any

from speechcal_core.sources.errors import SourceError
from speechcal_core.sources.scan import FileScan


def _lz4(data: bytes, size: int) -> bytes:
    import lz4.frame

    return bytes(lz4.frame.decompress(data))


def _zstd_module() -> Any:
    try:
        from compression import zstd  # type: ignore[import-not-found]
    except ImportError:
        from backports import zstd  # type: ignore[no-redef]
    return zstd


def _zstd(data: bytes, size: int) -> bytes:
    return bytes(_zstd_module().decompress(data))


def _bz2(data: bytes, size: int) -> bytes:
    return bz2.decompress(data)


_HAS_PREAD = hasattr(os, "pread")  # not on Windows
#: compressions that ``StreamedChunk`` can decompress piece by piece
STREAMED = ("lz4", "bz2", "zstd")
DECOMPRESSORS = {"bz2": _bz2, "lz4": _lz4, "zstd": _zstd}


def decompress(name: str, compression: str, data: bytes, size: int) -> bytes:
    """Decompress one chunk; ``SourceError`` naming the file when it is damaged."""
    if compression not in DECOMPRESSORS:
        raise SourceError(f"{name}: unsupported chunk compression {compression!r}")
    try:
        out = DECOMPRESSORS[compression](data, size)
    except Exception as exc:  # each codec has its own error type
        raise SourceError(f"{name}: a {compression} chunk is damaged ({exc})") from None
    if size and len(out) != size:
        raise SourceError(f"{name}: a {compression} chunk has {len(out)} bytes, expected {size}")
    return out


class PFile:
    """A file read by position (``os.pread``), with a lock and an LRU of decompressed chunks."""

    def __init__(self, path: Path, *, chunk_cache: int = 3) -> None:
        self.path = Path(path)
        self.name = self.path.name
        try:
            self.fd = os.open(self.path, os.O_RDONLY | getattr(os, "O_BINARY", 0))
        except FileNotFoundError:
            raise SourceError(f"{self.path}: file not found; check the path") from None
        except OSError as exc:
            raise SourceError(f"{self.path}: cannot open ({exc.strerror})") from None
        self.size = os.fstat(self.fd).st_size
        self.lock = threading.RLock()
        self._seek_lock = threading.Lock()
        self._chunks: OrderedDict[int, bytes] = OrderedDict()
        self._chunk_cache = chunk_cache
        self.scan_result: FileScan | None = None

    def advise_random(self) -> None:
        """Tell the kernel not to read ahead: the index reads a few bytes here and there."""
        if hasattr(os, "posix_fadvise"):
            os.posix_fadvise(self.fd, 0, 0, os.POSIX_FADV_RANDOM)

    def advise_normal(self) -> None:
        """Back to default read-ahead for frame reads."""
        if hasattr(os, "posix_fadvise"):
            os.posix_fadvise(self.fd, 0, 0, os.POSIX_FADV_NORMAL)

    def will_need(self, pos: int, n: int) -> None:
        """Start reading a range in the background (next compressed chunk while decoding)."""
        if hasattr(os, "posix_fadvise") and n > 0:
            os.posix_fadvise(self.fd, pos, n, os.POSIX_FADV_WILLNEED)

    def raw_pread(self, pos: int, n: int) -> bytes:
        """Up to n bytes at pos (``os.pread``; seek + read under a lock where it is missing)."""
        if _HAS_PREAD:
            return os.pread(self.fd, n, pos)
        with self._seek_lock:
            os.lseek(self.fd, pos, os.SEEK_SET)
            return os.read(self.fd, n)

    def pread(self, pos: int, n: int) -> bytes:
        """Exactly n bytes at pos, or ``SourceError`` when the file ends first."""
        data = self.raw_pread(pos, n)
        if len(data) != n:
            raise SourceError(
                f"{self.path}: file ends at byte {self.size} inside a record at {pos}; "
                "it is truncated"
            )
        return data

    def chunk(self, key: int) -> bytes:
        """Decompressed chunk ``key`` of the attached index (cached)."""
        data = self._chunks.get(key)
        if data is not None:
            self._chunks.move_to_end(key)
            return data
        assert self.scan_result is not None
        start, length, usize = self.scan_result.chunk_rows[key]
        comp = self.scan_result.chunk_compression[key]
        data = decompress(self.name, comp, self.pread(start, length), usize)
        self._chunks[key] = data
        while len(self._chunks) > self._chunk_cache:
            self._chunks.popitem(last=False)
        return data

    def read(self, offset: int, chunk: int, size: int) -> bytes:
        """Message bytes at a location: direct (chunk -1) or inside a compressed chunk."""
        with self.lock:
            if chunk < 0:
                return self.pread(offset, size)
            data = self.chunk(chunk)
            if offset + size > len(data):
                raise SourceError(f"{self.path}: message runs past its chunk; file is damaged")
            return data[offset : offset + size]

    def head(self, offset: int, chunk: int, n: int) -> bytes:
        """The first n bytes of a message; a compressed chunk is decompressed only that far."""
        with self.lock:
            if chunk >= 0 and chunk not in self._chunks and self.scan_result is not None:
                comp = self.scan_result.chunk_compression[chunk]
                if comp in STREAMED:
                    start, length, _ = self.scan_result.chunk_rows[chunk]
                    data = StreamedChunk(self, comp, start, length).get(offset, n)
                    if data is None:
                        raise SourceError(f"{self.path}: message runs past its chunk; damaged")
                    return data
        return self.read(offset, chunk, n)

    def attach(self, scan: FileScan) -> None:
        """Use this index for reads."""
        self.scan_result = scan

    def close(self) -> None:
        """Close the descriptor."""
        with self.lock:
            if self.fd >= 0:
                os.close(self.fd)
                self.fd = -1
            self._chunks.clear()


class Window:
    """Small buffered reads at increasing positions: one syscall per record header."""

    def __init__(self, f: PFile, block: int = 4096) -> None:
        self.f = f
        self.block = block
        self.start = 0
        self.buf = b""

    def get(self, pos: int, n: int) -> bytes | None:
        """n bytes at pos, or None when the file ends first."""
        off = pos - self.start
        if off < 0 or off + n > len(self.buf):
            self.start = pos
            self.buf = self.f.raw_pread(pos, max(n, self.block))
            off = 0
            if len(self.buf) < n:
                return None
        return self.buf[off : off + n]


class StreamedChunk:
    """The decompressed bytes of a chunk, produced only as far as they are asked for.

    Indexing a compressed chunk needs just the record heads; when a chunk holds one big
    image, only its first compressed block is read from disk and decompressed.
    """

    def __init__(self, f: PFile, compression: str, start: int, length: int, piece: int = 16384):
        import lz4.frame

        self.f = f
        self.compression = compression
        self.pos = start
        self.end = start + length
        self.piece = piece
        self.buf = bytearray()
        self.dec: Any
        if compression == "lz4":
            self.dec = lz4.frame.LZ4FrameDecompressor()
        elif compression == "bz2":
            self.dec = bz2.BZ2Decompressor()
        elif compression == "zstd":
            self.dec = _zstd_module().ZstdDecompressor()
        else:
            raise SourceError(f"{f.name}: unsupported chunk compression {compression!r}")

    def get(self, pos: int, n: int) -> bytes | None:
        """n decompressed bytes at pos, or None past the end of the chunk."""
        while len(self.buf) < pos + n:
            if self.pos >= self.end:
                return None
            k = min(self.piece, self.end - self.pos)
            data = self.f.pread(self.pos, k)
            self.pos += k
            self.piece = min(self.piece * 2, 1 << 20)
            try:
                self.buf += self.dec.decompress(data)
            except Exception as exc:  # each codec has its own error type
                msg = f"{self.f.name}: a {self.compression} chunk is damaged ({exc})"
                raise SourceError(msg) from None
        return bytes(self.buf[pos : pos + n])


class IndexedFile:
    """Message reads through a :class:`PFile` once an index is attached (ROS1 and MCAP)."""

    f: PFile

    def attach(self, scan: FileScan) -> None:
        """Use an index for reads."""
        self.f.attach(scan)

    def read(self, offset: int, chunk: int, size: int) -> bytes:
        """Message bytes at a location from the index."""
        return self.f.read(offset, chunk, size)

    def head(self, offset: int, chunk: int, n: int) -> bytes:
        """The first n bytes of a message."""
        return self.f.head(offset, chunk, n)

    def close(self) -> None:
        """Close the file."""
        self.f.close()
