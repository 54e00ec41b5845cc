"""The calibration check of one wide lens: time and RMS of its three model fits by views.

The window re-runs the check after every decision, over every set not rejected, and a
wide lens gets the pinhole, fisheye and double-sphere fits. Measures, in the same run
on the same views (a synthetic wide lens's holds, repeated with fresh corner noise to
reach a session's count):

- baseline ``joint``: the fisheye fit of every view at once and the double-sphere
  solver run to scipy's default tolerance, as the check was;
- ``check``: as :func:`fit_models` runs now (fisheye intrinsics from a spread subset of
  ``FIT_VIEWS`` views, each view then posed alone; the double sphere stopped at
  ``FIT_FTOL``).

    python benchmarks/bench_calibration_check.py            # seeds 1-4, about 100 views
    python benchmarks/bench_calibration_check.py --seeds 2 --copies 2 --repeats 5

Prints medians, ratios and both RMS per model; asserts nothing.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
for path in (REPO, REPO / "tests" / "calibration"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

from calib_views import synthetic_views  # noqa: E402

from speechcal_core.calibration import double_sphere, fisheye  # noqa: E402
from speechcal_core.calibration.check import fit_models  # noqa: E402
from speechcal_core.calibration.views import CalibrationResult, View  # noqa: E402

#: scipy's own ftol: the double sphere's stopping rule before FIT_FTOL
SCIPY_FTOL = 1e-8


def lens_views(seed: int, copies: int) -> tuple[tuple[int, int], list[View]]:
    """A synthetic wide lens's image size and its views, ``copies`` times over."""
    cam, views = synthetic_views(fisheye=True, seed=seed, holds=100)
    rng = np.random.default_rng(seed)
    many = [View(k, v.object_points, v.image_points + rng.normal(0, 0.1, v.image_points.shape))
            for k, v in enumerate(views * copies)]
    return (cam.width, cam.height), many


def timed_fits(views: list[View], size: tuple[int, int], repeats: int,
               ) -> tuple[float, dict[str, CalibrationResult]]:
    """Median seconds of :func:`fit_models` and its last result."""
    times, fits = [], {}
    for _ in range(repeats):
        start = time.perf_counter()
        fits = fit_models(views, size)
        times.append(time.perf_counter() - start)
    return statistics.median(times), fits


def measure(seed: int, copies: int, repeats: int) -> str:
    """One line of figures for one lens."""
    size, views = lens_views(seed, copies)
    subset, ftol = fisheye.FIT_VIEWS, double_sphere.FIT_FTOL
    try:
        fisheye.FIT_VIEWS, double_sphere.FIT_FTOL = len(views), SCIPY_FTOL
        base, joint = timed_fits(views, size, repeats)
    finally:
        fisheye.FIT_VIEWS, double_sphere.FIT_FTOL = subset, ftol
    ours, check = timed_fits(views, size, repeats)
    rms = " ".join(f"{m} {joint[m].rms_px:.4f}/{check[m].rms_px:.4f}" for m in check
                   if m in joint)
    return (f"seed {seed}, {len(views):3d} views: baseline joint {base:5.2f} s | check "
            f"{ours:5.2f} s ({base / ours:4.1f}x) | RMS px joint/check: {rms}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    parser.add_argument("--copies", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    for seed in args.seeds:
        print(measure(seed, args.copies, args.repeats), flush=True)


if __name__ == "__main__":
    main()
