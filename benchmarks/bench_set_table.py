"""The frame-set list and the waveform in the real review window (offscreen): UI-thread
time by set count.

A 30-minute calibration holds about 300 sets; the list is rewritten and every word mark
on the waveform moves on every offset edit (each step of a held ``}``), the list is
rewritten at the end of re-scoring and on opening, one row and one mark change on a
decision, and a filter hides rows. Opens seeded sessions of 50, 300 and 1000 sets
over one synthetic recording (4 cameras; seeded figures, warnings and decisions) in the
real window as it is (``window``) and, in the same run, with one of two named baselines:

- ``list baseline``: the ``QTableWidget`` list the list replaced (``widget_set_table.py``,
  a QTableWidget item per cell);
- ``marks baseline``: the waveform's word marks (``baseline_word_marks.py``: every change
  repaints the whole view) and the model's part of offset edits and of finding the set
  at the playhead (``baseline_review_model.py``) as at commit c098894;

and measures per action, each followed by the repaint it asks for:

- ``offset``: ``}`` / ``{`` (every row changes: time, nearest frames, "…");
- ``marks``: the "…" of re-scoring on every row and off again, as at the end of
  re-scoring (``refresh_rescore_marks``);
- ``decision``: ``A``, ``R``, ``U``, ``U`` in turn on an undecided set (one row changes;
  "then next set" off);
- ``next``: ``A``, ``U`` in turn with "then next set" on, as the window starts (the
  current set changes too);
- ``filter``: ``F`` (all, undecided, accepted, rejected, all: rows hidden and shown);
- ``open``: opening the session file, the window's thread only (building the review
  page once the worker has loaded the session).

Each figure is the window's whole action and the shares of the list (time inside the
list's methods and its repaints), of the waveform (inside its methods and its repaints)
and of the model's parts above, as wall time and, in brackets, as CPU time of the
window's thread (which other programs' load on the machine disturbs less); a baseline's
line ends with its ratio to the window's (whole action, and the share it replaces).
``--busy`` runs a pure-Python thread beside it, as a re-scoring or a calibration check
holds the GIL on the window's machine: every call between Python and Qt may then wait
for the GIL (up to a switch interval, 5 ms).
Background work the actions schedule (re-scoring, the calibration check) is kept from
starting, so that the figures are the window's own.

    python benchmarks/bench_set_table.py                 # 50, 300 and 1000 sets
    python benchmarks/bench_set_table.py --sets 300 --repeats 9 --busy
    python benchmarks/bench_set_table.py --sets 300 --baselines marks --rounds 3
    python benchmarks/bench_set_table.py --data /tmp/bench-list   # keep the recording

``--rounds`` measures the window and its baselines in turn that many times (the
medians are over all rounds), so that the machine's load falls on each alike.

Prints medians and ratios (baseline / window); asserts nothing.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import os
import shutil
import statistics
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
REPO = Path(__file__).resolve().parents[1]
for path in (REPO, REPO / "benchmarks"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

import numpy as np  # noqa: E402
from baseline_review_model import model_as_before  # noqa: E402
from baseline_word_marks import WordMarks as BaselineWordMarks  # noqa: E402
from bench_data import session_folder  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from widget_set_table import WidgetSetTable  # noqa: E402

import app.main_window as main_window  # noqa: E402
import app.waveform as waveform  # noqa: E402
from app.set_table import SetTable  # noqa: E402
from app.word_marks import WordMarks  # noqa: E402
from speechcal_core.frames.nearest import nearest_frame_sets  # noqa: E402
from speechcal_core.review.model import ReviewModel  # noqa: E402
from speechcal_core.session.model import Session, Trigger  # noqa: E402
from speechcal_core.session.store import save_session  # noqa: E402
from speechcal_core.sources import open_recording  # noqa: E402
from speechcal_core.sync.model import SyncModel  # noqa: E402
from speechcal_core.synth.options import SynthOptions  # noqa: E402
from speechcal_core.synth.session import generate_session  # noqa: E402

DURATION_S = 150.0
CAMERAS = 4


def make_recording(folder: Path) -> dict:
    """The synthetic recording every session of the benchmark uses."""
    print(f"making a {DURATION_S:.0f} s recording of {CAMERAS} cameras…", file=sys.stderr)
    return generate_session(folder, SynthOptions(cameras=CAMERAS, duration=DURATION_S,
                                                 width=320, height=240, seed=7), force=True)


def make_session(folder: Path, truth: dict, n: int, out: Path) -> Path:
    """A session of ``n`` sets spread over the recording: nearest frames with seeded
    figures (some flagged), words (some added or found alike) and decisions."""
    rng = np.random.default_rng(n)
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")
    start, end = 2.0, DURATION_S - 3.0
    step = (end - start) / n
    triggers = []
    for i in range(n):
        t = start + step * (i + float(rng.uniform(0.1, 0.4)))
        source = str(rng.choice(["detected", "manual", "similar"], p=[0.9, 0.05, 0.05]))
        triggers.append(Trigger("capture", t - 0.2, t + 0.2, 1.0, source))
    recording = str(folder / truth["recording"])
    with open_recording([recording]) as source:
        sets = nearest_frame_sets(source, sync, triggers)
    seeded = []
    for s in sets:
        frames = []
        for f in s.frames:
            sharp = round(float(rng.uniform(0.45, 1.1)), 3)
            corners = int(rng.integers(20, 145))
            flags = (("blurred",) if sharp < 0.7 else ()) + (("no-target",) if corners < 24
                                                              else ())
            frames.append(replace(f, sharpness=sharp, corners=corners, flags=flags)
                          if f.index >= 0 else f)
        decision = str(rng.choice(["accepted", "rejected", "undecided"], p=[0.4, 0.15, 0.45]))
        seeded.append(replace(s, frames=tuple(frames), decision=decision))
    session = Session([recording], str(folder / truth["audio"]), sync, seeded,
                      sync_evidence={"claps": truth["claps"]})
    save_session(session, out)
    return out


class _Share:
    """Time spent inside one part of the window (outermost calls only), for its share:
    wall and the window's thread's CPU time."""

    def __init__(self) -> None:
        self.seconds = self.cpu = 0.0
        self.depth = 0

    @contextlib.contextmanager
    def inside(self):
        self.depth += 1
        start, cpu = time.perf_counter(), time.thread_time()
        try:
            yield
        finally:
            self.depth -= 1
            if self.depth == 0:
                self.seconds += time.perf_counter() - start
                self.cpu += time.thread_time() - cpu

    def reset(self) -> None:
        self.seconds = self.cpu = 0.0


#: the parts whose shares are measured
SHARES = {"list": _Share(), "waveform": _Share(), "model": _Share()}
_COPIES = itertools.count()
#: the window-facing methods of each part (the list's and the waveform's repaints too)
TIMED = {"list": ("set_sets", "update_row", "show_rows", "select_row"),
         "waveform": ("set_sets", "update_set", "set_sync", "set_claps", "set_playhead"),
         "marks": ("set_current",),
         "model": ("_follow_sync", "set_at_playhead")}


def _counted(share: _Share, real: Callable) -> Callable:
    def method(self, *args, **kwargs):
        with share.inside():
            return real(self, *args, **kwargs)
    return method


def timed_class(base: type, part: str = "list", share: str | None = None) -> type:
    """``base`` with the methods :data:`TIMED` names for ``part`` (and its repaints, if
    a widget) counted in the share ``share`` (default ``part``)."""
    counted = SHARES[share or part]
    methods = {name: _counted(counted, getattr(base, name)) for name in TIMED[part]}
    if hasattr(base, "paintEvent"):
        methods["paintEvent"] = _counted(counted, base.paintEvent)
    return type(f"Timed{base.__name__}", (base,), methods)


@dataclass(frozen=True)
class Variant:
    """The window as measured: its list, its waveform's word marks, and whether the
    model does its offset-edit part as at the marks' baseline."""

    table: type
    marks: type
    model_before: bool = False


