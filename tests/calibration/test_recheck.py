"""Re-checking the calibration from stored corners leaves rejected sets out."""

from __future__ import annotations

import numpy as np
from calib_views import synthetic_views

from speechcal_core.calibration.recheck import recheck_calibration
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
from speechcal_core.sync.model import SyncModel
from speechcal_core.target import TargetSpec


def test_recheck_uses_stored_corners_and_skips_rejected_sets() -> None:
    cam, views = synthetic_views(fisheye=False, holds=8)
    target = TargetSpec()
    obj = target.object_points()
    sets, details = [], {}
    for v in views:
        ids = [int(np.flatnonzero((obj == p).all(axis=1))[0]) for p in v.object_points]
        sets.append(FrameSet(v.set_id, 0, Trigger("capture", 0, 0.5),
                             (FrameChoice(cam.name, v.set_id, 0),)))
        details[str(v.set_id)] = {"frames": {cam.name: {"ids": ids,
                                                        "points": v.image_points.tolist()}}}
    sets[0] = sets[0].with_decision("rejected")
    session = Session([], None, SyncModel(0), sets, extra={"frame_details": details})
    out = recheck_calibration(session, target, {cam.name: (cam.width, cam.height)},
                              ("pinhole",))
    entry = out[cam.name]
    assert [v["set"] for v in entry["views"]] == [v.set_id for v in views[1:]]
    assert entry["rms_px"] < 0.5

    # a false trigger in the second hold took that set's frame: still one view there
    sets.insert(2, FrameSet(99, 0, Trigger("capture", 0, 0.5), sets[1].frames))
    details["99"] = details[str(sets[1].id)]
    again = recheck_calibration(session, target, {cam.name: (cam.width, cam.height)},
                                ("pinhole",))[cam.name]
    assert [v["set"] for v in again["views"]] == [v["set"] for v in entry["views"]]
