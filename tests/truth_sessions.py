"""Sessions built straight from a synthetic session's truth (no detection): for tests."""

from __future__ import annotations

from pathlib import Path

from speechcal_core.session.model import Session


def truth_session(folder: Path, truth: dict) -> Session:
    """A session over ``folder``'s recording with one set per true trigger, each taking
    the frames nearest the trigger in every camera, and the truth's sync."""
    from speechcal_core.frames.nearest import nearest_frame_sets
    from speechcal_core.session.model import Trigger
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.model import SyncModel

    recording = str(folder / truth["recording"])
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")
    triggers = [Trigger(t["word"], t["start_s"], t["end_s"], 1.0, "truth")
                for t in truth["triggers"]]
    with open_recording([recording]) as source:
        sets = nearest_frame_sets(source, sync, triggers)
    return Session([recording], str(folder / truth["audio"]), sync, sets)