VARIANTS = {"window": Variant(SetTable, WordMarks),
            "list baseline": Variant(WidgetSetTable, WordMarks),
            "marks baseline": Variant(SetTable, BaselineWordMarks, model_before=True)}
#: the share each baseline replaces, for its ratio
REPLACED = {"list baseline": "list", "marks baseline": "waveform"}


def reset_shares() -> None:
    for share in SHARES.values():
        share.reset()


def share_figures() -> tuple[float, ...]:
    """Every share's wall and CPU ms since :func:`reset_shares`."""
    return tuple(ms for share in SHARES.values()
                 for ms in (share.seconds * 1000, share.cpu * 1000))


def settle(app: QApplication, window) -> None:
    """Let the window repaint what the action changed; keep background work from
    starting (re-scoring, the calibration check)."""
    app.processEvents()
    app.processEvents()
    for action in (window.rescorer, window.checker):
        action.timer.stop()


Figures = tuple[float, ...]  # ms: wall, CPU, then each share's wall, CPU (SHARES' order)


def medians(runs: list[Figures]) -> Figures:
    """Each column's median over ``runs``."""
    return tuple(statistics.median(column) for column in zip(*runs, strict=True))


def measure(app: QApplication, window, action: Callable[[], object],
            repeats: int) -> list[Figures]:
    """Every run of ``action`` (with its repaint) and the shares of it."""
    runs = []
    for _ in range(repeats):
        settle(app, window)
        reset_shares()
        start, cpu = time.perf_counter(), time.thread_time()
        action()
        settle(app, window)
        runs.append(((time.perf_counter() - start) * 1000, (time.thread_time() - cpu) * 1000,
                     *share_figures()))
    return runs


