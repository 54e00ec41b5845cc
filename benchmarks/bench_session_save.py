"""Autosave of a large session: the time one save holds the review window's thread.

Every decision saves the session file on the UI thread. A session of many sets and
cameras carries each chosen frame's found corners (``frame_details``), megabytes of
JSON. Builds such a session in memory (seeded: 144 corners per frame, figures per set)
and times, in the same run:

- baseline ``indented``: the file as it was written before, ``json.dumps(indent=1)``
  (the standard library's pure-Python encoder), then the atomic write;
- ``save_session``: a line per set, json's C encoder, every line encoded;
- ``autosave``: as the window saves after a decision: ``save_session`` with the window's
  ``SessionWriter``, one set decided and its details replaced since the last save (the
  other sets' lines are re-used).

All texts must load back to the same document.

    python benchmarks/bench_session_save.py                  # 66 sets x 6 cameras
    python benchmarks/bench_session_save.py --sets 200 --cameras 12

Prints medians and their ratio; asserts nothing beyond equal documents.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np
from timing import median_ms

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from speechcal_core.fsutil import atomic_write_text  # noqa: E402
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger  # noqa: E402
from speechcal_core.session.store import (  # noqa: E402
    SessionWriter,
    save_session,
    session_to_dict,
)
from speechcal_core.sync.model import SyncModel  # noqa: E402


def big_session(sets: int, cameras: int, seed: int = 0) -> Session:
    """A session of ``sets`` sets over ``cameras`` cameras with corners for every frame."""
    rng = np.random.default_rng(seed)
    streams = [f"/cam{k}/image_raw" for k in range(cameras)]
    t0 = 1_700_000_000_000_000_000
    frame_sets, details = [], {}
    for i in range(sets):
        t = t0 + i * 2_700_000_000
        frames = tuple(FrameChoice(s, 40 * i + k, t + int(rng.integers(0, 30_000_000)),
                                   round(float(rng.uniform(0.3, 1.0)), 3), 144)
                       for k, s in enumerate(streams))
        frame_sets.append(FrameSet(i + 1, t, Trigger("capture", 2.7 * i, 2.7 * i + 0.5),
                                   frames))
        details[str(i + 1)] = {
            "trigger_ns": t, "chosen_ns": t, "method": "best-still", "score": 0.9,
            "frames": {s: {"motion": 1.0, "quality": 0.99, "still": True,
                           "ids": list(range(144)),
                           "points": np.round(rng.uniform(0, 1280, (144, 2)), 2).tolist(),
                           "stamp_ns": t} for s in streams}}
    return Session(["recording.bag"], "audio.ogg", SyncModel(t0, 0.0, "auto"), frame_sets,
                   extra={"frame_details": details})



def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=66)
    parser.add_argument("--cameras", type=int, default=6)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    session = big_session(args.sets, args.cameras)
    with tempfile.TemporaryDirectory(prefix="bench_session_save_") as tmp:
        now, before = Path(tmp) / "session.json", Path(tmp) / "indented.json"

        def indented() -> None:
            text = json.dumps(session_to_dict(session, before), indent=1,
                              ensure_ascii=False) + "\n"
            atomic_write_text(before, text, keep_backup=True)

        base = median_ms(indented, args.repeats)
        ours = median_ms(lambda: save_session(session, now), args.repeats)
        same = json.loads(now.read_text()) == json.loads(before.read_text())
        size = now.stat().st_size / 1e6
        writer, details = SessionWriter(), session.extra["frame_details"]
        save_session(session, now, writer)
        decided = iter(range(10 ** 9))

        def autosave() -> None:
            frame_set = session.sets[next(decided) % len(session.sets)]
            session.replace_set(frame_set.with_decision("accepted"))
            details[str(frame_set.id)] = dict(details[str(frame_set.id)])  # replaced
            save_session(session, now, writer)

        auto = median_ms(autosave, args.repeats)
        same = same and json.loads(now.read_text()) == session_to_dict(session, now)
    print(f"{args.sets} sets x {args.cameras} cameras, {size:.1f} MB session file; "
          f"median of {args.repeats}")
    print(f"baseline indented (indent=1): {base:7.1f} ms per save")
    print(f"save_session:                 {ours:7.1f} ms per save  "
          f"({base / ours:.1f}x faster)")
    print(f"autosave (one set changed):   {auto:7.1f} ms per save  "
          f"({base / auto:.1f}x faster; same documents: {same})")


if __name__ == "__main__":
    main()
