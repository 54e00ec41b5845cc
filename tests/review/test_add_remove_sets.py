"""Operator fixes to detection in review: add a missed trigger's set, remove a false one."""

from __future__ import annotations

from pathlib import Path

from review_models import open_model

from speechcal_core.frames.nearest import nearest_index
from speechcal_core.review.model import KEY_BINDINGS, OPERATOR_SOURCE, ReviewModel, set_time_ns
from speechcal_core.session.store import load_session
from speechcal_core.sources import open_recording


def _model(path: Path, saves: list | None = None) -> ReviewModel:
    return open_model(path, saves, note=lambda s: [x.id for x in s.sets])


def _between_first_two_sets(model: ReviewModel) -> int:
    """A playhead half way between the first two sets (well away from both)."""
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    assert b - a > 1_000_000_000
    return (a + b) // 2


def test_add_set_at_playhead_takes_nearest_frames_and_is_saved_as_operator_added(
    truth_session_file: Path,
) -> None:
    saves: list = []
    model = _model(truth_session_file, saves)
    before = [s.id for s in model.session.sets]
    playhead = _between_first_two_sets(model)
    model.set_playhead(playhead)
    model.add_set()

    new = model.current_set
    assert new is not None and model.current == 1
    assert new.id == max(before) + 1
    assert new.decision == "undecided"
    assert [s.id for s in model.session.sets] == [before[0], new.id, *before[1:]]
    times = [s.t_ns for s in model.session.sets]
    assert times == sorted(times)
    trig = new.trigger
    assert trig.word == "capture" and trig.source == OPERATOR_SOURCE
    assert trig.start_s == trig.end_s == model.session.sync.to_audio(playhead)
    assert abs(new.t_ns - playhead) <= 1
    for frame in new.frames:  # every camera: the frame nearest the playhead
        stamps = model.source.stamps(frame.stream)
        assert frame.index == nearest_index(stamps, playhead)
        assert frame.stamp_ns == int(stamps[frame.index])
    assert [f.stream for f in new.frames] == model.streams
    assert model.playhead_ns == set_time_ns(new)

    assert len(saves) == 1
    reloaded = load_session(truth_session_file)
    assert reloaded.sets == model.session.sets
    assert reloaded.set_by_id(new.id).trigger.source == OPERATOR_SOURCE


def test_add_next_to_an_existing_set_selects_it_instead(truth_session_file: Path) -> None:
    saves: list = []
    model = _model(truth_session_file, saves)
    model.go_to_set(0)
    model.set_playhead(set_time_ns(model.session.sets[1]) + 150_000_000)
    count = len(model.session.sets)
    model.add_set()
    assert len(model.session.sets) == count
    assert model.current == 1
    assert saves == [] and model._undo == []


def test_add_on_a_sets_word_selects_that_set_though_its_frames_are_later(
        searched_session_file: Path) -> None:
    """Best still frames often lie half a second after the word: T on the word's mark
    on the waveform added a second set for the same word."""
    model = _model(searched_session_file)
    sync = model.session.sync
    apart = [(i, s) for i, s in enumerate(model.session.sets)
             if abs(set_time_ns(s) - sync.to_session(s.trigger.start_s)) > 300_000_000]
    assert apart, "no set whose frames lie well away from its word's start"
    index, far = apart[0]
    count = len(model.session.sets)
    model.go_to_set(0 if index else 1)
    model.set_playhead(int(sync.to_session(far.trigger.start_s)))  # the mark's left edge
    model.add_set()
    assert len(model.session.sets) == count and model.current == index
    assert model._undo == []


def test_remove_takes_out_the_current_set_and_saves(truth_session_file: Path) -> None:
    saves: list = []
    model = _model(truth_session_file, saves)
    ids = [s.id for s in model.session.sets]
    model.go_to_set(1)
    model.remove_set()
    assert [s.id for s in model.session.sets] == [ids[0], *ids[2:]]
    assert model.current == 1 and model.current_set.id == ids[2]
    assert saves == [[ids[0], *ids[2:]]]
    assert [s.id for s in load_session(truth_session_file).sets] == [ids[0], *ids[2:]]
    model.last_set()
    while model.session.sets:
        model.remove_set()
    assert model.current == -1 and model.current_set is None
    model.remove_set()  # nothing left: nothing happens
    assert load_session(truth_session_file).sets == []


