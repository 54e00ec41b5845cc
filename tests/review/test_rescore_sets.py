"""After an offset edit or an added set: nearest frames at once, re-scored sets when ready."""

from __future__ import annotations

import json
from pathlib import Path

from review_models import open_model
from truth_sessions import truth_triggers

from speechcal_core.frames.analysis import analyse_frames
from speechcal_core.frames.nearest import nearest_index
from speechcal_core.review.model import ReviewModel, set_time_ns
from speechcal_core.session.store import load_session
from speechcal_core.target import TargetSpec

SHIFT_NS = -300_000_000  # far enough that the nearest frames are not the still ones


def _rescore(model: ReviewModel) -> list[int]:
    request = model.rescore_request()
    assert request is not None
    return model.apply_rescored(request.run(model.source))


def _figures(model: ReviewModel, set_id: int) -> bool:
    frames = model.session.set_by_id(set_id).frames
    # measured: corners counted, and sharpness wherever the target was found
    return all(f.corners is not None and (f.sharpness is not None or "no-target" in f.flags)
               for f in frames)


def test_offset_edit_shows_nearest_frames_then_rescoring_brings_the_pipelines_choice(
    searched_session_file: Path, tiny_synth: tuple[Path, dict],
) -> None:
    saves: list = []
    model = open_model(searched_session_file, saves, note=lambda s: s.sync.offset_ns)
    ids = [s.id for s in model.session.sets]
    assert model.rescore_ids() == [] and model.rescore_request() is None
    model.go_to_set(1)
    model.accept()
    model.nudge_offset(SHIFT_NS)

    # at once: every set at its new time with the frames nearest it, without figures
    assert model.rescore_ids() == ids
    for s in model.session.sets:
        for f in s.frames:
            assert f.index == nearest_index(model.source.stamps(f.stream), s.t_ns)
            assert f.sharpness is None and f.corners is None
    assert all(t.corners == () for t in model.tiles())  # no corners of other frames

    events: list = []
    model.connect("rescored", events.append)
    request = model.rescore_request()
    assert request.references is None and [s.id for s in request.sets] == ids
    assert _rescore(model) == ids
    assert events == [ids] and model.rescore_ids() == []

    _folder, truth = tiny_synth
    pipeline = analyse_frames(model.source, model.session.sync, truth_triggers(truth),
                              TargetSpec())
    assert [s.frames for s in model.session.sets] == [s.frames for s in pipeline.sets]
    assert any(f.index != nearest_index(model.source.stamps(f.stream), s.t_ns)
               for s in model.session.sets for f in s.frames)  # still frames, not nearest
    assert all(_figures(model, i) for i in ids)
    assert model.session.sets[1].decision == "accepted" and model.current == 1
    assert model.playhead_ns == set_time_ns(model.current_set)
    assert all(t.chosen for t in model.tiles())
    assert any(t.corners for t in model.tiles())
    saved = load_session(searched_session_file)
    assert saved.sets == model.session.sets and len(saves) == 3  # accept, nudge, re-scored
    assert saved.extra["frame_references"] == pipeline.extra["frame_references"]


def test_results_for_an_older_offset_are_dropped(searched_session_file: Path) -> None:
    model = open_model(searched_session_file)
    model.nudge_offset(SHIFT_NS)
    stale = model.rescore_request().run(model.source)
    model.offset_plus_ms()
    shown = list(model.session.sets)
    assert model.apply_rescored(stale) == []
    assert model.session.sets == shown and len(model.rescore_ids()) == len(shown)
    assert _rescore(model) == [s.id for s in shown]
    assert model.rescore_ids() == []


