"""A calibration check whose progress callback refuses to go on fits no further camera."""

from __future__ import annotations

import threading

import pytest
from calib_views import synthetic_views

from speechcal_core.calibration.check import check_cameras


class Stop(Exception):
    """What the window's progress callback raises when the check is no longer wanted."""


def test_a_check_stopped_by_its_progress_fits_no_further_camera() -> None:
    cam, views = synthetic_views(fisheye=False, holds=12)
    names = [f"/cam{i}" for i in range(8)]
    calls: list[float] = []
    lock = threading.Lock()

    def progress(_text: str, fraction: float) -> None:
        with lock:
            calls.append(fraction)
        raise Stop

    with pytest.raises(Stop):
        check_cameras({n: views for n in names}, {n: (cam.width, cam.height) for n in names},
                      models=("pinhole",), progress=progress)
    assert calls and all(f == 0.0 for f in calls)  # stopped before each fit, none ended
    assert len(calls) < len(names)  # the cameras not yet started were never begun


def test_a_check_that_may_go_on_reports_each_camera_before_and_after() -> None:
    cam, views = synthetic_views(fisheye=False, holds=12)
    names = ["/left", "/right"]
    calls: list[float] = []
    lock = threading.Lock()

    def progress(_text: str, fraction: float) -> None:
        with lock:
            calls.append(fraction)

    entries = check_cameras({n: views for n in names},
                            {n: (cam.width, cam.height) for n in names},
                            models=("pinhole",), progress=progress)
    assert set(entries) == set(names)
    assert len(calls) == 2 * len(names) and max(calls) == 1.0
