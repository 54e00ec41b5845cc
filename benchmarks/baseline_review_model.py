"""The review model's part of an offset edit and of finding the set at the playhead as it
was before choices were kept and set times remembered (kept verbatim from commit c098894
as the named baseline of ``bench_set_table.py``; not used by the app): every offset edit
makes a new frame choice per camera and set, and every look for the set at the playhead
sorts every set's stamps."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import replace

import numpy as np

from speechcal_core.frames.nearest import frame_period_ns
from speechcal_core.review.model import ReviewModel, set_time_ns
from speechcal_core.session.model import FrameChoice, FrameSet


def nearest_choices(stream: str, stamps: np.ndarray, times_ns: Sequence[int],
                    period_ns: int | None = None) -> list[FrameChoice]:
    """:func:`nearest_choice` for many times at once (one search over the stamps: an
    offset edit moves every set, a dozen cameras' frames each)."""
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
    return [FrameChoice(stream, -1, int(s), flags=("no-frame",)) if f
            else FrameChoice(stream, int(i), int(s))
            for i, s, f in zip(idx.tolist(), near.tolist(), far.tolist(), strict=True)]


def set_at_playhead(self: ReviewModel, tolerance_ns: int = 50_000_000) -> FrameSet | None:
    """The frame set whose time is within ``tolerance_ns`` of the playhead (of sets at
    the same time, such as a false trigger that took a real set's frames, the current
    one)."""
    best, best_d = None, tolerance_ns + 1
    sets = self.session.sets
    # while listeners hear of a changed list, ``current`` may not be set yet
    first = [sets[self.current]] if 0 <= self.current < len(sets) else []
    for s in first + sets:
        d = abs(set_time_ns(s) - self.playhead_ns)
        if d < best_d:
            best, best_d = s, d
    return best


def follow_sync(self: ReviewModel) -> None:
    """Sets whose time does not follow the session's sync (moved by an offset edit, or
    read from a file whose offset was edited by hand) take the frames nearest their
    time under it, without details, until re-scored."""
    sets = self.session.sets
    if not sets:
        return
    # every set at once: an offset edit moves them all, a dozen cameras' frames each
    now = self.session.sync.to_session(np.array([s.trigger.t_s for s in sets]))
    moved = [i for i, s in enumerate(sets) if s.t_ns != int(now[i])]
    if not moved:
        return
    details = self._frame_details()
    times = [int(now[i]) for i in moved]
    nearest = [nearest_choices(name, st, times, self._periods[name])
               for name, st in self._stamps.items()]
    for k, i in enumerate(moved):
        details.pop(str(sets[i].id), None)  # its corners are other frames'
        frames = tuple(choices[k] for choices in nearest)
        sets[i] = replace(sets[i], t_ns=times[k], frames=frames or sets[i].frames)


@contextmanager
def model_as_before(model_class: type[ReviewModel]) -> Iterator[None]:
    """``model_class`` does these two parts as before, until the block ends."""
    now = model_class._follow_sync, model_class.set_at_playhead
    model_class._follow_sync, model_class.set_at_playhead = follow_sync, set_at_playhead
    try:
        yield
    finally:
        model_class._follow_sync, model_class.set_at_playhead = now
