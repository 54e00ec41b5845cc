"""Frame sets by nearest header stamp: the baseline every smarter selection is compared with."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.session.model import FrameChoice, FrameSet, Trigger
from speechcal_core.sources import stats
from speechcal_core.sync.model import SyncModel

if TYPE_CHECKING:
    from speechcal_core.sources.base import FrameSource


def nearest_index(stamps: np.ndarray, t_ns: int) -> int:
    """Index of the stamp closest to ``t_ns`` in a sorted int64 array (-1 if empty)."""
    return stats.nearest_index(stamps, t_ns) if len(stamps) else -1


def stamped_index(stamps: np.ndarray, stamp_ns: int, hint: int = -1) -> int | None:
    """Index of the frame stamped exactly ``stamp_ns`` in a sorted int64 array (``hint``,
    its index as last known, is tried first); None when there is no such frame."""
    if 0 <= hint < stamps.size and int(stamps[hint]) == stamp_ns:
        return hint
    k = int(np.searchsorted(stamps, stamp_ns))
    return k if k < stamps.size and int(stamps[k]) == stamp_ns else None


def frame_period_ns(stamps: np.ndarray) -> int:
    """Median stamp spacing (0 with fewer than two stamps)."""
    return int(np.median(np.diff(stamps))) if len(stamps) > 1 else 0


def nearest_choice(stream: str, stamps: np.ndarray, t_ns: int,
                   period_ns: int | None = None) -> FrameChoice:
    """The nearest frame, flagged ``no-frame`` when it is further than half a period away.

    ``period_ns`` is the stream's frame period when the caller already knows it.
    """
    i = nearest_index(stamps, t_ns)
    if i < 0:
        return FrameChoice(stream, -1, t_ns, flags=("no-frame",))
    stamp = int(stamps[i])
    period = frame_period_ns(stamps) if period_ns is None else period_ns
    if period and abs(stamp - t_ns) > period // 2 + 1:
        return FrameChoice(stream, -1, stamp, flags=("no-frame",))
    return FrameChoice(stream, i, stamp)


def nearest_choices(stream: str, stamps: np.ndarray, times_ns: Sequence[int],
                    period_ns: int | None = None,
                    known: dict[int, FrameChoice] | None = None) -> list[FrameChoice]:
    """:func:`nearest_choice` for many times at once (one search over the stamps: an
    offset edit moves every set, a dozen cameras' frames each).

    ``known`` keeps the choices made, by frame index, to be given again (choices are
    immutable): each step of a held ``]`` picks mostly frames it picked before.
    """
    t = np.asarray(times_ns, dtype=np.int64).reshape(-1)
    n = stamps.size
    if n == 0:
        return [FrameChoice(stream, -1, int(v), flags=("no-frame",)) for v in t]
    st = np.asarray(stamps, dtype=np.int64)
    j = np.searchsorted(st, t, side="left")
    lo, hi = np.clip(j - 1, 0, n - 1), np.clip(j, 0, n - 1)
    # the earlier one on a tie, as stats.nearest_index
    idx = np.where((j > 0) & ((j >= n) | (t - st[lo] <= st[hi] - t)), lo, hi)
    near = st[idx]
    period = frame_period_ns(st) if period_ns is None else period_ns
    far = np.abs(near - t) > period // 2 + 1 if period else np.zeros(t.size, bool)
    known = {} if known is None else known
    out = []
    for i, s, f in zip(idx.tolist(), near.tolist(), far.tolist(), strict=True):
        if f:
            out.append(FrameChoice(stream, -1, s, flags=("no-frame",)))
            continue
        choice = known.get(i)
        if choice is None:
            choice = known[i] = FrameChoice(stream, i, s)
        out.append(choice)
    return out


def nearest_frame_sets(
    source: FrameSource, sync: SyncModel, triggers: Sequence[Trigger]
) -> list[FrameSet]:
    """One frame set per trigger: every camera's frame nearest the trigger's session time."""
    stamps = {s.name: source.stamps(s.name) for s in source.streams}
    sets = []
    for n, trig in enumerate(sorted(triggers, key=lambda t: t.t_s)):
        t_ns = int(sync.to_session(trig.t_s))
        frames = tuple(nearest_choice(name, st, t_ns) for name, st in stamps.items())
        sets.append(FrameSet(n + 1, t_ns, trig, frames))
    return sets
