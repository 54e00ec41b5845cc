"""The undo history kept in the session file: Ctrl+Z takes back the last review's steps
after the session is opened again, and a history that no longer fits the file's sets is
dropped with a note, never applied to them."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from review_models import open_model

import speechcal_core.review.undo_history as undo_history
from speechcal_core.review.undo_history import (
    UNDO_HISTORY_KEY,
    HistoryWriter,
    history_fingerprint,
    read_history,
)
from speechcal_core.review.undo_steps import Decided, Removed
from speechcal_core.session.store import load_session, save_session


def _stored(path: Path) -> dict | None:
    return json.loads(path.read_text()).get(UNDO_HISTORY_KEY)


def test_decisions_are_undone_and_redone_after_the_session_is_opened_again(
        truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    model.accept()
    model.next_set()
    model.reject()
    ids = [s.id for s in model.session.sets[:2]]

    again = open_model(truth_session_file)
    assert again.history_note == "" and again.undo_label == f"decision on set {ids[1]}"
    again.undo()
    again.undo()
    assert [s.decision for s in again.session.sets[:2]] == ["undecided", "undecided"]
    again.undo()  # nothing older
    assert again.redo_label == f"decision on set {ids[0]}"

    # the redo steps are kept too, with the undo steps left
    third = open_model(truth_session_file)
    third.redo()
    assert [s.decision for s in third.session.sets[:2]] == ["accepted", "undecided"]
    assert load_session(truth_session_file).sets[0].decision == "accepted"


def test_each_undo_saves_once_with_its_step_on_the_redo_stack(
        truth_session_file: Path) -> None:
    saves: list = []
    model = open_model(truth_session_file, saves,
                       note=lambda s: s.extra.get(UNDO_HISTORY_KEY))
    model.accept()
    model.undo()
    assert len(saves) == 2
    assert saves[-1]["undo"] == [] and [d["step"] for d in saves[-1]["redo"]] == ["decided"]
    assert _stored(truth_session_file) == saves[-1]


def test_a_removed_set_comes_back_after_a_reopening_with_its_frames_and_figures(
        searched_session_file: Path) -> None:
    model = open_model(searched_session_file)
    model.go_to_set(1)
    removed = model.current_set
    details = model.session.extra["frame_details"][str(removed.id)]
    model.remove_set()

    again = open_model(searched_session_file)
    assert again.removed_here and again.undo_label == f"removing set {removed.id}"
    again.undo()
    assert again.session.sets[1] == removed and again.current == 1
    assert again.session.extra["frame_details"][str(removed.id)] == details
    assert again.rescore_ids() == []  # as measured: nothing to search again


def test_an_added_set_is_taken_back_after_a_reopening(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    ids = [s.id for s in model.session.sets]
    model.set_playhead((model.session.sets[0].t_ns + model.session.sets[1].t_ns) // 2)
    model.add_set()
    assert len(model.session.sets) == len(ids) + 1

    again = open_model(truth_session_file)
    again.undo()
    assert [s.id for s in again.session.sets] == ids


def test_an_offset_edit_and_its_clap_are_undone_after_a_reopening(
        searched_session_file: Path, tiny_synth) -> None:
    session = load_session(searched_session_file)
    session.sync_evidence = {**session.sync_evidence, "claps": tiny_synth[1]["claps"]}
    save_session(session, searched_session_file)
    model = open_model(searched_session_file)
    sync, claps = model.session.sync, model.session.sync_evidence["claps"]
    frames = [s.frames for s in model.session.sets]
    model.set_playhead(model.camera_clap_ns() + 3_000_000)
    model.clap_at_playhead()  # C: another sound is the clap
    assert model.session.sync != sync
    assert model.session.sync_evidence["claps"][0]["audio_source"] == "manual"

    again = open_model(searched_session_file)
    again.undo()
    assert again.session.sync == sync and again.session.sync_evidence["claps"] == claps
    # its frames and figures were not kept in the file: the sets wait for re-scoring,
    # which finds the frames they showed before the edit
    assert again.rescore_ids() == [s.id for s in again.session.sets]
    again.apply_rescored(again.rescore_request().run(again.source))
    assert [s.frames for s in again.session.sets] == frames
    assert again.accepted_with_new_frames == []
    again.redo()  # the edit again, as it was made
    assert again.session.sync == model.session.sync
    assert again.session.sync_evidence["claps"][0]["audio_source"] == "manual"


def _edit_decision(path: Path) -> None:
    session = load_session(path)
    session.sets[-1] = session.sets[-1].with_decision("rejected")
    save_session(session, path)


def _edit_offset(path: Path) -> None:
    data = json.loads(path.read_text())
    data["sync"]["offset_ns"] += 5_000_000
    path.write_text(json.dumps(data))


def _remove_the_decided_set(path: Path) -> None:
    session = load_session(path)
    session.sets = session.sets[1:]
    save_session(session, path)


def _process_again(path: Path) -> None:
    """Other triggers under the same set ids (what processing anew with other words
    gives), the old history kept as an older SpeechCal keeps a key it does not know."""
    session = load_session(path)
    session.sets = [replace(s, trigger=replace(s.trigger, word="snapshot"))
                    for s in session.sets]
    save_session(session, path)


@pytest.mark.parametrize("edit", [_edit_decision, _edit_offset, _remove_the_decided_set,
                                  _process_again])
def test_a_history_the_file_no_longer_matches_is_dropped_with_a_note(
        truth_session_file: Path, edit) -> None:
    model = open_model(truth_session_file)
    model.accept()
    edit(truth_session_file)
    before = [(s.id, s.decision) for s in load_session(truth_session_file).sets]

    again = open_model(truth_session_file)
    assert "undo steps were dropped" in again.history_note
    assert "changed since they were saved" in again.history_note
    again.undo()  # nothing to take back
    assert again.undo_label == ""
    assert [(s.id, s.decision) for s in again.session.sets] == before
    again.reject()  # the next save leaves the old steps out
    assert [d["step"] for d in _stored(truth_session_file)["undo"]] == ["decided"]
    assert open_model(truth_session_file).history_note == ""


def test_a_history_of_a_newer_speechcal_or_damaged_is_dropped_with_a_note(
        truth_session_file: Path) -> None:
    open_model(truth_session_file).accept()
    data = json.loads(truth_session_file.read_text())
    stored = data[UNDO_HISTORY_KEY]

    data[UNDO_HISTORY_KEY] = {**stored, "version": 2}
    truth_session_file.write_text(json.dumps(data))
    assert "a newer SpeechCal wrote them" in open_model(truth_session_file).history_note

    for damaged in ({**stored, "undo": "A"},
                    {**stored, "undo": [{"step": "decided", "set": 999,
                                         "previous": "undecided"}]},
                    {**stored, "undo": [{"step": "decided", "set": 1, "previous": "maybe"}]},
                    [1, 2]):
        data[UNDO_HISTORY_KEY] = damaged
        truth_session_file.write_text(json.dumps(data))
        model = open_model(truth_session_file)
        assert "they are damaged in the file" in model.history_note
        assert model.undo_label == ""


def test_a_set_re_scored_elsewhere_keeps_the_history_and_cameras_left_out_drop_it(
        searched_session_file: Path) -> None:
    """What the steps act on: no step refers to a set's frames (``speechcal export``
    re-scores sets a closed review left waiting), but a removed set's cameras are its."""
    session = load_session(searched_session_file)
    fingerprint = history_fingerprint(session)
    first = session.sets[0]
    other = replace(first.frames[0], index=first.frames[0].index + 1, sharpness=1.0)
    session.sets[0] = replace(first, frames=(other, *first.frames[1:]))
    assert history_fingerprint(session) == fingerprint
    session.sets[0] = replace(first, frames=first.frames[1:])
    assert history_fingerprint(session) != fingerprint


