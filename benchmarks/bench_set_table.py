"""The frame-set list rewritten on the window's thread: time per rewrite by row count.

Offset edits, re-scoring and added sets rewrite the list. Measures, in the same run and
on the same sets (seeded, 6 cameras each), with the real Qt widget (offscreen):

- baseline ``per-cell fit``: the header in ResizeToContents mode, as the list was, where
  every cell written measures the whole table again;
- ``SetTable``: as the window rewrites it now (columns fitted once per rewrite, rows
  that show the same left alone), for a rewrite where every row changes (a new offset
  moves every set) and one where one row changes.

    python benchmarks/bench_set_table.py                 # 16, 33, 66 and 132 sets
    python benchmarks/bench_set_table.py --rows 66 --repeats 5

Prints medians and ratios; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import numpy as np  # noqa: E402
from PySide6.QtWidgets import QApplication, QHeaderView  # noqa: E402
from timing import median_ms  # noqa: E402

from app.set_table import SetTable  # noqa: E402
from speechcal_core.session.model import FrameChoice, FrameSet, Trigger  # noqa: E402


def frame_sets(n: int, shift_ns: int = 0, seed: int = 0) -> list[FrameSet]:
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        t = 1_700_000_000_000_000_000 + i * 2_700_000_000 + shift_ns
        frames = tuple(FrameChoice(f"/cam{k}/image_raw", 40 * i + k,
                                   t + int(rng.integers(0, 30_000_000)),
                                   round(float(rng.uniform(0.3, 1.0)), 3),
                                   int(rng.integers(60, 145))) for k in range(6))
        out.append(FrameSet(i + 1, t, Trigger("capture", 2.7 * i, 2.7 * i + 0.5), frames))
    return out



def alternating(first: list[FrameSet], second: list[FrameSet]):
    """A function giving ``first`` and ``second`` in turn (each rewrite changes rows)."""
    turn = iter(range(10**9))
    return lambda: first if next(turn) % 2 else second


def measure(app: QApplication, n: int, repeats: int) -> str:
    """One line of figures for ``n`` sets."""
    origin = 1_700_000_000_000_000_000
    a, b = frame_sets(n), frame_sets(n, shift_ns=130_000_000)  # every row reads otherwise
    one = [*a[:-1], a[-1].with_decision("accepted")]
    baseline, table = SetTable(), SetTable()
    for widget in (baseline, table):
        widget.resize(480, 400)
        widget.show()
    baseline.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
    next_all, next_one = alternating(a, b), alternating(one, a)

    def per_cell() -> None:
        sets = next_all()
        baseline._rows = []  # the list kept nothing: every cell written, each fit
        baseline.setRowCount(len(sets))
        for row, s in enumerate(sets):
            baseline._write_row(row, s, False)
        app.processEvents()

    def every_row() -> None:
        table.set_sets(next_all(), origin)
        app.processEvents()

    def one_row() -> None:
        table.set_sets(next_one(), origin)
        app.processEvents()

    base = median_ms(per_cell, repeats)
    ours = median_ms(every_row, repeats)
    table.set_sets(a, origin)
    single = median_ms(one_row, repeats)
    baseline.close()
    table.close()
    return (f"{n:4d} sets: baseline per-cell fit {base:8.1f} ms | SetTable every row "
            f"{ours:7.1f} ms ({base / ours:5.1f}x) | one row {single:6.1f} ms "
            f"({base / single:6.1f}x)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, nargs="+", default=[16, 33, 66, 132])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    app = QApplication.instance() or QApplication([])
    for n in args.rows:
        print(measure(app, n, args.repeats), flush=True)


if __name__ == "__main__":
    main()
