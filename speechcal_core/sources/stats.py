"""Stamp statistics of a stream: ordering problems, median period, dropped frames."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from speechcal_core.text import counted

#: what the problems say of a stream that starts at or before 0
UNSET_STAMPS = "zero or negative stamps (header stamps not set?)"
#: what the problems say of a stream whose files interleave (two takes given as one)
ANOTHER_RECORDING = "another recording given too?"
#: a stamp given by hand or by a file's name beyond this (the year 2116) is no header
#: stamp: a digit too many overflowed int64, or left the stamps after it no room
MAX_STAMP_NS = 2**62
#: how to write a header stamp, said where one is beyond :data:`MAX_STAMP_NS`
STAMP_FORM = "nanoseconds since 1970, e.g. 1700000000000000000 (19 digits)"


@dataclass(frozen=True)
class StampStats:
    """Summary of one stream's header stamps after sorting."""

    order: np.ndarray  # permutation that sorts the stamps in storage order (stable)
    stamps: np.ndarray  # sorted int64 stamps
    median_period_ns: int
    nominal_rate_hz: float
    dropped: int
    problems: str


def stamp_stats(parts: Sequence[np.ndarray], *, unset_out: bool = False) -> StampStats:
    """Sort stamps (stable) and describe ordering problems, period and dropped frames.

    ``parts`` are the stamps of each file in storage order; out-of-order stamps are
    counted within a file (split bags may be given in any order). With ``unset_out``,
    zero or negative stamps among positive ones (header stamps a driver did not set) are
    left out of ``order`` and ``stamps``: they would put a frame decades before the rest.
    """
    arrays = [np.asarray(p, dtype=np.int64) for p in parts]
    raw = np.concatenate(arrays) if arrays else np.zeros(0, np.int64)
    problems: list[str] = []
    unset = int(np.count_nonzero(raw <= 0)) if unset_out else 0
    if 0 < unset < raw.size:
        keep = np.flatnonzero(raw > 0)
        arrays = [a[a > 0] for a in arrays]
        problems.append(f"{counted(unset, 'frame')} with a zero or negative header stamp "
                        "left out (not set by the camera driver?)")
    else:
        keep = np.arange(raw.size)
    backwards = sum(int(np.count_nonzero(np.diff(a) < 0)) for a in arrays)
    order = keep[np.argsort(raw[keep], kind="stable")]
    stamps = raw[order]
    if backwards:
        problems.append(f"{counted(backwards, 'stamp')} out of order (sorted)")
    diffs = np.diff(stamps)
    duplicates = int(np.count_nonzero(diffs == 0))
    if duplicates:
        problems.append(f"{counted(duplicates, 'duplicate stamp')} (kept)")
    interleaved = _interleaved(arrays)
    if interleaved:
        problems.append(f"{counted(interleaved, 'stamp')} of one file fall among another's "
                        f"({ANOTHER_RECORDING} split bags follow each other)")
    if raw.size and int(stamps[0]) <= 0:
        problems.append(UNSET_STAMPS)
    positive = diffs[diffs > 0]
    median = int(np.median(positive)) if positive.size else 0
    dropped = 0
    if median > 0:
        long_gaps = positive[positive > 1.5 * median]
        dropped = int(np.sum(np.rint(long_gaps / median).astype(np.int64) - 1))
    rate = round(1e9 / median, 3) if median > 0 else 0.0
    return StampStats(order, stamps, median, rate, dropped, "; ".join(problems))


#: files of one stream may overlap this many stamps at their seam (a split while writing)
SEAM_STAMPS = 5


def _interleaved(arrays: Sequence[np.ndarray]) -> int:
    """How many stamps of the files fall inside another file's span beyond a seam's
    few: split bags of one recording follow each other, two recordings overlap."""
    spans = sorted(((int(a.min()), int(a.max()), a) for a in arrays if a.size),
                   key=lambda span: span[:2])  # arrays do not compare
    inside = 0
    for k, (lo, hi, _a) in enumerate(spans):
        for lo2, _hi2, b in spans[k + 1:]:
            if lo2 > hi:
                break
            n = int(np.count_nonzero((b >= lo) & (b <= hi)))
            inside += n if n > SEAM_STAMPS else 0
    return inside


def nearest_index(stamps: np.ndarray, t_ns: int) -> int:
    """Index of the stamp nearest to ``t_ns`` (the earlier one on a tie)."""
    n = stamps.size
    if n == 0:
        raise IndexError("stream has no frames")
    j = int(np.searchsorted(stamps, t_ns, side="left"))
    if j <= 0:
        return 0
    if j >= n:
        return n - 1
    before = t_ns - int(stamps[j - 1])
    after = int(stamps[j]) - t_ns
    return j - 1 if before <= after else j