def test_an_added_set_is_rescored_alone_and_keeps_its_figures_through_undo_and_redo(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    others = list(model.session.sets)
    a, b = (set_time_ns(s) for s in others[1:3])
    model.set_playhead((a + b) // 2)
    model.add_set()
    new = model.current_set
    assert model.rescore_ids() == [new.id] and not _figures(model, new.id)
    request = model.rescore_request()
    assert [s.id for s in request.sets] == [new.id] and request.references is not None
    assert _rescore(model) == [new.id]
    assert _figures(model, new.id)
    assert [s for s in model.session.sets if s.id != new.id] == others
    details = model.session.extra["frame_details"][str(new.id)]
    assert details["method"] == "best-still"
    assert model.playhead_ns == set_time_ns(model.current_set)

    rescored = model.current_set
    model.undo()
    assert rescored not in model.session.sets
    model.redo()
    assert model.current_set == rescored and model.rescore_ids() == []
    assert model.session.extra["frame_details"][str(new.id)] == details


def test_a_set_removed_meanwhile_is_skipped_and_comes_back_to_be_rescored(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    model.go_to_set(2)
    kept = model.current_set
    model.remove_set()  # scored at the old offset ...
    model.nudge_offset(SHIFT_NS)  # ... which then changes
    model.go_to_set(0)
    gone = model.current_set
    model.remove_set()  # removed while waiting for re-scoring
    result = model.rescore_request().run(model.source)
    assert gone.id not in model.apply_rescored(result)
    assert model.rescore_ids() == []
    model.undo()
    assert model.session.sets[0].id == gone.id and model.rescore_ids() == [gone.id]
    model.undo()  # the offset edit: every set back with the frames scored before it
    assert model.rescore_ids() == []
    model.redo()  # ... and forth again: the one that was not re-scored waits again
    assert model.rescore_ids() == [gone.id]
    model.undo()
    model.undo()  # the first removal: back at the time it was scored at, with its figures
    back = model.session.set_by_id(kept.id)
    assert back.t_ns == kept.t_ns and _figures(model, kept.id)
    assert model.rescore_ids() == []
    assert all(_figures(model, s.id) for s in model.session.sets)


def test_a_session_made_without_the_search_is_rescored_whole_after_an_edit(
    truth_session_file: Path,
) -> None:
    model = open_model(truth_session_file)
    assert model.rescore_request() is None  # opening changes nothing
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    model.set_playhead((a + b) // 2)
    model.add_set()
    request = model.rescore_request()  # no references to score one set against
    assert len(request.sets) == len(model.session.sets) and request.references is None
    model.apply_rescored(request.run(model.source))
    assert all(_figures(model, s.id) for s in model.session.sets)
    assert "frame_references" in load_session(truth_session_file).extra


def _edit_offset_by_hand(path: Path) -> None:
    """Move the session file's offset as a text editor would: its sets keep their times."""
    data = json.loads(path.read_text(encoding="utf-8"))
    data["sync"]["offset_ns"] += SHIFT_NS
    path.write_text(json.dumps(data), encoding="utf-8")


def test_a_session_whose_offset_was_edited_by_hand_is_rescored_once(
    searched_session_file: Path,
) -> None:
    _edit_offset_by_hand(searched_session_file)
    model = open_model(searched_session_file)
    sync = model.session.sync
    for s in model.session.sets:  # at once at their time under the file's offset
        assert s.t_ns == int(sync.to_session(s.trigger.t_s))
    ids = [s.id for s in model.session.sets]
    assert model.rescore_ids() == ids
    assert sorted(_rescore(model)) == sorted(ids)
    assert model.rescore_ids() == []  # taken, so re-scoring does not run again and again


def test_rescoring_a_hand_edited_file_outside_the_window_takes_the_new_times(
    searched_session_file: Path,
) -> None:
    from speechcal_core.review.rescore import rescore_ids, rescore_waiting
    from speechcal_core.sources import open_recording

    _edit_offset_by_hand(searched_session_file)
    session = load_session(searched_session_file)
    with open_recording(session.recording) as source:  # as `speechcal export` does
        taken = rescore_waiting(session, source)
    assert sorted(taken) == sorted(s.id for s in session.sets)
    assert rescore_ids(session) == []
    assert all(s.t_ns == int(session.sync.to_session(s.trigger.t_s)) for s in session.sets)


def test_undoing_an_offset_edit_brings_back_the_frames_scored_before_it(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    before = list(model.session.sets)
    references = model.session.extra["frame_references"]
    model.nudge_offset(SHIFT_NS)
    _rescore(model)
    after = list(model.session.sets)
    references_after = model.session.extra["frame_references"]
    assert references_after != references  # re-measured for the new offset
    model.undo()
    assert model.session.sets == before and model.rescore_ids() == []  # nothing to re-score
    # sets re-scored later are judged on the same scale as the frames put back
    assert model.session.extra["frame_references"] == references
    model.redo()
    assert model.session.sets == after and model.rescore_ids() == []
    assert model.session.extra["frame_references"] == references_after


def test_accepted_sets_given_other_frames_by_an_offset_edit_are_named(
    searched_session_file: Path,
) -> None:
    """An export writes the chosen frames: an accepted set whose re-scored frames differ
    from those it showed when accepted is named, so the operator can look again."""
    model = open_model(searched_session_file)

    def frames() -> dict[int, list[tuple[str, int]]]:
        return {s.id: [(f.stream, f.index) for f in s.frames] for s in model.session.sets}

    shown = frames()
    first, second, third = (s.id for s in model.session.sets[:3])
    for index, decide in ((0, model.accept), (1, model.reject), (2, model.accept)):
        model.go_to_set(index)
        decide()
    model.nudge_offset(-600_000_000)
    model.offset_plus_ms()  # a second edit before re-scoring: still compared with the first
    _rescore(model)
    moved = {i for i, keys in frames().items() if keys != shown[i]}
    # at this offset the second and third sets get other still frames, the first not
    assert first not in moved and {second, third} <= moved
    assert model.accepted_with_new_frames == [third]  # the rejected one is not exported

    model.undo()
    model.undo()  # the frames shown when the decisions were made, no re-scoring due
    assert frames() == shown and model.rescore_ids() == []
    model.nudge_offset(-600_000_000)
    _rescore(model)
    assert model.accepted_with_new_frames == [third]


def test_a_window_closed_before_rescoring_landed_names_the_same_sets_when_reopened(
    searched_session_file: Path,
) -> None:
    """Closed after an offset edit, before re-scoring landed: the reopened review
    compared the re-scored frames with the nearest frames the edit left, and named
    accepted sets whose frames were the same as when they were accepted."""
    model = open_model(searched_session_file)
    first, _second, third = (s.id for s in model.session.sets[:3])
    for index, decide in ((0, model.accept), (1, model.reject), (2, model.accept)):
        model.go_to_set(index)
        decide()
    model.nudge_offset(-600_000_000)
    assert set(load_session(searched_session_file).extra["frames_before_offset_edit"]) \
        >= {str(first), str(third)}

    reopened = open_model(searched_session_file)  # the autosave after the edit
    assert first in reopened.rescore_ids()
    _rescore(reopened)
    assert reopened.accepted_with_new_frames == [third]  # as in the window left open
    assert "frames_before_offset_edit" not in load_session(searched_session_file).extra


def test_an_added_set_accepted_before_rescoring_is_named_when_its_frames_change(
    searched_session_file: Path,
) -> None:
    """A set added with T shows its nearest frames until re-scoring lands; accepted on
    those, it is named when re-scoring gives it others, also in a window opened again
    on the autosaved file (the operator closed the first before re-scoring landed)."""
    model = open_model(searched_session_file)
    a, b = (set_time_ns(s) for s in model.session.sets[1:3])
    model.set_playhead((a + b) // 2)
    model.add_set()
    added = model.current_set
    shown = [(f.stream, f.index) for f in added.frames]
    model.advance_after_decision = False
    model.accept()

    reopened = open_model(searched_session_file)  # the autosave holds the decision
    assert reopened.rescore_ids() == [added.id]
    for window_model in (model, reopened):
        _rescore(window_model)
        now = [(f.stream, f.index) for f in window_model.session.set_by_id(added.id).frames]
        assert now != shown  # the nearest frames are not the best still ones here
        assert window_model.accepted_with_new_frames == [added.id]


def test_an_added_set_decided_after_rescoring_is_not_named(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    a, b = (set_time_ns(s) for s in model.session.sets[1:3])
    model.set_playhead((a + b) // 2)
    model.add_set()
    _rescore(model)
    model.accept()
    assert model.accepted_with_new_frames == []
