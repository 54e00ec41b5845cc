"""What a file that is not the recording it was given as looks like, for error messages."""

from __future__ import annotations

from pathlib import Path

#: leading bytes of files people give by mistake, and what to call them
_KINDS = (
    (b"#ROSBAG V2.0\n", "a ROS1 bag (name it .bag)"),
    (b"#ROSBAG V1.", "a ROS1 bag of the old format 1.2 (convert it: rosbag fix)"),
    (b"\x89MCAP0\r\n", "an MCAP file (name it .mcap)"),
    (b"SQLite format 3\0", "an SQLite database (a ROS2 .db3: name it .db3)"),
    (b"\x89PNG\r\n\x1a\n", "a PNG image"),
    (b"\xff\xd8\xff", "a JPEG image"),
    (b"OggS", "an Ogg audio file (give audio with --audio)"),
    (b"RIFF", "a WAV audio file (give audio with --audio)"),
    (b"fLaC", "a FLAC audio file (give audio with --audio)"),
    (b"PK\x03\x04", "a zip archive (unpack it first)"),
    (b"{", "a JSON file (a session file opens with speechcal review)"),
)


def looks_like(path: Path) -> str:
    """What ``path`` seems to be from its first bytes ("empty (0 bytes)", "a PNG image"),
    or "" when nothing is recognised or it cannot be read."""
    try:
        with open(path, "rb") as f:
            head = f.read(16)
    except OSError:
        return ""
    if not head:
        return "empty (0 bytes)"
    return next((kind for magic, kind in _KINDS if head.startswith(magic)), "")