def test_the_history_kept_is_bounded_newest_steps_first(
        searched_session_file: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    session = load_session(searched_session_file)
    ids = [s.id for s in session.sets]
    writer = HistoryWriter()
    decisions = [Decided(ids[k % len(ids)], "undecided") for k in range(250)]
    entry = writer.entry(decisions, [], session)
    assert len(entry["undo"]) == undo_history.MAX_STEPS
    assert entry["undo"][-1] == {"step": "decided", "set": decisions[-1].set_id,
                                 "previous": "undecided"}

    # a removed set's details go first, then the oldest steps
    gone, session.sets = session.sets[0], session.sets[1:]
    details = session.extra["frame_details"][str(gone.id)]
    removed = Removed(gone, 0, details)
    size = len(json.dumps(undo_history.encode_step(removed)))
    monkeypatch.setattr(undo_history, "MAX_CHARS", size - 1)
    entry = HistoryWriter().entry([decisions[-1], removed], [], session)
    assert [d["step"] for d in entry["undo"]] == ["decided", "removed"]
    assert entry["undo"][1]["details"] is None
    monkeypatch.setattr(undo_history, "MAX_CHARS", 100)
    entry = HistoryWriter().entry([decisions[-1], removed], [], session)
    assert entry["undo"] == []
    # what is kept reads back in
    monkeypatch.undo()
    read = read_history(HistoryWriter().entry([removed], [], session), session)
    assert read.note == "" and read.undo == [removed]


def test_a_camera_left_out_keeps_the_history_with_the_cameras_kept(
        searched_session_file: Path) -> None:
    """Edit ▸ Leave a camera out opens the session again without it: the review's steps
    go on (a removed set comes back with the cameras kept), not dropped with a note."""
    from speechcal_core.review.loading import load_for_review
    from speechcal_core.sources import StreamChoice

    model = open_model(searched_session_file)
    model.accept()
    model.go_to_set(1)
    removed = model.current_set
    model.remove_set()
    left = removed.frames[-1].stream

    inputs = load_for_review(session_path=searched_session_file,
                             streams=StreamChoice(skip=(left,)))
    inputs.close()
    again = open_model(searched_session_file)
    assert again.history_note == ""
    assert again.undo_label == f"removing set {removed.id}"
    again.undo()
    back = again.session.set_by_id(removed.id)
    assert [f.stream for f in back.frames] == [f.stream for f in removed.frames[:-1]]
    assert left not in again.session.extra["frame_details"][str(removed.id)]["frames"]
    again.undo()
    assert again.session.sets[0].decision == "undecided"
    assert open_model(searched_session_file).history_note == ""


def test_a_removed_set_whose_place_was_edited_beyond_the_list_comes_back_in_time_order(
        truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    ids = [s.id for s in model.session.sets]
    model.go_to_set(1)
    model.remove_set()
    data = json.loads(truth_session_file.read_text())
    data[UNDO_HISTORY_KEY]["undo"][-1]["index"] = 1000
    truth_session_file.write_text(json.dumps(data))

    again = open_model(truth_session_file)
    again.undo()
    assert [s.id for s in again.session.sets] == ids
    assert again.current_set.id == ids[1]
