"""MP3 files joined byte by byte: ``cat a.mp3 b.mp3 > c.mp3`` (two takes in one file).

An encoder such as LAME puts a Xing/Info header in an MP3 file's first frame giving the
stream's length in frames and in bytes. libsndfile (mpg123) trusts that count, so a file
joined after it decodes only to the first take's length and the takes after it (every
trigger said in them) would be lost without a word.

:func:`mp3_takes` reads the first frame of each take (a few KB, once per open) and finds
where the take ends by its header's byte count; what follows is another MP3 file when an
ID3v2 tag or two MPEG audio frames in a row start there. :func:`open_mp3_chain` reads the
takes one after another, each as a file of its own (a view of its bytes), so each decodes
exactly as it would alone. :func:`joined_mp3_note` tells the operator where the rest of a
joined file does not decode.
"""

from __future__ import annotations

import functools
import os
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import soundfile as sf

from speechcal_core.audio.ogg_chain import (
    SoundFileChain,
    close_parts,
    open_parts,
    part_formats,
)

#: kbit/s by bitrate index: MPEG-1 layer III, and MPEG-2/2.5 layer III
_BITRATES = {
    3: (0, 32, 40, 48, 56, 64, 80, 96, 112, 128, 160, 192, 224, 256, 320, 0),
    2: (0, 8, 16, 24, 32, 40, 48, 56, 64, 80, 96, 112, 128, 144, 160, 0),
}
#: Hz by sample rate index, per version bits (3: MPEG-1, 2: MPEG-2, 0: MPEG-2.5)
_RATES = {3: (44100, 48000, 32000), 2: (22050, 24000, 16000), 0: (11025, 12000, 8000)}
#: bytes read of a take's start: an ID3v2 tag's header and the first frames
_HEAD = 4096
#: bytes past the header's count not taken for more audio (stray padding, a short tag)
SLACK_BYTES = 4096
SLACK_RATIO = 0.02


def _frame(data: bytes, at: int = 0) -> tuple[int, int, int] | None:
    """An MPEG layer III frame header at ``at``: (frame bytes, sample rate, samples per
    frame), None where none starts there."""
    if at + 4 > len(data) or data[at] != 0xFF or data[at + 1] & 0xE0 != 0xE0:
        return None
    version, layer = (data[at + 1] >> 3) & 3, (data[at + 1] >> 1) & 3
    bitrate_index, rate_index = data[at + 2] >> 4, (data[at + 2] >> 2) & 3
    if version == 1 or layer != 1 or rate_index == 3:
        return None
    kbps = _BITRATES[3 if version == 3 else 2][bitrate_index]
    if kbps == 0:
        return None
    rate = _RATES[version][rate_index]
    per_frame = 1152 if version == 3 else 576
    size = per_frame // 8 * kbps * 1000 // rate + ((data[at + 2] >> 1) & 1)
    return size, rate, per_frame


def _id3v2_size(data: bytes) -> int:
    """Bytes of an ID3v2 tag at the start of ``data`` (0 when none)."""
    if len(data) < 10 or data[:3] != b"ID3":
        return 0
    n = 0
    for b in data[6:10]:
        n = (n << 7) | (b & 0x7F)
    return 10 + n + (10 if data[5] & 0x10 else 0)


def _xing(data: bytes, size: int) -> tuple[int | None, int | None]:
    """(frames, bytes) of a Xing/Info header in the frame of ``size`` bytes ``data``
    starts with, None where not given."""
    frame = data[:size]
    found = max(frame.find(b"Xing"), frame.find(b"Info"))
    if found < 0 or found + 8 > len(frame):
        return None, None
    flags = struct.unpack_from(">I", frame, found + 4)[0]
    pos, frames, nbytes = found + 8, None, None
    if flags & 1 and pos + 4 <= len(frame):
        frames = struct.unpack_from(">I", frame, pos)[0]
        pos += 4
    if flags & 2 and pos + 4 <= len(frame):
        nbytes = struct.unpack_from(">I", frame, pos)[0]
    return frames, nbytes


def _tags_end(f: BinaryIO, size: int) -> int:
    """Where the audio of a file of ``size`` bytes ends: before an ID3v1 tag and an
    APEv2 tag at its end."""
    end = size
    read, seek = f.read, f.seek
    if end >= 128:
        seek(end - 128)
        if read(3) == b"TAG":
            end -= 128
    if end >= 32:
        seek(end - 32)
        footer = read(32)
        if footer[:8] == b"APETAGEX":
            tag = struct.unpack_from("<I", footer, 12)[0]
            has_header = struct.unpack_from("<I", footer, 20)[0] & 0x80000000
            end -= tag + (32 if has_header else 0)
    return max(end, 0)


def _after_tags(f: BinaryIO, at: int, end: int) -> int:
    """Where the bytes from ``at`` on go on past the ID3v1 and APEv2 tags that end a take
    there (the header's byte count leaves them out)."""
    f.seek(at)
    head = f.read(32)
    if head[:8] == b"APETAGEX" and len(head) == 32:
        at += struct.unpack_from("<I", head, 12)[0] + 32
        f.seek(at)
        head = f.read(3)
    if head[:3] == b"TAG" and at + 128 <= end:
        at += 128
    return at