def open_window(app: QApplication, path: Path, variant: Variant):
    """A shown window with ``path`` open; (window, :data:`Figures` of the window's thread
    building the review page)."""
    main_window.SetTable = timed_class(variant.table)
    main_window.WaveformView = timed_class(waveform.WaveformView, "waveform")
    waveform.WordMarks = timed_class(variant.marks, "marks", "waveform")
    main_window.ReviewModel = timed_class(ReviewModel, "model")  # as the variant has it
    window = main_window.ReviewWindow()
    window.setProperty("headless", True)
    window.resize(1400, 900)
    window.show()
    built: list[float] = []
    real = window._on_loaded

    def on_loaded(inputs) -> None:
        reset_shares()
        start, cpu = time.perf_counter(), time.thread_time()
        real(inputs)
        app.processEvents()  # the first paint of the page
        built.append(((time.perf_counter() - start) * 1000,
                      (time.thread_time() - cpu) * 1000, *share_figures()))

    window._on_loaded = on_loaded
    fresh = path.with_name(f"{path.stem}-{next(_COPIES)}.json")  # the file as made: the
    shutil.copyfile(path, fresh)  # window saves decisions, offsets and its place in it
    window.open(session_path=str(fresh))
    deadline = time.monotonic() + 120
    while not built and time.monotonic() < deadline:
        app.processEvents()
        time.sleep(0.002)
    if not built:
        raise SystemExit(f"{path} did not open")
    settle(app, window)
    return window, built[0]


def close_window(app: QApplication, window) -> None:
    window.close()
    window.deleteLater()
    app.processEvents()


def run_variant(app: QApplication, path: Path, variant: Variant, repeats: int) -> dict:
    """Every action's runs (:data:`Figures`) in the window as ``variant``."""
    with model_as_before(ReviewModel) if variant.model_before else contextlib.nullcontext():
        return _run_actions(app, path, variant, repeats)


