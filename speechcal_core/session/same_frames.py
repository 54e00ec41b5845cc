"""Frame sets that show the very same frames: two triggers in one still hold.

The operator says the trigger word once per hold, but a false trigger (a distractor heard
as the word) in the same hold takes the same stillest frames as the real one. Such sets
are one calibration view, not two: the list says so, the calibration check counts each
frame once and an export writes the frames once.
"""

from __future__ import annotations

from collections.abc import Sequence

from speechcal_core.session.model import FrameSet


def frames_key(frame_set: FrameSet) -> tuple[tuple[str, int], ...]:
    """The set's chosen frames as (stream, index) pairs; empty when it has none."""
    return tuple(sorted((f.stream, f.index) for f in frame_set.frames if f.index >= 0))


def same_frames(sets: Sequence[FrameSet]) -> dict[int, tuple[int, ...]]:
    """For each set whose chosen frames another set shows too, the other sets' ids."""
    groups: dict[tuple[tuple[str, int], ...], list[int]] = {}
    for s in sets:
        key = frames_key(s)
        if key:
            groups.setdefault(key, []).append(s.id)
    return {i: tuple(j for j in ids if j != i)
            for ids in groups.values() if len(ids) > 1 for i in ids}


def first_of_same_frames(sets: Sequence[FrameSet]) -> tuple[list[FrameSet], dict[int, int]]:
    """``sets`` without those showing an earlier set's frames, and for each set left out
    the id of the set kept in its place."""
    kept: list[FrameSet] = []
    first: dict[tuple[tuple[str, int], ...], int] = {}
    dropped: dict[int, int] = {}
    for s in sets:
        key = frames_key(s)
        if key and key in first:
            dropped[s.id] = first[key]
            continue
        if key:
            first[key] = s.id
        kept.append(s)
    return kept, dropped
