"""Chained Ogg files: whole Ogg streams one after another in one file.

A recorder that pauses and resumes, a stream dump, or ``cat a.ogg b.ogg > c.ogg`` writes
them, and the Ogg format allows it. libsndfile decodes only the first link and reports its
length as the file's, so the triggers said after the first link would be lost without a
word. :func:`open_ogg_chain` opens each link on its own (a view of its bytes) and reads
them back as one sound file, the links' samples end to end.
"""

from __future__ import annotations

import functools
import io
import os
import struct
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import soundfile as sf

from speechcal_core.audio.errors import AudioError

CAPTURE = b"OggS"
#: an Ogg page header: capture pattern, version, flags, granule position, serial, page
#: number, checksum, segment count; the segment table follows
PAGE_HEADER = struct.Struct("<4sBBqIIIB")
BEGINNING_OF_STREAM = 0x02
#: libsndfile's frame count for a length its header does not know
_UNKNOWN_FRAMES = 1 << 62


def ogg_links(path: str | Path) -> tuple[tuple[int, int], ...]:
    """Byte ranges ``(start, end)`` of the chain links of the Ogg file ``path``.

    A link starts where a stream begins (a beginning-of-stream page) after pages of an
    earlier one. One range covering the whole file for anything else: no Ogg file, a
    single link, or pages that stop making sense part way (a damaged file reads as
    libsndfile reads it). Remembered while the file's size and time stay the same: the
    page walk takes about 0.1 s for an hour of audio, and playback opens the file often.
    """
    st = os.stat(path)
    return _links(str(path), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _links(path: str, size: int, _mtime_ns: int) -> tuple[tuple[int, int], ...]:
    with open(path, "rb") as f:
        if f.read(4) != CAPTURE:
            return ((0, size),)
        starts = [0]
        pos, previous_began = 0, False
        while pos + PAGE_HEADER.size <= size:
            f.seek(pos)
            header = f.read(PAGE_HEADER.size)
            capture, _version, flags, *_rest, segments = PAGE_HEADER.unpack(header)
            table = f.read(segments)
            if capture != CAPTURE or len(table) != segments:
                return ((0, size),)
            begins = bool(flags & BEGINNING_OF_STREAM)
            if begins and pos > 0 and not previous_began:
                starts.append(pos)
            previous_began = begins
            pos += PAGE_HEADER.size + segments + sum(table)
    ends = [*starts[1:], size]
    return tuple(zip(starts, ends, strict=True))


class _ByteRange(io.RawIOBase):
    """Bytes ``start`` .. ``end`` of an open binary file, as a seekable file of its own."""

    def __init__(self, file: io.BufferedReader, start: int, end: int) -> None:
        super().__init__()
        self._file, self._start, self._end, self._pos = file, start, end, 0

    def readable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def tell(self) -> int:
        return self._pos

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        base = {io.SEEK_SET: 0, io.SEEK_CUR: self._pos,
                io.SEEK_END: self._end - self._start}[whence]
        self._pos = max(0, base + offset)
        return self._pos

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer).cast("B")
        n = max(0, min(len(view), self._end - self._start - self._pos))
        self._file.seek(self._start + self._pos)
        got = self._file.readinto(view[:n])
        self._pos += got
        return got


class OggChain:
    """The links of a chained Ogg file read as one sound file: the part of
    :class:`soundfile.SoundFile`'s reading interface this package uses (``samplerate``,
    ``channels``, ``frames``, ``seek``, ``read``, ``close``, ``with``)."""

    def __init__(self, path: Path, links: Sequence[sf.SoundFile], raw: io.BufferedReader
                 ) -> None:
        self.name = str(path)
        self._links = list(links)
        self._raw = raw
        self.samplerate = int(links[0].samplerate)
        self.channels = int(links[0].channels)
        self._lengths = [_frames(link) for link in self._links]
        self.frames = int(sum(self._lengths))
        self._link = 0

    def seek(self, frame: int) -> int:
        """Go to ``frame`` of the whole chain (clipped to it); returns where it went."""
        frame = int(min(max(frame, 0), self.frames))
        first = 0
        for k, length in enumerate(self._lengths):
            if frame < first + length or k == len(self._lengths) - 1:
                self._link = k
                self._links[k].seek(min(frame - first, length))
                return frame
            first += length
        return frame

    def read(self, frames: int = -1, dtype: str = "float64", always_2d: bool = False,
             out: np.ndarray | None = None) -> np.ndarray:
        """Up to ``frames`` frames (all that remain for -1) from where the chain stands,
        crossing from one link into the next, as :meth:`soundfile.SoundFile.read` reads."""
        if out is None:
            want = self._remaining() if frames < 0 else int(frames)
            out = np.empty((want, self.channels), dtype=dtype)
        else:
            want = out.shape[0] if frames < 0 else min(int(frames), out.shape[0])
        target = out if out.ndim == 2 else out.reshape(-1, 1)
        n = 0
        while n < want and self._link < len(self._links):
            got = self._links[self._link].read(want - n, dtype=str(target.dtype),
                                               always_2d=True, out=target[n:want])
            n += got.shape[0]
            if n < want:  # this link is done: the next one from its start
                self._link += 1
                if self._link < len(self._links):
                    self._links[self._link].seek(0)
        result = target[:n]
        return result if always_2d or self.channels > 1 else result[:, 0]

    def _remaining(self) -> int:
        done = sum(self._lengths[:self._link])
        if self._link < len(self._links):
            done += self._links[self._link].tell()
        return max(0, self.frames - done)

    def close(self) -> None:
        for link in self._links:
            link.close()
        self._raw.close()

    def __enter__(self) -> OggChain:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def open_ogg_chain(path: str | Path) -> OggChain | None:
    """``path`` read across all its chain links, or None when it has only one (open it as
    usual). Raises :class:`AudioError` when the links differ in sample rate or channels
    (recordings of different devices joined: convert each apart)."""
    p = Path(path)
    links = ogg_links(p)
    if len(links) < 2:
        return None
    raw = open(p, "rb")  # noqa: SIM115 - closed by the chain, or below
    files: list[sf.SoundFile] = []
    try:
        for start, end in links:
            files.append(sf.SoundFile(_ByteRange(raw, start, end)))
        formats = {(int(f.samplerate), int(f.channels)) for f in files}
        if len(formats) > 1:
            described = ", ".join(f"{rate} Hz with {ch} channel(s)"
                                  for rate, ch in sorted(formats))
            raise AudioError(
                f"{p}: holds {len(links)} Ogg streams one after another in different "
                f"formats ({described}); convert each to WAV or FLAC on its own and "
                "join them at one rate, e.g. with sox")
        return OggChain(p, files, raw)
    except BaseException:
        for f in files:
            f.close()
        raw.close()
        raise


def _frames(link: sf.SoundFile) -> int:
    """A link's length in frames, decoded to its end where its header does not know it."""
    frames = int(link.frames or 0)
    if 0 <= frames < _UNKNOWN_FRAMES:
        return frames
    n = 0
    for block in link.blocks(blocksize=1 << 16, dtype="float32", always_2d=True):
        n += block.shape[0]
    link.seek(0)
    return n
