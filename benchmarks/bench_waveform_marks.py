"""The waveform's frame-set marks on the window's thread: time to show the sets by count.

Opening a session makes every set's mark; adding a set (T, "find more like this") or
removing one changes one. Measures, in the same run and on the same sets, with the real
pyqtgraph widget (offscreen):

- baseline ``rebuild``: every mark taken away and made again for the new list of sets,
  as the waveform did on every set added or removed;
- ``set_sets``: as the window calls it now, for a session opened (every mark new) and
  for one set added or removed (the other marks kept and moved).

    python benchmarks/bench_waveform_marks.py              # 50, 105, 200 and 400 sets
    python benchmarks/bench_waveform_marks.py --sets 105 --repeats 7

Prints medians and ratios; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from PySide6.QtWidgets import QApplication  # noqa: E402
from timing import median_ms  # noqa: E402

from app.waveform import WaveformView  # noqa: E402
from speechcal_core.session.model import FrameSet, Trigger  # noqa: E402
from speechcal_core.sync.model import SyncModel  # noqa: E402


def frame_sets(n: int) -> list[FrameSet]:
    """``n`` sets, one word every 2.7 s (the session clock is the audio's)."""
    return [FrameSet(i + 1, int((2.7 * i + 1.25) * 1e9),
                     Trigger("capture", 2.7 * i + 1.0, 2.7 * i + 1.5), ())
            for i in range(n)]


def measure(app: QApplication, n: int, repeats: int) -> str:
    """One line of figures for ``n`` sets."""
    sets = frame_sets(n)
    added = [*sets, FrameSet(n + 1, 500_000_000, Trigger("capture", 0.4, 0.6), ())]
    view = WaveformView(0)
    view.resize(1400, 200)
    view.show()
    view.sync = SyncModel(0)
    turn = iter(range(10**9))

    def rebuild() -> None:
        view.set_sets([])
        view.set_sets(added if next(turn) % 2 else sets)
        app.processEvents()

    def open_() -> float:
        view.set_sets([])  # not timed: the marks of a session shown before
        app.processEvents()
        start = time.perf_counter()
        view.set_sets(sets)
        app.processEvents()
        return (time.perf_counter() - start) * 1000

    def add_or_remove() -> None:
        view.set_sets(added if next(turn) % 2 else sets)
        app.processEvents()

    base = median_ms(rebuild, repeats)
    opened = statistics.median(open_() for _ in range(repeats))
    view.set_sets(sets)
    one = median_ms(add_or_remove, repeats)
    view.hide()
    view.deleteLater()
    return (f"{n:4d} sets: baseline rebuild {base:7.1f} ms | set_sets: open {opened:7.1f} ms, "
            f"one set added or removed {one:6.1f} ms ({base / one:5.1f}x)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, nargs="+", default=[50, 105, 200, 400])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    app = QApplication.instance() or QApplication([])
    for n in args.sets:
        print(measure(app, n, args.repeats), flush=True)


if __name__ == "__main__":
    main()
