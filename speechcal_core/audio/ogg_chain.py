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
    earlier one. One range covering the whole file for anything else: no Ogg file or a
    single link. Bytes that are no page (damaged, or a gap where a copy lost some) are
    skipped to the next page, so the links after them are still found. Remembered while
    the file's size and time stay the same: the page walk takes about 0.1 s for an hour
    of audio, and playback opens the file often.
    """
    return tuple((start, end) for start, end, _ in _walk(path))


def ogg_link_lengths(path: str | Path) -> tuple[int | None, ...]:
    """Per link of :func:`ogg_links`, its length in samples as its last page's granule
    position gives it (at the rate libsndfile decodes it), None where the codec or the
    pages do not tell. A link damaged or cut part way decodes to less: its pages still
    say how long it was, so the links after it keep their place in time."""
    return tuple(length for _, _, length in _walk(path))


def _walk(path: str | Path) -> tuple[tuple[int, int, int | None], ...]:
    st = os.stat(path)
    return _links(str(path), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _links(path: str, size: int, _mtime_ns: int) -> tuple[tuple[int, int, int | None], ...]:
    with open(path, "rb") as f:
        if f.read(4) != CAPTURE:
            return ((0, size, None),)
        starts = [0]
        # per link: the serial of its first stream, what its first packet says of how
        # granule positions count, and the last granule position of that stream
        heads: list[tuple[int, bytes]] = []
        granules: list[int | None] = []
        pos, previous_began = 0, False
        while pos + PAGE_HEADER.size <= size:
            f.seek(pos)
            header = f.read(PAGE_HEADER.size)
            capture, version, flags, granule, serial, *_rest, segments = \
                PAGE_HEADER.unpack(header)
            if capture != CAPTURE or version != 0:  # damaged: on at the next page
                found = _next_capture(f, pos + 1)
                if found < 0:
                    break
                pos = found
                continue
            table = f.read(segments)
            if len(table) != segments:
                break
            begins = bool(flags & BEGINNING_OF_STREAM)
            if pos == 0 or (begins and not previous_began):
                if pos > 0:
                    starts.append(pos)
                heads.append((serial, f.read(min(sum(table), 32))))
                granules.append(None)
            elif heads and serial == heads[-1][0] and granule >= 0:
                granules[-1] = granule
            previous_began = begins
            pos += PAGE_HEADER.size + segments + sum(table)
    if not heads:
        return ((0, size, None),)
    ends = [*starts[1:], size]
    return tuple((start, end, _samples(head, granule)) for start, end, (_serial, head), granule
                 in zip(starts, ends, heads, granules, strict=True))


def _next_capture(f: io.BufferedReader, start: int) -> int:
    """Where the next page's capture pattern lies from ``start`` on, -1 when none does (as
    libogg finds its way back into a damaged stream)."""
    block = 1 << 16
    while True:
        f.seek(start)
        chunk = f.read(block + len(CAPTURE) - 1)
        found = chunk.find(CAPTURE)
        if found >= 0:
            return start + found
        if len(chunk) < block + len(CAPTURE) - 1:
            return -1
        start += block


def _samples(head: bytes, granule: int | None) -> int | None:
    """A stream's length in samples from its last granule position and its first packet
    (``head``): Vorbis and FLAC count samples, Opus counts 48 kHz samples from before its
    pre-skip and decodes at the rate its header names."""
    if granule is None:
        return None
    if head.startswith((b"\x01vorbis", b"\x7fFLAC")):
        return granule
    if head.startswith(b"OpusHead") and len(head) >= 16:
        pre_skip, rate = struct.unpack_from("<HI", head, 10)
        rate = rate if rate in (8000, 12000, 16000, 24000, 48000) else 48000
        return max(0, granule - pre_skip) * rate // 48000
    return None


class ByteRange(io.RawIOBase):
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


class SoundFileChain:
    """The links of a chained Ogg file (or the takes of joined MP3 files,
    :mod:`~speechcal_core.audio.mp3_join`), each a sound file of its own, read as one: the
    part of :class:`soundfile.SoundFile`'s reading interface this package uses
    (``samplerate``, ``channels``, ``frames``, ``seek``, ``read``, ``close``, ``with``).

    A link that decodes to less than its pages say it holds (damaged or cut part way)
    reads as silence for the rest (:attr:`silent_frames`), so the links after it keep
    their place in time: a trigger said after it maps to the frames it was said at."""

    def __init__(self, path: Path, links: Sequence[sf.SoundFile], raw: io.BufferedReader,
                 lengths: Sequence[int | None] | None = None) -> None:
        self.name = str(path)
        self._links = list(links)
        self._raw = raw
        self.samplerate = int(links[0].samplerate)
        self.channels = int(links[0].channels)
        #: frames each link decodes to (lowered where reading stops before)
        self._decodes = [_frames(link) for link in self._links]
        paged = list(lengths) if lengths is not None else [None] * len(self._links)
        self._lengths = [max(d, n or 0) for d, n in zip(self._decodes, paged, strict=True)]
        self.frames = int(sum(self._lengths))
        self._link = 0
        self._in_link = 0  # frames into the current link

    @property
    def silent_frames(self) -> int:
        """Frames read as silence because their link does not decode that far (as far as
        known: reading finds where a link stops decoding)."""
        return int(sum(n - d for n, d in zip(self._lengths, self._decodes, strict=True)))

    def seek(self, frame: int) -> int:
        """Go to ``frame`` of the whole chain (clipped to it); returns where it went."""
        frame = int(min(max(frame, 0), self.frames))
        first = 0
        for k, length in enumerate(self._lengths):
            if frame < first + length or k == len(self._lengths) - 1:
                self._link = k
                self._in_link = min(frame - first, length)
                self._links[k].seek(min(self._in_link, self._decodes[k]))
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
            k = self._link
            take = min(want - n, self._lengths[k] - self._in_link)
            if take <= 0:  # this link is done: the next one from its start
                self._link += 1
                self._in_link = 0
                if self._link < len(self._links):
                    self._links[self._link].seek(0)
                continue
            if self._in_link < self._decodes[k]:
                got = self._links[k].read(min(take, self._decodes[k] - self._in_link),
                                          dtype=str(target.dtype), always_2d=True,
                                          out=target[n:n + take]).shape[0]
                if got == 0:  # it decodes no further than this
                    self._decodes[k] = self._in_link
            else:
                target[n:n + take] = 0
                got = take
            n += got
            self._in_link += got
        result = target[:n]
        return result if always_2d or self.channels > 1 else result[:, 0]

    def _remaining(self) -> int:
        done = sum(self._lengths[:self._link]) + self._in_link
        return max(0, self.frames - done)

    def close(self) -> None:
        for link in self._links:
            link.close()
        self._raw.close()

    def __enter__(self) -> SoundFileChain:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def open_ogg_chain(path: str | Path) -> SoundFileChain | None:
    """``path`` read across all its chain links, or None when it has only one (open it as
    usual). Raises :class:`AudioError` when the links differ in sample rate or channels
    (recordings of different devices joined: convert each apart)."""
    p = Path(path)
    links = ogg_links(p)
    if len(links) < 2:
        return None
    raw, files = open_parts(p, links)
    try:
        formats = part_formats(files)
        if len(formats) > 1:
            described = ", ".join(f"{rate} Hz with {ch} channel(s)"
                                  for rate, ch in sorted(formats))
            raise AudioError(
                f"{p}: holds {len(links)} Ogg streams one after another in different "
                f"formats ({described}); convert each to WAV or FLAC on its own and "
                "join them at one rate, e.g. with sox")
        return SoundFileChain(p, files, raw, ogg_link_lengths(p))
    except BaseException:
        close_parts(raw, files)
        raise


def open_parts(path: Path, ranges: Sequence[tuple[int, int]]
               ) -> tuple[io.BufferedReader, list[sf.SoundFile]]:
    """``path`` opened once, and each byte range of it opened as a sound file of its own
    (a :class:`ByteRange` view); nothing is left open when one of them fails."""
    raw = open(path, "rb")  # noqa: SIM115 - closed by close_parts (or the chain)
    files: list[sf.SoundFile] = []
    try:
        for start, end in ranges:
            files.append(sf.SoundFile(ByteRange(raw, start, end)))
    except BaseException:
        close_parts(raw, files)
        raise
    return raw, files


def close_parts(raw: io.BufferedReader, files: Sequence[sf.SoundFile]) -> None:
    """Close what :func:`open_parts` opened."""
    for f in files:
        f.close()
    raw.close()


def part_formats(files: Sequence[sf.SoundFile]) -> set[tuple[int, int]]:
    """The (sample rate, channels) pairs the parts decode to."""
    return {(int(f.samplerate), int(f.channels)) for f in files}


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
