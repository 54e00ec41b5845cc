"""Nearest frames for many times at once agree with one time at a time."""

from __future__ import annotations

import numpy as np

from speechcal_core.frames.nearest import nearest_choice, nearest_choices


def test_nearest_choices_agree_with_nearest_choice_at_every_time() -> None:
    """Ties (the earlier frame), times before the first and after the last frame, a gap
    of dropped frames (no frame within half a period), with and without the period."""
    rng = np.random.default_rng(3)
    stamps = np.cumsum(rng.integers(33_000_000, 34_000_000, 300)).astype(np.int64)
    stamps = np.delete(stamps, range(100, 110))  # dropped frames
    times = [int(stamps[0]) - 10**9, int(stamps[-1]) + 10**9,
             int(stamps[5] + stamps[6]) // 2,  # a tie when the sum is even
             *(int(t) for t in rng.integers(int(stamps[0]), int(stamps[-1]), 400))]
    for period in (None, 33_500_000, 0):
        assert nearest_choices("/cam", stamps, times, period) == \
            [nearest_choice("/cam", stamps, t, period) for t in times]
    empty = np.zeros(0, np.int64)
    assert nearest_choices("/cam", empty, times[:3]) == \
        [nearest_choice("/cam", empty, t) for t in times[:3]]
    assert nearest_choices("/cam", stamps, []) == []
    even = np.array([0, 10, 20], np.int64)
    assert [c.index for c in nearest_choices("/cam", even, [5, 15, 16], 10)] == [0, 1, 2]
