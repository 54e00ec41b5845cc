"""The waveform's frame-set marks on the window's thread: time to show the sets by count.

Opening a session marks every set; an offset edit (each step of a held ``]``) moves every
mark; adding a set (T, "find more like this") or removing one changes one. Measures, in
the same run, on the same sets and the real pyqtgraph widget (offscreen), each followed
by a repaint of the view:

- baseline ``items``: a pyqtgraph region and text item per set, as the waveform drew
  them before (made when a set appears, moved on an offset edit);
- ``set_sets``: as the window calls it now (two items paint every mark).

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
from collections.abc import Callable
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import pyqtgraph as pg  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from timing import median_ms  # noqa: E402

from app.style import BACKGROUND, DECISION_COLOURS, DECISION_SYMBOLS  # noqa: E402
from app.waveform import WaveformView  # noqa: E402
from speechcal_core.session.model import FrameSet, Trigger  # noqa: E402
from speechcal_core.sync.model import SyncModel  # noqa: E402


def frame_sets(n: int) -> list[FrameSet]:
    """``n`` sets, one word every 2.7 s (the session clock is the audio's)."""
    return [FrameSet(i + 1, int((2.7 * i + 1.25) * 1e9),
                     Trigger("capture", 2.7 * i + 1.0, 2.7 * i + 1.5), ())
            for i in range(n)]


class ItemPerSet:
    """The baseline: a region and a label item per set on ``view``, placed as before."""

    def __init__(self, view: WaveformView) -> None:
        self.view = view
        self.items: dict[int, tuple[pg.LinearRegionItem, pg.TextItem]] = {}

    def show(self, sets: list[FrameSet], offset_s: float = 0.0) -> None:
        wanted = {s.id for s in sets}
        for set_id in [i for i in self.items if i not in wanted]:
            for item in self.items.pop(set_id):
                self.view.removeItem(item)
        for s in sets:
            if s.id not in self.items:
                region = pg.LinearRegionItem(movable=False)
                label = pg.TextItem("", anchor=(0.5, 0.0), fill=pg.mkBrush(BACKGROUND))
                for item in (region, label):
                    self.view.addItem(item, ignoreBounds=True)
                self.items[s.id] = (region, label)
            region, label = self.items[s.id]
            start, end = s.trigger.start_s + offset_s, s.trigger.end_s + offset_s
            region.setRegion((start, end))
            label.setPos((start + end) / 2, 1.0)
            colour = DECISION_COLOURS[s.decision]
            region.setBrush(pg.mkBrush(colour.red(), colour.green(), colour.blue(), 70))
            for line in region.lines:
                line.setPen(pg.mkPen(colour))
            label.setText(f"{DECISION_SYMBOLS[s.decision]}{s.id}", color=colour.lighter(140))

    def clear(self) -> None:
        self.show([])


def measure(app: QApplication, n: int, repeats: int) -> str:
    """Two lines of figures for ``n`` sets: the baseline's and set_sets'."""
    sets = frame_sets(n)
    added = [*sets, FrameSet(n + 1, 500_000_000, Trigger("capture", 0.4, 0.6), ())]
    view = WaveformView(0)
    view.resize(1400, 200)
    view.show()
    view.sync = SyncModel(0)
    view.setXRange(0, 2.7 * n + 2, padding=0)
    app.processEvents()

    def shown(action: Callable[[], object]) -> Callable[[], None]:
        def run() -> None:
            action()
            app.processEvents()
            view.viewport().repaint()
        return run

    baseline = ItemPerSet(view)
    turn = iter(range(10**9))
    figures = {}
    for name, show, clear in (
            ("baseline items", baseline.show, baseline.clear),
            ("set_sets", lambda s, offset_s=0.0: (
                setattr(view, "sync", SyncModel(round(offset_s * 1e9))), view.set_sets(s)),
             lambda: view.set_sets([]))):
        opened = []
        for _ in range(repeats):
            clear()
            app.processEvents()
            start = time.perf_counter()
            shown(lambda show=show: show(sets))()
            opened.append((time.perf_counter() - start) * 1000)
        step = median_ms(shown(lambda show=show: show(sets, next(turn) * 0.001)), repeats)
        one = median_ms(shown(lambda show=show: show(added if next(turn) % 2 else sets)),
                        repeats)
        clear()
        figures[name] = (statistics.median(opened), step, one)
    view.hide()
    view.deleteLater()
    (b_open, b_step, b_one), (n_open, n_step, n_one) = figures.values()
    return (f"{n:4d} sets: baseline items  open {b_open:7.1f} ms, offset step {b_step:6.1f} ms, "
            f"one added/removed {b_one:6.1f} ms\n"
            f"           set_sets        open {n_open:7.1f} ms ({b_open / n_open:5.1f}x), "
            f"offset step {n_step:6.1f} ms ({b_step / n_step:5.1f}x), one added/removed "
            f"{n_one:6.1f} ms ({b_one / n_one:5.1f}x)")


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
