"""The length a WAV file's own header gives: its data chunk's size.

libsndfile gives a WAV file cut short (a copy that stopped early) the length of what is
left, not the one its header declares, so the file seemed whole; and a file whose header
a recorder never finished (data size 0) none at all. The data chunk's size, read here
from the RIFF header (a few dozen bytes), tells both apart from a whole file.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from pathlib import Path

#: format tags whose block align is one frame: PCM, IEEE float, A-law, mu-law, extensible
FRAME_TAGS = (0x0001, 0x0003, 0x0006, 0x0007, 0xFFFE)
#: a size a streaming recorder writes for "up to the end of the file"
UNKNOWN_SIZES = (0xFFFFFFFF, 0x7FFFFFFF)
#: chunks read before giving up on finding the data chunk
MAX_CHUNKS = 64


@dataclass(frozen=True)
class DataChunk:
    """A WAV file's data chunk: its declared size, where its bytes start, bytes a frame."""

    size: int
    start: int
    frame_bytes: int  # 0: frames not of fixed size (a compressed format)


def wav_data_chunk(path: str | Path) -> DataChunk | None:
    """The data chunk of the RIFF WAV file ``path``; None for other files."""
    try:
        with open(path, "rb") as f:
            if f.read(4) != b"RIFF" or len(f.read(4)) < 4 or f.read(4) != b"WAVE":
                return None
            frame_bytes = 0
            for _ in range(MAX_CHUNKS):
                head = f.read(8)
                if len(head) < 8:
                    return None
                name, size = head[:4], struct.unpack("<I", head[4:])[0]
                if name == b"data":
                    return DataChunk(size, f.tell(), frame_bytes)
                body = f.read(min(size, 16)) if name == b"fmt " else b""
                if name == b"fmt " and len(body) >= 14:
                    tag, _channels, _rate, _rate_bytes, align = struct.unpack("<HHIIH",
                                                                               body[:14])
                    frame_bytes = align if tag in FRAME_TAGS else 0
                f.seek(size + (size & 1) - len(body), 1)  # chunks are padded to even sizes
    except OSError:
        return None
    return None


def wav_declared_frames(path: str | Path) -> int | None:
    """Frames the data chunk of the WAV file ``path`` declares; None where that is not
    known (not a RIFF WAV file, a compressed format, no size written)."""
    chunk = wav_data_chunk(path)
    if chunk is None or not chunk.frame_bytes or chunk.size in (0, *UNKNOWN_SIZES):
        return None
    return chunk.size // chunk.frame_bytes


def wav_unfinished_bytes(path: str | Path) -> int:
    """Bytes after the data chunk's header of a WAV file whose header declares no data
    (a recorder that stopped before writing the length): libsndfile reads none of them."""
    chunk = wav_data_chunk(path)
    if chunk is None or chunk.size != 0:
        return 0
    try:
        return max(0, os.stat(path).st_size - chunk.start)
    except OSError:
        return 0