def _run_actions(app: QApplication, path: Path, variant: Variant, repeats: int) -> dict:
    opened = []
    for _ in range(max(1, repeats // 3)):  # opening is slow: fewer repeats
        window, figures = open_window(app, path, variant)
        opened.append(figures)
        close_window(app, window)
    window, _figures = open_window(app, path, variant)
    model = window.model
    window.advance_box.setChecked(False)  # decisions stay on the set
    sets = model.session.sets
    model.go_to_set(next(i for i in range(len(sets) // 2, len(sets))
                         if sets[i].decision == "undecided"))
    settle(app, window)
    turn = iter(range(10**9))
    figures = {"open": opened}
    figures["offset"] = measure(app, window, lambda: window.run_action(
        ("offset_plus_frame", "offset_minus_frame")[next(turn) % 2]), repeats)

    def marks() -> None:
        window.rescorer.held = not window.rescorer.held  # held: no "…" shown
        window.refresh_rescore_marks()
    figures["marks"] = measure(app, window, marks, repeats)
    decisions = iter(range(10**9))
    figures["decision"] = measure(app, window, lambda: window.run_action(
        ("accept", "reject", "undo", "undo")[next(decisions) % 4]), repeats)
    window.advance_box.setChecked(True)  # as the window starts: on to the next set
    figures["next"] = measure(app, window, lambda: window.run_action(
        ("accept", "undo")[next(decisions) % 2]), repeats)
    window.advance_box.setChecked(False)
    figures["filter"] = measure(app, window, lambda: window.run_action("next_filter"),
                                repeats)
    close_window(app, window)
    return figures


@contextlib.contextmanager
def busy_thread(on: bool):
    """A pure-Python thread holding the GIL as a worker does, while ``on``."""
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            sum(i * i for i in range(2000))

    thread = threading.Thread(target=spin, daemon=True)
    if on:
        thread.start()
    try:
        yield
    finally:
        stop.set()
        if on:
            thread.join()


ACTIONS = ("offset", "marks", "decision", "next", "filter", "open")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, nargs="+", default=[50, 300, 1000])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--rounds", type=int, default=1,
                        help="measure the window and its baselines in turn this many times")
    parser.add_argument("--busy", action="store_true",
                        help="a pure-Python thread runs beside the window (GIL contention)")
    parser.add_argument("--baselines", nargs="*", choices=("list", "marks"),
                        default=["list", "marks"],
                        help="the named baselines to measure beside the window (none: "
                             "the window only)")
    parser.add_argument("--data", help="folder of the recording (made there once, kept)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary recording")
    args = parser.parse_args()
    app = QApplication.instance() or QApplication([])
    names = ["window"] + [f"{b} baseline" for b in args.baselines]
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; "
          f"{'a busy Python thread beside' if args.busy else 'no other thread busy'}; "
          f"median of {args.repeats} x {args.rounds} round(s) (open: "
          f"{max(1, args.repeats // 3)} x {args.rounds}); ms of the window's action, wall "
          "(CPU of its thread), then the shares of the list, the waveform and the model's "
          "parts", flush=True)
    with session_folder(args.data, args.keep, make_recording) as (folder, truth), \
            tempfile.TemporaryDirectory(prefix="speechcal-bench-list-") as tmp:
        for n in args.sets:
            path = make_session(folder, truth, n, Path(tmp) / f"sets{n}.json")
            runs: dict[str, dict[str, list[Figures]]] = {
                name: {action: [] for action in ACTIONS} for name in names}
            for _round in range(args.rounds):
                for name in names:
                    with busy_thread(args.busy):
                        done = run_variant(app, path, VARIANTS[name], args.repeats)
                    for action in ACTIONS:
                        runs[name][action] += done[action]
            for action in ACTIONS:
                for k, name in enumerate(names):
                    print(figures_line(n, action if k == 0 else "", name,
                                       medians(runs[name][action]),
                                       medians(runs["window"][action])), flush=True)
            print(f"      (load average {os.getloadavg()[0]:.1f})", flush=True)


def figures_line(n: int, action: str, name: str, figures: Figures, window: Figures) -> str:
    """One line of the table: ``name``'s figures for ``action``, and a baseline's ratios
    to the window's (whole action, and the share it replaces)."""
    wall, cpu, *shares = figures
    line = f"{n:5d} sets  {action:8s} {name:14s} {wall:6.1f} ({cpu:6.1f})"
    for k, share in enumerate(SHARES):
        line += f" | {share} {shares[2 * k]:5.1f} ({shares[2 * k + 1]:5.1f})"
    if name in REPLACED:
        k = 2 + 2 * list(SHARES).index(REPLACED[name])
        ratios = [figures[i] / max(window[i], 1e-3) for i in (0, 1, k, k + 1)]
        line += " | x{:4.1f} ({:4.1f}) [{}: x{:4.1f} ({:4.1f})]".format(
            *ratios[:2], REPLACED[name], *ratios[2:])
    return line


if __name__ == "__main__":
    main()