def test_add_and_remove_undo_and_redo_with_decisions(truth_session_file: Path) -> None:
    saves: list = []
    model = _model(truth_session_file, saves)
    original = list(model.session.sets)
    model.go_to_set(1)
    model.reject()
    rejected = model.current_set
    model.remove_set()
    model.set_playhead(_between_first_two_sets(model))
    model.add_set()
    added = model.current_set
    assert [s.id for s in model.session.sets][:2] == [original[0].id, added.id]

    model.undo()  # the add
    assert added not in model.session.sets
    model.undo()  # the removal: back in place, still rejected, selected
    assert model.session.sets[1] == rejected and model.current == 1
    model.undo()  # the rejection
    assert model.session.sets == original
    model.redo()
    model.redo()
    assert rejected not in model.session.sets
    model.redo()
    assert model.session.sets[1] == added and model.current_set == added
    assert len(saves) == 9  # every action, undo and redo saved
    assert load_session(truth_session_file).sets == model.session.sets

    model.undo()
    model.accept()  # a new action drops what could be redone
    model.redo()
    assert added not in model.session.sets


def test_add_and_remove_tell_listeners_and_have_keys(truth_session_file: Path) -> None:
    model = _model(truth_session_file)
    events: list = []
    model.connect("sets", lambda: events.append("sets"))
    model.remove_set()
    model.undo()
    assert events == ["sets", "sets"]
    assert KEY_BINDINGS["T"] == "add_set" and KEY_BINDINGS["Delete"] == "remove_set"


def test_removing_a_set_drops_its_corners_until_undone(truth_session_file: Path) -> None:
    session = load_session(truth_session_file)
    last = session.sets[-1]
    session.extra["frame_details"] = {str(last.id): {"frames": {}}}
    model = ReviewModel(session, open_recording(session.recording))
    model.last_set()
    model.remove_set()
    assert str(last.id) not in session.extra["frame_details"]
    _start, end = model.time_range_ns()
    model.set_playhead(end)
    model.add_set()  # a new number (never the removed set's), without corners
    assert model.current_set.id == last.id + 1
    assert not {str(last.id), str(last.id + 1)} & set(session.extra["frame_details"])
    model.undo()
    model.undo()
    assert session.extra["frame_details"] == {str(last.id): {"frames": {}}}


def test_undo_and_redo_labels_name_the_step_each_would_take(truth_session_file: Path) -> None:
    """For the Edit menu: Undo names the step it takes back, Redo the one it does again
    (the redo stack holds the inverse step, which must not be what it names)."""
    model = _model(truth_session_file)
    assert (model.undo_label, model.redo_label) == ("", "")
    model.go_to_set(1)
    model.reject()
    rejected_id = model.current_set.id
    assert model.undo_label == f"decision on set {rejected_id}"
    model.remove_set()
    assert model.undo_label == f"removing set {rejected_id}"
    model.set_playhead(_between_first_two_sets(model))
    model.add_set()
    added_id = model.current_set.id
    assert model.undo_label == f"adding set {added_id}"
    model.undo()
    assert (model.undo_label, model.redo_label) == (f"removing set {rejected_id}",
                                                    f"adding set {added_id}")
    model.undo()
    assert model.redo_label == f"removing set {rejected_id}"
    model.redo()
    assert model.undo_label == f"removing set {rejected_id}"
    assert model.redo_label == f"adding set {added_id}"
    model.nudge_offset(1_000_000)
    assert (model.undo_label, model.redo_label) == ("audio offset change", "")


