"""How long a usage error or ``--help`` takes, against the heavy imports it used to wait for.

Each case runs the console script's ``main`` in a fresh Python process ``--runs`` times
and prints the median wall time. The baseline, measured in the same run, is the same
command with the modules the command's ``run`` imported before checking its options (as
it did before those checks came first) imported ahead of ``main``.

    .venv/bin/python benchmarks/bench_cli_usage.py [--runs 7]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: what each command's run() imported before its first option check, before the change
SYNTH = ["speechcal_core.synth.session"]
SYNC = ["speechcal_core.sources", "speechcal_core.sync.manual", "speechcal_core.sync.pipeline",
        "speechcal_core.sync.sources"]
AUDIO = ["scipy.signal"]  # the audio package imported scipy.signal with itself
CASES = [
    (["synth", "OUT", "--cameras", "20"], SYNTH),
    (["synth", "OUT", "--size", "12"], SYNTH),
    (["sync", "REC.bag", "--audio", "A.ogg", "--search-s", "-1"], SYNC),
    (["process", "REC.bag", "-o", "S.json"], AUDIO),
    (["review", "REC.bag"], AUDIO),
    (["synth"], []),
    (["synth", "OUT", "--bogus"], []),
    (["synth", "--help"], []),
    (["process", "--help"], []),
]


def _median_s(argv: list[str], preload: list[str], runs: int) -> tuple[float, int]:
    probe = ("import sys\n" + "".join(f"import {m}\n" for m in preload)
             + "from speechcal_core.cli import main\n"
             "try:\n    code = main(sys.argv[1:])\nexcept SystemExit as exc:\n"
             "    code = exc.code\nsys.exit(code)\n")
    times, code = [], 0
    for _ in range(runs):
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-c", probe, *argv], capture_output=True)
        times.append(time.perf_counter() - t0)
        code = p.returncode
    return statistics.median(times), code


def main() -> int:
    """Time every case and its baseline; print one JSON line each, then the medians."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=7)
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for argv, preload in CASES:
            argv = [str(Path(tmp) / a) if a in ("OUT", "REC.bag", "A.ogg", "S.json") else a
                    for a in argv]
            new_s, code = _median_s(argv, [], args.runs)
            row = {"command": " ".join(a.replace(tmp + "/", "") for a in argv),
                   "exit": code, "median_s": round(new_s, 3)}
            if preload:
                old_s, old_code = _median_s(argv, preload, args.runs)
                row.update(baseline_median_s=round(old_s, 3), baseline_exit=old_code,
                           ratio=round(old_s / new_s, 1))
            rows.append(row)
            print(json.dumps(row), flush=True)
    print(json.dumps({"baseline": "the modules run() imported before its option checks, "
                      "imported first", "runs": args.runs,
                      "median_s": round(statistics.median(r["median_s"] for r in rows), 3),
                      "median_ratio": statistics.median(r["ratio"] for r in rows
                                                        if "ratio" in r)}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
