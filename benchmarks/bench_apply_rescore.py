"""Re-scored sets taken into the session (UI thread, when re-scoring ends), by set count.

A long calibration (30 minutes, a trigger every 5-6 s) holds 300-400 sets, and an offset
edit re-scores every one of them. Measures, on the same synthetic sets (3 cameras each),
``apply_rescore`` as it is against the baseline it replaced, which looked each result set
up by a search through the session's sets (quadratic in the set count).

    python benchmarks/bench_apply_rescore.py                 # 50, 300 and 1000 sets
    python benchmarks/bench_apply_rescore.py --sets 300 --repeats 9

Prints medians and ratios; asserts nothing.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from timing import median_ms  # noqa: E402

from speechcal_core.review.rescore import RescoreResult, apply_rescore  # noqa: E402
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger  # noqa: E402
from speechcal_core.sync.model import SyncModel  # noqa: E402


def session(n: int) -> Session:
    sync = SyncModel(offset_ns=1_700_000_000_000_000_000)
    sets = []
    for i in range(n):
        trigger = Trigger("capture", 6.0 * i, 6.0 * i + 0.5)
        t = int(sync.to_session(trigger.t_s))
        frames = tuple(FrameChoice(f"/cam{k}/image_raw", 180 * i + k, t + k) for k in range(3))
        sets.append(FrameSet(i + 1, t, trigger, frames))
    return Session(["recording.bag"], "audio.ogg", sync, sets, extra={"frame_details": {}})


def baseline(s: Session, result: RescoreResult) -> None:
    """apply_rescore's lookup as it was: a search through the sets per result set."""
    for new in result.sets:
        index = next((i for i, x in enumerate(s.sets) if x.id == new.id), -1)
        if index >= 0 and s.sets[index].trigger == new.trigger:
            s.sets[index] = replace(s.sets[index], t_ns=new.t_ns, frames=new.frames)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, nargs="+", default=[50, 300, 1000])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    for n in args.sets:
        s = session(n)
        result = RescoreResult(s.sync, tuple(s.sets))
        base = median_ms(lambda: baseline(s, result), args.repeats)  # noqa: B023
        ours = median_ms(lambda: apply_rescore(s, result), args.repeats)  # noqa: B023
        print(f"{n:5d} sets: baseline search per set {base:8.2f} ms | apply_rescore "
              f"{ours:7.2f} ms ({base / ours:5.1f}x)", flush=True)


if __name__ == "__main__":
    main()