def _take_start(f: BinaryIO, at: int, end: int) -> bool:
    """Whether another MP3 file starts at byte ``at``: an ID3v2 tag, or two frames in a
    row."""
    f.seek(at)
    data = f.read(_HEAD)
    if data[:3] == b"ID3":
        return True
    first = _frame(data)
    return first is not None and (at + first[0] >= end or _frame(data, first[0]) is not None)


@dataclass(frozen=True)
class Mp3Layout:
    """What :func:`mp3_layout` finds: the takes' byte ranges, the seconds the first
    take's header gives, its stream's bytes, and the audio bytes of the whole file."""

    takes: tuple[tuple[int, int], ...]
    first_s: float
    first_bytes: int
    audio_bytes: int

    @property
    def joined(self) -> bool:
        """Whether the file holds well more audio than its first header counts."""
        extra = self.audio_bytes - self.first_bytes
        return self.first_bytes > 0 and extra > max(SLACK_BYTES,
                                                     SLACK_RATIO * self.first_bytes)


def mp3_layout(path: str | Path) -> Mp3Layout | None:
    """The layout of the MP3 file ``path``, None for anything else or an MP3 file whose
    first frame gives no byte count (libsndfile then reads it to its end). Remembered
    while the file's size and time stay the same."""
    st = os.stat(path)
    return _layout(str(path), st.st_size, st.st_mtime_ns)


@functools.lru_cache(maxsize=32)
def _layout(path: str, size: int, _mtime_ns: int) -> Mp3Layout | None:
    with open(path, "rb") as f:
        audio_end = _tags_end(f, size)
        takes: list[tuple[int, int]] = []
        first_s, first_bytes, start = 0.0, 0, 0
        while start < audio_end:
            f.seek(start)
            at = _id3v2_size(f.read(10))
            f.seek(start + at)  # the first frame, after any ID3v2 tag
            data = f.read(_HEAD)
            frame = _frame(data)
            frames, nbytes = _xing(data, frame[0]) if frame else (None, None)
            if frame is None or not nbytes:
                if not takes:
                    return None
                takes.append((start, audio_end))  # a take that counts no bytes
                break
            if not takes:
                first_s = (frames or 0) * frame[2] / frame[1]
                first_bytes = nbytes + at
            # the count starts at the first frame (some writers count the tag before it)
            ends = [e for e in (start + at + nbytes, start + nbytes) if e <= audio_end]
            found = next(((e, n) for e in ends
                          if _take_start(f, n := _after_tags(f, e, audio_end), audio_end)),
                         None)
            if found is None:  # the last take, or bytes after it that are no MP3 file
                takes.append((start, audio_end))
                break
            takes.append((start, found[0]))
            start = found[1]
    return Mp3Layout(tuple(takes), first_s, first_bytes, audio_end)


def open_mp3_chain(path: str | Path) -> SoundFileChain | None:
    """``path`` read across all the MP3 takes joined in it, or None when it holds one
    (open it as usual) or the takes differ in sample rate or channels (then only the
    first decodes: :func:`joined_mp3_note` says so)."""
    p = Path(path)
    layout = mp3_layout(p)
    if layout is None or len(layout.takes) < 2 or not layout.joined:
        return None
    try:
        raw, files = open_parts(p, layout.takes)
    except (sf.LibsndfileError, RuntimeError, TypeError):
        return None
    try:
        if len(part_formats(files)) == 1:
            return SoundFileChain(p, files, raw)
    except (sf.LibsndfileError, RuntimeError, TypeError):
        pass
    except BaseException:
        close_parts(raw, files)
        raise
    close_parts(raw, files)
    return None


def joined_mp3_note(path: str | Path | None, decoded_s: float) -> str:
    """A note when the MP3 file ``path`` holds well more audio than its first header
    counts and only about that much decoded (``decoded_s`` seconds), else ""."""
    if path is None or not Path(path).is_file():
        return ""
    try:
        layout = mp3_layout(path)
    except OSError:
        return ""
    if layout is None or not layout.joined or layout.first_s <= 0:
        return ""
    if decoded_s > layout.first_s + 0.5:  # the takes after the first decoded as well
        return ""
    rough_s = layout.first_s * layout.audio_bytes / layout.first_bytes
    return (f"{path}: only the first {decoded_s:.1f} s decode, but the file holds roughly "
            f"{rough_s:.0f} s of MP3 audio: its first header counts only the first "
            f"{layout.first_bytes} of its {layout.audio_bytes} bytes, as when MP3 takes "
            "are joined byte by byte (cat a.mp3 b.mp3), and the rest is left out; convert "
            "each take on its own to WAV or FLAC and give them apart, or join them with an "
            "audio editor that writes the joined file anew")
