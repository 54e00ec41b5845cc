"""What goes where: camera order and folder names, one shared file name per frame set.

The file name of a set is its trigger time ``t_ns`` (``<t_ns>.png``), the same in every
camera's folder, so Kalibr's ``kalibr_bagcreater`` and other same-name tools pair the
cameras' images. Two sets with the same ``t_ns`` (rare: duplicate triggers) get the later
one's name moved by 1 ns. Names have :data:`NAME_DIGITS` digits, zeros in front where the
time is shorter (a camera clock that starts at 0): ``kalibr_bagcreater`` takes all but the
last nine digits as the seconds (``int(name[0:-9])``, which fails on a name of nine digits
or fewer, a set under 1 s) and sorts the names as text.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from speechcal_core.export.errors import ExportError
from speechcal_core.frames.nearest import stamped_index

if TYPE_CHECKING:
    from speechcal_core.session.model import FrameChoice, FrameSet
    from speechcal_core.sources.base import FrameSource

#: progress callback of every writer: (what is being done, fraction done)
Progress = Callable[[str, float], None]
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def safe_name(topic: str) -> str:
    """A folder name from a topic: ``/cam0/image_raw`` -> ``cam0_image_raw``."""
    name = _UNSAFE.sub("_", topic.strip("/")).strip("._")
    return name or "camera"


def unique_safe_names(topics: list[str]) -> dict[str, str]:
    """Filesystem-safe folder names, made unique with ``_2``, ``_3``... (case-insensitively)."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for topic in topics:
        base = name = safe_name(topic)
        k = 2
        while name.lower() in used:
            name = f"{base}_{k}"
            k += 1
        used.add(name.lower())
        out[topic] = name
    return out


@dataclass(frozen=True)
class PlannedFrame:
    """One camera's frame of one set, with its index checked against the recording."""

    frame_set: FrameSet
    choice: FrameChoice
    index: int
    name: str  # the set's shared file stem


@dataclass(frozen=True)
class Plan:
    """Cameras in export order and every frame to write."""

    streams: list[str]  # the recording's streams that have a frame in the export
    sets: list[FrameSet]
    names: dict[int, str]  # set id -> shared file stem
    frames: list[PlannedFrame]
    recording_streams: list[str]  # all of the recording's streams, in its order

    @property
    def left_out(self) -> list[str]:
        """The recording's streams without a frame in any exported set."""
        return [s for s in self.recording_streams if s not in self.streams]

    def frames_of(self, set_id: int) -> list[PlannedFrame]:
        return [f for f in self.frames if f.frame_set.id == set_id]


#: digits of a set's file name: those of an int64 of nanoseconds, which a header stamp of
#: this century (from 2001-09-09, 10**18 ns) has already, so that the names of a folder
#: sort as text in time order and every one has seconds before its last nine digits
NAME_DIGITS = 19


def shared_names(sets: list[FrameSet]) -> dict[int, str]:
    """One file stem per set: its ``t_ns`` in :data:`NAME_DIGITS` digits (zeros in front
    of a short one: ``0000000000601438148`` for 0.601 s), moved by 1 ns when an earlier
    set took it."""
    names: dict[int, str] = {}
    used: set[int] = set()
    for s in sets:
        t = s.t_ns
        while t in used:
            t += 1
        used.add(t)
        names[s.id] = f"{t:0{NAME_DIGITS}d}"
    return names


#: what to do when the session's recording is not the one it was made from
_OWN_RECORDING = ("point the session at its own recording (speechcal review RECORDING "
                  "--audio AUDIO --session SESSION.json), or process this one into a new "
                  "session (its review starts anew)")


def resolve_index(source: FrameSource, choice: FrameChoice, where: str) -> int:
    """The frame's index in ``source``, found by its header stamp if the index moved."""
    index = stamped_index(source.stamps(choice.stream), choice.stamp_ns, choice.index)
    if index is not None:
        return index
    raise ExportError(
        f"{where}: {choice.stream} has no frame stamped {choice.stamp_ns}; the recording "
        f"differs from the one this session was made from: {_OWN_RECORDING}"
    )


def make_plan(source: FrameSource, sets: list[FrameSet], where: str) -> Plan:
    """Cameras (recording order) and the frames of ``sets``; ``ExportError`` on a mismatch."""
    known = [s.name for s in source.streams]
    used = {f.stream for s in sets for f in s.frames if f.index >= 0}
    missing = sorted(used - set(known))
    if missing:
        raise ExportError(
            f"{where}: the recording has no stream {missing[0]!r} (it has {', '.join(known)}); "
            f"the session belongs to another recording: {_OWN_RECORDING}"
        )
    streams = [n for n in known if n in used]
    names = shared_names(sets)
    order = {n: k for k, n in enumerate(streams)}
    frames = [
        PlannedFrame(s, f, resolve_index(source, f, where), names[s.id])
        for s in sets
        for f in sorted((f for f in s.frames if f.index >= 0), key=lambda f: order[f.stream])
    ]
    return Plan(streams, sets, names, frames, known)


@dataclass
class Outcome:
    """What a writer produced: per (set id, stream) the file (relative to the export
    folder) or why the frame was left out, and every file written."""

    files: dict[tuple[int, str], str]
    skipped: dict[tuple[int, str], str]
    written: list[str]

    @classmethod
    def empty(cls) -> Outcome:
        return cls({}, {}, [])
