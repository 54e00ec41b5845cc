"""The headless review model: navigation, decisions, undo, autosave, tiles at the playhead."""

from __future__ import annotations

import copy
from dataclasses import replace
from pathlib import Path

from review_models import open_model

from speechcal_core.frames.nearest import nearest_choice
from speechcal_core.review.model import KEY_BINDINGS, ReviewModel, set_time_ns
from speechcal_core.session.store import load_session
from speechcal_core.sources import open_recording


def test_accept_reject_undo_redo_and_every_action_autosaves(truth_session_file: Path) -> None:
    saves: list = []
    model = open_model(truth_session_file, saves)
    assert len(model.session.sets) >= 3
    model.accept()
    model.next_set()
    model.reject()
    assert [s.decision for s in model.session.sets[:2]] == ["accepted", "rejected"]
    assert load_session(truth_session_file).sets[1].decision == "rejected"
    model.undo()
    assert model.session.sets[1].decision == "undecided"
    model.undo()
    assert model.session.sets[0].decision == "undecided"
    assert model.current == 0  # undo brings the undone set back into view
    model.redo()
    assert model.session.sets[0].decision == "accepted"
    assert len(saves) == 5
    assert load_session(truth_session_file).sets[0].decision == "accepted"


def test_a_decision_off_the_set_lands_on_the_set_shown_decided(truth_session_file) -> None:
    """Stepped away from the current set, A decides the set at the playhead if there is
    one, else the current set, and the playhead returns to it: the grid shows the frames
    the decision is on (it showed the nearest frames of another moment)."""
    model = open_model(truth_session_file)
    sets = model.session.sets
    model.go_to_set(1)
    gap = set_time_ns(sets[2]) - set_time_ns(sets[1])
    model.set_playhead(set_time_ns(sets[1]) + gap // 2)  # between two sets
    model.accept()
    assert [s.decision for s in sets[:3]] == ["undecided", "accepted", "undecided"]
    assert model.current == 1 and model.playhead_ns == set_time_ns(sets[1])
    assert all(tile.chosen for tile in model.tiles())
    model.set_playhead(set_time_ns(sets[2]) + 10_000_000)  # a scrub onto the next set
    model.reject()
    assert model.current == 2 and sets[2].decision == "rejected"
    assert model.playhead_ns == set_time_ns(sets[2])


def test_del_and_s_act_on_the_set_a_would_decide(truth_session_file) -> None:
    """Playback stopped on the next set's frames (the list still marks the set it
    started from): A decided the set shown, Del removed the one the list marked."""
    model = open_model(truth_session_file)
    sets = model.session.sets
    model.go_to_set(1)
    shown = sets[2]
    model.set_playhead(set_time_ns(shown) + 10_000_000)
    assert model.current == 1 and model.acting_set() is shown
    model.find_similar()
    assert model.similar_wanted is not None and model.similar_wanted.set_id == shown.id
    model.remove_set()
    assert shown.id not in [s.id for s in model.session.sets]
    assert sets[1].id in [s.id for s in model.session.sets]
    model.undo()
    assert model.current_set.id == shown.id


def test_of_two_sets_at_one_time_the_current_one_is_at_the_playhead(
        truth_session_file) -> None:
    """A false trigger that took a real set's frames sits at its time: W played the
    other set's word, as the first of the two in the list."""
    model = open_model(truth_session_file)
    sets = model.session.sets
    sets.insert(2, replace(sets[1], id=99))  # the same frames and time as sets[1]
    model.go_to_set(2)
    assert model.set_at_playhead() is sets[2] and model.acting_set() is sets[2]
    model.go_to_set(1)
    assert model.set_at_playhead() is sets[1]


def test_a_click_on_a_sets_word_goes_to_the_set_then_within_its_word(
        truth_session_file) -> None:
    """A set's time is its stillest frame, often after the word: a click on the word's
    mark shows that set's frames; once it is current, a click in its word moves the
    playhead there (to listen from inside the word)."""
    model = open_model(truth_session_file)
    word = model.session.sets[2].trigger
    inside = model.session.sync.to_session((word.start_s + word.end_s) / 2)
    model.click_word(model.session.sets[2].id, int(inside))
    assert model.current == 2 and model.playhead_ns == set_time_ns(model.session.sets[2])
    assert all(tile.chosen for tile in model.tiles())
    model.click_word(model.session.sets[2].id, int(inside))
    assert model.current == 2 and model.playhead_ns == int(inside)
    model.click_word(10_000, int(inside))  # a set removed meanwhile: nothing happens
    assert model.current == 2 and model.playhead_ns == int(inside)


def test_set_navigation_moves_the_playhead_to_the_set(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    seen = []
    model.connect("playhead", seen.append)
    model.last_set()
    assert model.playhead_ns == set_time_ns(model.session.sets[-1])
    model.next_set()  # stays on the last one
    assert model.current == len(model.session.sets) - 1
    model.first_set()
    assert seen[-1] == set_time_ns(model.session.sets[0])
    assert model.set_at_playhead() is model.session.sets[0]


def test_tiles_show_nearest_frames_and_say_when_none_is_near(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    model.go_to_set(0)
    tiles = model.tiles()
    assert [t.stream for t in tiles] == model.streams
    assert all(t.index >= 0 for t in tiles)
    for tile in tiles:
        period = 1e9 / 15
        assert abs(tile.offset_ns) <= period / 2 + 1
    _start, end = model.time_range_ns()
    model.playhead_ns = end + 10**9  # beyond every stream: nothing near
    assert all(t.index == -1 for t in model.tiles())


def test_frame_stepping_visits_every_stamp_in_order(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    model.go_to_set(1)
    before = model.playhead_ns
    model.next_frame()
    after = model.playhead_ns
    assert after > before
    all_stamps = sorted({int(s) for name in model.streams for s in model.source.stamps(name)})
    assert after == next(s for s in all_stamps if s > before)
    model.previous_frame()
    assert model.playhead_ns < after


def test_shift_stepping_moves_every_camera_on_by_a_frame(truth_session_file: Path) -> None:
    """With several free-running cameras the next stamp of any is a few ms away; Shift+→
    goes as far as every camera's next frame, Shift+← back past every camera's previous."""
    model = open_model(truth_session_file)
    model.go_to_set(1)
    before = model.playhead_ns
    stamps = {name: model.source.stamps(name) for name in model.streams}
    model.next_frame_of_every_camera()
    assert model.playhead_ns == max(int(s[s > before][0]) for s in stamps.values())
    for s in stamps.values():  # every camera has a new frame at or before the playhead
        assert int(s[s > before][0]) <= model.playhead_ns
    after = model.playhead_ns
    model.previous_frame_of_every_camera()
    assert model.playhead_ns == min(int(s[s < after][-1]) for s in stamps.values())
    assert KEY_BINDINGS["Shift+Right"] == "next_frame_of_every_camera"
    assert KEY_BINDINGS["Shift+Left"] == "previous_frame_of_every_camera"


def test_a_zero_offset_shift_changes_nothing(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    events = []
    model.connect("sync", events.append)
    model.preview_offset(20_000_000)  # the clap handle dragged ...
    model.nudge_offset(0)  # ... and released where it started
    assert model.session.sync.source == "auto" and events == []
    assert model.playhead_ns == set_time_ns(model.session.sets[model.current])
    assert load_session(truth_session_file).sync.source == "auto"


def test_a_clap_drag_shows_where_its_release_puts_the_current_set(
        searched_session_file: Path) -> None:
    """A set's still frame may lie tenths of a second from its trigger; moved by an
    offset edit, the set takes the frames nearest the trigger's new time (until
    re-scored), so the drag's preview shows that place, not the still frame's shifted."""
    model = open_model(searched_session_file)
    gaps = [abs(set_time_ns(s) - s.t_ns) for s in model.session.sets]
    model.go_to_set(gaps.index(max(gaps)))
    assert max(gaps) > 1e9 / 15  # the still frame more than a frame from the trigger
    model.preview_offset(150_000_000)
    preview = model.playhead_ns
    model.nudge_offset(150_000_000)
    assert abs(set_time_ns(model.current_set) - preview) <= 1e9 / 15 / 2 + 1


def test_a_clap_drag_away_from_the_sets_moves_the_playhead_with_its_sound(
        truth_session_file: Path) -> None:
    """On the clap, the playhead goes with the sound under it: each move of the drag
    from where it was before the drag (not from the last move's place), back there when
    the handle returns, and the release leaves it on the sound."""
    model = open_model(truth_session_file)
    seen = model.camera_clap_ns()
    model.set_playhead(seen)
    model.preview_offset(20_000_000)
    model.preview_offset(50_000_000)
    assert model.playhead_ns == seen + 50_000_000
    model.preview_offset(0)
    assert model.playhead_ns == seen
    model.preview_offset(30_000_000)
    model.set_playhead(seen + 100_000_000)  # playback moved it on meanwhile
    model.preview_offset(40_000_000)
    assert model.playhead_ns == seen + 140_000_000
    model.nudge_offset(40_000_000)  # released
    assert abs(model.playhead_ns - (seen + 140_000_000)) <= 1


def test_every_key_binding_names_an_action() -> None:
    for action in KEY_BINDINGS.values():
        assert callable(getattr(ReviewModel, action))


def test_offset_nudge_moves_sets_marks_sync_manual_and_saves(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    before = [s.t_ns for s in model.session.sets]
    events = []
    model.connect("sync", events.append)
    model.offset_plus_ms()
    assert [s.t_ns for s in model.session.sets] == [t + 1_000_000 for t in before]
    assert model.session.sync.source == "manual"
    model.nudge_offset_frame(-1)
    shift = model.session.sets[0].t_ns - before[0]
    assert -40_000_000 < shift < -30_000_000  # one 30 fps frame back, after +1 ms
    saved = load_session(truth_session_file)
    assert saved.sync.source == "manual" and saved.sets[0].t_ns == model.session.sets[0].t_ns
    assert len(events) == 2
    for s in model.session.sets:
        for f in s.frames:
            if f.index >= 0:
                assert abs(f.stamp_ns - s.t_ns) <= 1e9 / 15 / 2 + 1


def test_offset_edits_back_and_forth_take_each_time_the_frames_nearest_the_sets(
        truth_session_file: Path, monkeypatch) -> None:
    """An offset edit gives again the frame choices it made before (a held ] picks mostly
    the same frames): whatever it keeps, every set shows the frames nearest its time."""
    import speechcal_core.review.model as review_model

    model = open_model(truth_session_file)
    streams = {name: model.source.stamps(name) for name in model.streams}

    def nearest_everywhere() -> None:
        for s in model.session.sets:
            expected = [nearest_choice(name, stamps, s.t_ns) for name, stamps in streams.items()]
            assert list(s.frames) == expected

    for action in ("offset_plus_frame", "offset_plus_ms", "offset_minus_frame",
                   "offset_plus_frame", "offset_minus_ms", "offset_minus_frame"):
        model.trigger(action)
        nearest_everywhere()
    monkeypatch.setattr(review_model, "NEAREST_KNOWN_PER_SET", 0)  # what it kept, dropped
    model.offset_plus_frame()
    nearest_everywhere()
    assert all(len(known) <= len(model.session.sets) for known in model._nearest_known.values())
    model.undo()  # the frames measured for the sync before come back
    nearest_everywhere()


def test_the_set_at_the_playhead_follows_sets_changed_by_an_offset_edit(
        truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    second = model.session.sets[1]
    model.go_to_set(1)
    assert model.set_at_playhead().id == second.id
    model.offset_plus_frame()  # every set moves a frame on, the playhead with the current
    assert model.playhead_ns == set_time_ns(model.session.sets[1]) != set_time_ns(second)
    assert model.set_at_playhead() is model.session.sets[1]
    model.set_playhead(set_time_ns(second))  # where the set was: its old time
    assert model.set_at_playhead() is model.session.sets[1]  # within 50 ms still


def test_c_puts_the_sound_at_the_playhead_where_the_cameras_saw_the_clap(
        truth_session_file: Path) -> None:
    """A knock taken for the clap: the operator clicks the real clap on the waveform and
    presses C; the audio moves so that it lands on the cameras' clap."""
    model = open_model(truth_session_file)
    seen = model.camera_clap_ns()
    assert seen is not None
    before = model.session.sync
    model.set_playhead(seen + 2_500_000_000)  # the real clap, heard 2.5 s later
    heard_s = before.to_audio(model.playhead_ns)
    model.clap_at_playhead()
    assert abs(model.session.sync.to_session(heard_s) - seen) <= 1
    assert model.session.sync.source == "manual"
    model.undo()
    assert model.session.sync == before

    model.session.sync_evidence = {}  # an offset given by hand: no clap seen to go by
    model.clap_at_playhead()
    assert model.session.sync == before and model.undo_label == ""


def test_c_with_the_clap_already_at_the_playhead_changes_nothing(
        truth_session_file: Path) -> None:
    """No shift, no step: the clap heard stayed what it was, unsaved, or it was a change
    that no undo could take back."""
    saves: list = []
    model = open_model(truth_session_file, saves)
    seen = model.camera_clap_ns()
    model.set_playhead(seen)
    sync, evidence = model.session.sync, copy.deepcopy(model.session.sync_evidence)
    told: list = []
    model.connect("sync", told.append)
    saved = len(saves)
    model.clap_at_playhead()
    assert model.session.sync == sync and model.undo_label == ""
    assert model.session.sync_evidence == evidence
    assert told == [] and len(saves) == saved


def test_an_offset_edit_is_undone_and_redone_in_turn_with_decisions(
        truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    auto = model.session.sync
    before = [s.t_ns for s in model.session.sets]
    model.accept()  # an older step the undo must not reach first
    model.nudge_offset(100_000_000)
    assert model.session.sync.source == "manual"
    model.undo()  # the offset edit, not the decision
    assert model.session.sync == auto
    assert [s.t_ns for s in model.session.sets] == before
    assert model.session.sets[0].decision == "accepted"
    assert load_session(truth_session_file).sync == auto
    model.redo()
    assert model.session.sync.offset_ns == auto.offset_ns + 100_000_000
    model.undo()
    model.undo()  # now the decision
    assert model.session.sync == auto and model.session.sets[0].decision == "undecided"


def test_at_a_set_the_tiles_show_its_chosen_frames_and_their_warnings(
    truth_session_file: Path,
) -> None:
    session = load_session(truth_session_file)
    first = session.sets[0]
    source = open_recording(session.recording)
    # as the best-still-frame search would: every camera one frame later, one flagged
    later = []
    for n, f in enumerate(first.frames):
        i = f.index + 1
        stamp = int(source.stamps(f.stream)[i])
        later.append(replace(f, index=i, stamp_ns=stamp, flags=("blurred",) if n == 0 else ()))
    session.replace_set(replace(first, frames=tuple(later)))
    model = ReviewModel(session, source)
    model.go_to_set(0)
    tiles = model.tiles()
    assert [t.index for t in tiles] == [f.index for f in later]
    assert all(t.chosen for t in tiles)
    assert tiles[0].flags == ("blurred",) and tiles[1].flags == ()
    model.next_frame()  # off the set's time: plain nearest frames again
    assert not any(t.chosen for t in model.tiles())


def test_chosen_frames_carry_their_corners_and_drag_preview_changes_nothing(
    truth_session_file: Path,
) -> None:
    session = load_session(truth_session_file)
    first = session.sets[0]
    name = first.frames[0].stream
    session.extra["frame_details"] = {
        str(first.id): {"frames": {name: {"ids": [0, 1], "points": [[10.0, 20.5], [30, 40]]}}}
    }
    model = ReviewModel(session, open_recording(session.recording))
    model.go_to_set(0)
    tiles = {t.stream: t for t in model.tiles()}
    assert tiles[name].corners == ((10.0, 20.5), (30.0, 40.0))
    assert all(t.corners == () for s, t in tiles.items() if s != name)
    offset = model.session.sync.offset_ns
    model.preview_offset(20_000_000)
    assert model.playhead_ns == first.t_ns + 20_000_000
    assert model.session.sync.offset_ns == offset and model.session.sets[0] == first


def test_a_session_opens_again_at_the_set_and_filter_of_its_last_save(
    truth_session_file: Path,
) -> None:
    saves: list = []
    model = open_model(truth_session_file, saves)
    model.set_filter("undecided")
    model.go_to_set(2)
    model.advance_after_decision = False
    model.reject()  # a save: it keeps where the review is
    again = open_model(truth_session_file)
    assert (again.current, again.filter) == (2, "undecided")
    assert again.playhead_ns == set_time_ns(again.session.sets[2])

    model.go_to_set(3)  # moving about saves nothing ...
    assert len(saves) == 1 and open_model(truth_session_file).current == 2
    model.save_place()  # ... until the window closes
    assert len(saves) == 2 and open_model(truth_session_file).current == 3
    model.save_place()  # nothing moved since
    assert len(saves) == 2


def test_a_saved_place_whose_set_is_gone_opens_at_the_first_set(
    truth_session_file: Path,
) -> None:
    model = open_model(truth_session_file)
    model.go_to_set(len(model.session.sets) - 1)
    model.remove_set()  # the current set goes: the place saved is another set
    gone = open_model(truth_session_file)
    assert gone.current == model.current
    session = load_session(truth_session_file)
    session.extra["review_place"] = {"set": 9999, "filter": "no such filter"}
    model = ReviewModel(session, open_recording(session.recording))
    assert (model.current, model.filter) == (0, "all")


def test_opening_without_moving_saves_nothing(truth_session_file: Path) -> None:
    """A window that only looked (a screenshot) leaves the file as it was."""
    saves: list = []
    model = open_model(truth_session_file, saves)
    model.save_place()
    assert saves == []


def test_j_and_k_from_a_playhead_moved_between_sets_go_to_the_sets_around_it(
    truth_session_file: Path,
) -> None:
    """A click on the waveform between sets 1 and 2 (0-based) moves the playhead, not the
    current set (the last): K goes on to set 2, J back to set 1, not from the last set."""
    model = open_model(truth_session_file)
    times = [set_time_ns(s) for s in model.session.sets]
    last = len(times) - 1
    assert last >= 3
    between = (times[1] + times[2]) // 2
    model.go_to_set(last)
    model.set_playhead(between)
    model.next_set()
    assert model.current == 2 and model.playhead_ns == times[2]
    model.go_to_set(last)
    model.set_playhead(between)
    model.previous_set()
    assert model.current == 1
    model.next_set()  # at the current set: one on, as before
    assert model.current == 2

    model.set_filter("rejected")  # none rejected: the filter shows no set to go to
    model.set_playhead(between)
    model.next_set()
    assert model.current == 2 and model.playhead_ns == between
    model.set_filter("all")
    model.go_to_set(0)
    model.set_playhead(times[-1] + 1)  # past the last set: K goes to the last one
    model.next_set()
    assert model.current == last


def test_j_and_k_after_stepping_frames_off_the_set_go_on_from_it(
    truth_session_file: Path,
) -> None:
    """A frame back from set 2 and K: set 3, not set 2 again (the set after the
    playhead); a frame on from it and J: set 1."""
    model = open_model(truth_session_file)
    model.go_to_set(2)
    model.previous_frame()
    assert model.playhead_ns < set_time_ns(model.session.sets[2])
    model.next_set()
    assert model.current == 3
    model.go_to_set(2)
    model.next_frame()
    model.previous_set()
    assert model.current == 1


def test_a_step_that_goes_nowhere_says_why(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    first, last = model.session.sets[0].id, model.session.sets[-1].id
    model.previous_set()
    assert model.step_refused == f"no set listed before set #{first}"
    model.next_set()
    assert model.step_refused == ""
    model.last_set()
    model.next_set()
    assert model.step_refused == f"no set listed after set #{last}"
    model.set_filter("accepted")
    for step in (model.next_set, model.previous_set, model.first_set, model.last_set):
        step()
        assert model.step_refused.startswith("no accepted sets listed: F steps")
