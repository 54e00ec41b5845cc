"""Sessions built straight from a synthetic session's truth (no detection): for tests."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from speechcal_core.session.model import Session, Trigger
from speechcal_core.sync.model import SyncModel


def truth_sync(truth: dict) -> SyncModel:
    """The synthetic session's true clock offset and drift."""
    return SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")


def truth_triggers(truth: dict) -> list[Trigger]:
    """The trigger words as spoken, with their true start and end."""
    return [Trigger(t["word"], t["start_s"], t["end_s"], 1.0, "truth")
            for t in truth["triggers"]]


def truth_session(folder: Path, truth: dict) -> Session:
    """A session over ``folder``'s recording with one set per true trigger, each taking
    the frames nearest the trigger in every camera, and the truth's sync."""
    from speechcal_core.frames.nearest import nearest_frame_sets
    from speechcal_core.sources import open_recording

    recording = str(folder / truth["recording"])
    with open_recording([recording]) as source:
        sets = nearest_frame_sets(source, truth_sync(truth), truth_triggers(truth))
    return Session([recording], str(folder / truth["audio"]), truth_sync(truth), sets)


def searched_session(folder: Path, truth: dict, sync: SyncModel | None = None) -> Session:
    """A session as ``speechcal process`` makes it from the true triggers and sync (or
    ``sync``): best still frames with their figures, frame details and references, the
    default target."""
    from speechcal_core.frames.analysis import analyse_frames
    from speechcal_core.sources import open_recording
    from speechcal_core.target import TargetSpec

    recording = str(folder / truth["recording"])
    target = TargetSpec()
    sync = sync or truth_sync(truth)
    with open_recording([recording]) as source:
        analysis = analyse_frames(source, sync, truth_triggers(truth), target)
    return Session([recording], str(folder / truth["audio"]), sync,
                   analysis.sets, calibration=analysis.calibration,
                   extra={**analysis.extra, "target": asdict(target)})


def quiet_time_s(truth: dict, gap_s: float = 2.5) -> float:
    """An audio time in the middle of the first stretch of ``gap_s`` or more in which
    nobody speaks (between two spoken words of the truth, triggers or not)."""
    from itertools import pairwise

    spoken = sorted((p["start_s"], p["end_s"]) for p in truth["triggers"] + truth["distractors"])
    return next((a + b) / 2 for (_s0, a), (b, _e1) in pairwise(spoken) if b - a > gap_s)
