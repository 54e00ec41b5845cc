"""Stamp statistics: sorting, problems, period, dropped frames, nearest index."""

from __future__ import annotations

import numpy as np
import pytest

from speechcal_core.sources.stats import nearest_index, stamp_stats


def test_regular_stamps_have_no_problems() -> None:
    st = stamp_stats([np.arange(10, dtype=np.int64) * 100 + 1000])
    assert st.problems == "" and st.median_period_ns == 100 and st.dropped == 0
    assert st.nominal_rate_hz == 1e7


def test_order_is_counted_per_file_and_sorting_is_stable() -> None:
    a = np.array([10, 20, 30], np.int64)
    b = np.array([1, 5], np.int64)  # an earlier file given second: not a problem
    st = stamp_stats([a, b])
    assert st.problems == ""
    assert list(st.stamps) == [1, 5, 10, 20, 30] and list(st.order) == [3, 4, 0, 1, 2]
    st = stamp_stats([np.array([10, 30, 20, 20], np.int64)])
    assert st.problems == "1 stamp out of order (sorted); 1 duplicate stamp (kept)"
    assert list(st.order) == [0, 2, 3, 1]


def test_two_recordings_of_one_topic_given_together_are_reported() -> None:
    """Split bags follow each other (a seam may overlap a few stamps); a second recording
    of the same topics interleaves with the first: 2966 frames at "37 Hz", unsaid."""
    first = np.arange(100, dtype=np.int64) * 50 + 10**9
    seam = np.arange(97, 200, dtype=np.int64) * 50 + 10**9 + 7  # 3 stamps at the seam
    assert stamp_stats([first, seam]).problems == ""
    other = np.arange(80, dtype=np.int64) * 50 + 10**9 + 13  # another take, same time
    assert stamp_stats([first, other]).problems == (
        "80 stamps of one file fall among another's (another recording given too? split "
        "bags follow each other)")

def test_dropped_frames_round_gaps_to_whole_periods() -> None:
    stamps = np.array([0, 100, 200, 500, 600, 800, 900], np.int64)
    assert stamp_stats([stamps]).dropped == 3  # 2 missing before 500, 1 before 800


def test_unset_stamps_are_reported() -> None:
    assert "not set" in stamp_stats([np.zeros(3, np.int64)]).problems


def test_an_unset_stamp_among_set_ones_is_left_out_where_asked() -> None:
    """A driver's first frame with a zero header stamp: counted as 34 billion dropped
    frames, and the stream's start put in 1970."""
    stamps = np.array([0, 1000, 1100, 1200, 1300], np.int64)
    st = stamp_stats([stamps], unset_out=True)
    assert list(st.stamps) == [1000, 1100, 1200, 1300] and list(st.order) == [1, 2, 3, 4]
    assert st.dropped == 0 and st.median_period_ns == 100
    assert st.problems == ("1 frame with a zero or negative header stamp left out "
                           "(not set by the camera driver?)")
    assert list(stamp_stats([stamps]).stamps) == list(stamps)  # a video's first frame is 0


@pytest.mark.parametrize(
    ("t", "want"), [(-5, 0), (0, 0), (49, 0), (50, 0), (51, 1), (140, 1), (151, 2), (999, 2)]
)
def test_nearest_index_prefers_the_earlier_frame_on_a_tie(t: int, want: int) -> None:
    assert nearest_index(np.array([0, 100, 200], np.int64), t) == want


def test_nearest_on_an_empty_stream_raises() -> None:
    with pytest.raises(IndexError):
        nearest_index(np.zeros(0, np.int64), 5)


def test_two_files_with_the_same_span_are_compared_by_their_spans_only() -> None:
    """Sorting files by span compared the stamp arrays on a tie: a ValueError."""
    stamps = np.arange(10, dtype=np.int64) * 50 + 10**9
    assert "10 stamps of one file fall among another's" in stamp_stats(
        [stamps, stamps.copy()]).problems