def test_a_decision_or_removal_with_no_sets_left_says_why_it_did_nothing(
    truth_session_file: Path,
) -> None:
    """With every set removed, A, R and Del did nothing and gave no reason (J and K said
    "no frame sets to go to: T adds one at the playhead")."""
    model = _model(truth_session_file)
    while model.session.sets:
        model.remove_set()
    for act in (model.accept, model.reject, model.remove_set):
        model.step_refused = ""
        act()
        assert model.step_refused.startswith("no frame sets to ")
        assert "T adds one at the playhead" in model.step_refused
        assert model.last_decided is None and not model.session.sets


def test_a_decision_that_went_through_carries_no_earlier_reason(
    truth_session_file: Path,
) -> None:
    """A with no sets left gave its reason; after T added a set, A on it (without "then
    next set") still carried that reason, and the window said "set #1 accepted · no frame
    sets to decide on"."""
    model = _model(truth_session_file)
    model.advance_after_decision = False
    while model.session.sets:
        model.remove_set()
    model.accept()
    assert model.step_refused
    model.add_set()
    model.accept()
    assert model.session.sets[0].decision == "accepted"
    assert model.step_refused == ""


def _add_between_first_two(model: ReviewModel) -> int:
    """Add a set half way between the first two sets; its id."""
    model.set_playhead(_between_first_two_sets(model))
    model.add_set()
    assert model.current_set is not None
    return model.current_set.id


def _remove_highest(model: ReviewModel) -> int:
    highest = max(s.id for s in model.session.sets)
    model.go_to_set(next(i for i, s in enumerate(model.session.sets) if s.id == highest))
    model.remove_set()
    return highest


def test_a_removed_sets_number_is_never_given_again(truth_session_file: Path) -> None:
    """Set numbers are what the operator reads and says ("set 7"): after set 7 was
    removed the next set added was set 7 again, another set under the same name in notes
    and in exports. Not within the review, nor after the session is opened again."""
    model = _model(truth_session_file)
    removed = _remove_highest(model)
    assert _add_between_first_two(model) == removed + 1
    assert load_session(truth_session_file).last_set_id == removed + 1

    model = _model(truth_session_file)  # opened again, the highest set removed again
    removed_too = _remove_highest(model)
    assert removed_too == removed + 1
    model = _model(truth_session_file)
    assert _add_between_first_two(model) == removed + 2


def test_an_undone_added_sets_number_is_not_given_again(truth_session_file: Path) -> None:
    """Added, heard as "set 9" and taken back: the next set added is set 10; redo of a
    removal brings a set back under its own number, which no other set took meanwhile."""
    from speechcal_core.review.similar import SimilarResult
    from speechcal_core.speech.backend import Word

    model = _model(truth_session_file)
    highest = max(s.id for s in model.session.sets)
    added = _add_between_first_two(model)
    assert added == highest + 1
    model.undo()
    assert _add_between_first_two(model) == highest + 2
    model.undo()
    removed = _remove_highest(model)  # the highest detected set
    model.undo()  # back under its own number
    assert model.session.set_by_id(removed).id == highest
    # found words (S, detect again) take the next numbers too
    a, b = (set_time_ns(s) for s in model.session.sets[:2])
    t_s = float(model.session.sync.to_audio((a + b) // 2))
    found = model.apply_similar(SimilarResult(None, (t_s, t_s + 0.4),  # type: ignore[arg-type]
                                              (Word("capture", t_s, t_s + 0.4),)))
    assert found == [highest + 3]
    ids = [s.id for s in load_session(truth_session_file).sets]
    assert len(ids) == len(set(ids))


def test_a_session_file_without_the_last_set_number_counts_on_from_its_sets(
        truth_session_file: Path) -> None:
    """A file written before the session kept its last set number opens; new sets are
    numbered after its highest set."""
    import json

    data = json.loads(truth_session_file.read_text())
    data.pop("last_set_id", None)
    truth_session_file.write_text(json.dumps(data))
    session = load_session(truth_session_file)
    highest = max(s.id for s in session.sets)
    assert session.last_set_id == highest
    assert _add_between_first_two(_model(truth_session_file)) == highest + 1
