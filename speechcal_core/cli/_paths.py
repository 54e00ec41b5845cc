"""File and folder arguments: an empty one is bad usage, never the current folder."""

from __future__ import annotations

import argparse
from collections.abc import Callable


def path_arg(what: str) -> Callable[[str], str]:
    """An argparse ``type`` for a file or folder argument, ``what`` naming what to give:
    an empty value (an unset shell variable, ``--out ""``) is refused as bad usage; the
    path functions would take it for the current folder."""

    def check(value: str) -> str:
        if value == "":
            raise argparse.ArgumentTypeError(
                f"an empty name; give {what} (an empty name is not taken for the current "
                "folder: is a shell variable unset?)")
        return value

    check.__name__ = what
    return check


RECORDING = path_arg("the recording (bags, a video or an image folder)")
AUDIO = path_arg("the audio file")
SESSION = path_arg("the session file")
TARGET = path_arg("the board's Kalibr target yaml")
TRANSCRIPT = path_arg("the transcript file")
SCREENSHOT = path_arg("the PNG file to write")
