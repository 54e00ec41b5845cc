"""Time ``speechcal synth`` on the issue's session: 120 s, 4 cameras, 640x480, default options.

Runs the whole session (recording + audio + truth) when the orchestrator is available,
and the video side (``write_recording``) alone, each ``--repeat`` times in a temporary
folder (deleted afterwards), and prints median wall time, CPU time (this process and its
workers), frame counts and the per-frame render cost. Also prints the load average,
since other work on the machine stretches wall time.

    python benchmarks/bench_synth.py               # the issue's session, 3 repeats
    python benchmarks/bench_synth.py --repeat 1 --duration 30

Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


def _cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _measure(label: str, run, repeat: int) -> None:
    walls, cpus = [], []
    frames = 0
    for _ in range(repeat):
        tmp = Path(tempfile.mkdtemp(prefix="speechcal-bench-synth-"))
        try:
            cpu0, t0 = _cpu_s(), time.perf_counter()
            frames = run(tmp / "session")
            walls.append(time.perf_counter() - t0)
            cpus.append(_cpu_s() - cpu0)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    med_wall, med_cpu = statistics.median(walls), statistics.median(cpus)
    print(f"{label:28s} median wall {med_wall:6.1f} s  (runs: "
          f"{', '.join(f'{w:.1f}' for w in walls)})  cpu {med_cpu:6.1f} s  "
          f"frames {frames}  cpu/frame {1e3 * med_cpu / max(frames, 1):.2f} ms", flush=True)


def _render_cost(options, samples: int = 150) -> None:
    """Single-thread render time per frame of camera 0, still and moving frames apart."""
    import cv2
    import numpy as np

    from speechcal_core.synth.image_messages import encode_pixels
    from speechcal_core.synth.render import FrameRenderer
    from speechcal_core.synth.timeline import plan_session

    cv2.setNumThreads(1)
    tl = plan_session(options)
    renderer = FrameRenderer(tl)
    t0 = time.perf_counter()
    renderer.render(0, tl.start_ns)
    setup = time.perf_counter() - t0
    for kind in ("still", "move"):
        segs = [s for s in tl.segments if s.is_hold == (kind == "still")]
        times = np.concatenate([np.linspace(s.start_ns, min(s.end_ns, tl.end_ns), 12)[1:-1]
                                for s in segs]).astype(np.int64)[:samples]
        t0 = time.perf_counter()
        for t in times:
            renderer.render(0, int(t))
        render_ms = (time.perf_counter() - t0) / len(times) * 1e3
        frame = renderer.render(0, int(times[0]))
        t0 = time.perf_counter()
        for _ in range(30):
            encode_pixels(frame, options.encoding)
        enc_ms = (time.perf_counter() - t0) / 30 * 1e3
        print(f"render camera 0, {kind:5s} frames: {render_ms:.2f} ms/frame "
              f"(+ {options.encoding} encode {enc_ms:.2f} ms); camera setup {setup:.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--cameras", type=int, default=4)
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()

    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.recording_writer import write_recording
    from speechcal_core.synth.timeline import plan_session

    width, height = (int(v) for v in args.size.split("x"))
    options = SynthOptions(cameras=args.cameras, duration=args.duration, width=width,
                           height=height)
    print(f"session: {args.duration:g} s, {args.cameras} cameras, {width}x{height}, "
          f"{options.format}, {options.encoding}; cores {os.cpu_count()}, "
          f"load average {', '.join(f'{v:.1f}' for v in os.getloadavg())}", flush=True)

    def video(out: Path) -> int:
        truth = write_recording(plan_session(options), out, workers=args.workers)
        return sum(len(v) for v in truth.stamps.values())

    try:
        from speechcal_core.synth.session import generate_session
    except ImportError as exc:  # the orchestrator is not there yet
        print(f"whole session: skipped ({exc})")
    else:
        def whole(out: Path) -> int:
            truth = generate_session(out, options)
            return sum(c.get("count", 0) for c in truth.get("cameras", []))

        _measure("whole session (video+audio)", whole, args.repeat)
    _measure("video only (write_recording)", video, args.repeat)
    _render_cost(options)
    print(f"load average after: {', '.join(f'{v:.1f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
