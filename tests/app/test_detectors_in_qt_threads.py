"""The frame search's per-thread detectors on the window's Qt pool threads: a detector
must not be freed while PySide tears a pool thread's Python state down (OpenCV's
clean-up then crashes the process)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

# a task that builds the search's detectors on a Qt pool thread, uses them from the
# search's own worker thread, and whose detectors outlive the task (as when a stack
# sampler, a profiler or a kept traceback holds the frame that held them)
SCRIPT = textwrap.dedent("""
    from concurrent.futures import ThreadPoolExecutor
    from PySide6.QtCore import QCoreApplication, QRunnable, QThreadPool
    from speechcal_core.frames.sets import _Detectors
    from speechcal_core.target import TargetSpec

    app = QCoreApplication([])
    kept = []

    class Task(QRunnable):
        def run(self):
            local = _Detectors(TargetSpec())
            with ThreadPoolExecutor(max_workers=1) as pool:
                assert pool.submit(lambda: local.preview is not None).result()
            kept.append(local)

    pool = QThreadPool()
    pool.setMaxThreadCount(1)
    for _ in range(5):
        pool.start(Task())
        pool.waitForDone()
    print("done")
""")


def test_detectors_outliving_their_qt_task_do_not_crash_the_process() -> None:
    run = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                         timeout=120, env={**os.environ, "QT_QPA_PLATFORM": "offscreen"})
    assert run.returncode == 0, run.stderr[-2000:]  # a segfault before: -11
    assert run.stdout.strip() == "done"
