"""Re-scoring frame sets for another clock offset: the pipeline's choice, ids kept."""

from __future__ import annotations

from pathlib import Path

import pytest
from truth_sessions import truth_sync, truth_triggers

from speechcal_core.frames.sets import FrameReferences, build_frame_sets, rescore_frame_sets
from speechcal_core.sources import open_recording
from speechcal_core.target import TargetSpec


class Stop(Exception):
    pass


def test_rescoring_every_set_gives_what_the_pipeline_gives_at_that_offset(
    tiny_synth: tuple[Path, dict],
) -> None:
    folder, truth = tiny_synth
    sync, triggers, target = truth_sync(truth), truth_triggers(truth), TargetSpec()
    moved = sync.with_offset(sync.offset_ns - 300_000_000)
    with open_recording([str(folder / truth["recording"])]) as source:
        before = build_frame_sets(source, sync, triggers, target)
        sets = [s.with_decision("accepted") if s.id == 2 else s for s in before.sets]
        again = rescore_frame_sets(source, moved, sets, target)
        pipeline = build_frame_sets(source, moved, triggers, target)
    assert [(s.id, s.trigger, s.decision) for s in again.sets] == \
        [(s.id, s.trigger, s.decision) for s in sets]
    assert [s.frames for s in again.sets] == [s.frames for s in pipeline.sets]
    assert [s.t_ns for s in again.sets] == [s.t_ns for s in pipeline.sets]
    assert again.details == pipeline.details and again.references == pipeline.references
    assert all(f.sharpness is not None or "no-target" in f.flags
               for s in again.sets for f in s.frames)


def test_one_set_with_the_sessions_references_scores_as_in_the_whole_run(
    tiny_synth: tuple[Path, dict],
) -> None:
    folder, truth = tiny_synth
    sync, target = truth_sync(truth), TargetSpec()
    with open_recording([str(folder / truth["recording"])]) as source:
        whole = build_frame_sets(source, sync, truth_triggers(truth), target)
        refs = FrameReferences.from_dict(whole.references.to_dict())  # as kept in the file
        assert refs == whole.references
        one = rescore_frame_sets(source, sync, whole.sets[1:2], target, references=refs)
    assert one.sets == whole.sets[1:2]
    assert one.details == {"2": whole.details["2"]}
    assert FrameReferences.from_dict({"noise_floor": {}}) is None  # older session: none


def test_rescoring_stops_when_progress_raises(tiny_synth: tuple[Path, dict]) -> None:
    folder, truth = tiny_synth

    def cancel(_stage: str, _fraction: float) -> None:
        raise Stop

    with open_recording([str(folder / truth["recording"])]) as source:
        sets = build_frame_sets(source, truth_sync(truth), truth_triggers(truth), None).sets
        with pytest.raises(Stop):
            rescore_frame_sets(source, truth_sync(truth), sets, TargetSpec(), progress=cancel)
