"""The frame-set list's figures and filters, headless: worst quality per set, which sets show."""

from __future__ import annotations

import pytest

from speechcal_core.review.model import KEY_BINDINGS, ReviewModel
from speechcal_core.review.summary import (
    FILTERS,
    camera_lines,
    list_place,
    no_sets_hint,
    passes,
    shown_indices,
    summarize,
)
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
from speechcal_core.sync.model import SyncModel

S = 1_000_000_000


def frame_set(set_id: int, *frames: FrameChoice, decision: str = "undecided") -> FrameSet:
    t_ns = set_id * 3 * S
    return FrameSet(set_id, t_ns, Trigger("capture", set_id * 3.0, set_id * 3.0 + 0.4),
                    frames or (FrameChoice("/cam0", set_id, t_ns),), decision)


def test_summary_keeps_the_worst_sharpness_and_the_fewest_corners_over_cameras() -> None:
    s = frame_set(1, FrameChoice("/cam0", 10, 0, 0.92, 144),
                  FrameChoice("/cam1", 11, 0, 0.31, 96),
                  FrameChoice("/cam2", 12, 0, 1.10, 120))
    q = summarize(s)
    assert (q.worst_sharpness, q.fewest_corners) == (0.31, 96)
    assert (q.frames_found, q.frames_total) == (3, 3)
    assert q.flags == () and q.flagged == ()
    assert not (q.sharpness_warned or q.corners_warned or q.skew_warned or q.frames_warned)


def test_unknown_figures_and_cameras_without_a_frame_are_left_out_of_the_summary() -> None:
    s = frame_set(1, FrameChoice("/cam0", 10, 0, None, 144),
                  FrameChoice("/cam1", 11, 0, 0.5, None),
                  FrameChoice("/cam2", -1, 0, 0.01, 0, ("no-frame",)))
    q = summarize(s)
    assert (q.worst_sharpness, q.fewest_corners) == (0.5, 144)
    assert (q.frames_found, q.frames_total) == (2, 3)
    assert q.frames_warned and not q.sharpness_warned


def test_a_set_of_nearest_frames_has_no_quality_figures() -> None:
    q = summarize(frame_set(1, FrameChoice("/cam0", 10, 0), FrameChoice("/cam1", 11, 0)))
    assert q.worst_sharpness is None and q.fewest_corners is None
    assert summarize(FrameSet(1, 0, Trigger("capture", 0.0, 0.4), ())).frames_total == 0


@pytest.mark.parametrize(("flag", "warned"), [
    ("blurred", "sharpness_warned"),
    ("moving", "sharpness_warned"),
    ("no-target", "corners_warned"),
    ("skew", "skew_warned"),
    ("bad-frame", "frames_warned"),
    ("something-new", "frames_warned"),  # a flag no figure covers still warns somewhere
])
def test_each_quality_flag_warns_on_one_figure(flag: str, warned: str) -> None:
    q = summarize(frame_set(1, FrameChoice("/cam0", 10, 0, 0.9, 144),
                            FrameChoice("/cam1", 11, 0, 0.2, 3, (flag,))))
    figures = ("sharpness_warned", "corners_warned", "skew_warned", "frames_warned")
    assert [getattr(q, f) for f in figures] == [f == warned for f in figures]
    assert q.flagged == (("/cam1", (flag,)),)


def test_flags_of_every_camera_are_listed_once() -> None:
    q = summarize(frame_set(1, FrameChoice("/cam0", 10, 0, 0.1, 0, ("blurred", "no-target")),
                            FrameChoice("/cam1", 11, 0, 0.2, 3, ("no-target", "skew"))))
    assert q.flags == ("blurred", "no-target", "skew")


def test_camera_lines_give_each_cameras_figures_and_flags() -> None:
    s = frame_set(1, FrameChoice("/cam0", 10, 0, 0.923, 144),
                  FrameChoice("/cam1", 11, 0, 0.1, 0, ("blurred", "no-target")),
                  FrameChoice("/cam2", -1, 0, flags=("no-frame",)),
                  FrameChoice("/cam3", 12, 0))
    assert camera_lines(s).splitlines() == [
        "/cam0: sharpness 0.92, 144 corners",
        "/cam1: sharpness 0.10, 0 corners  ▲ blurred, target not found",
        "/cam2: no frame",
        "/cam3: sharpness –, – corners",
    ]


def decided_sets() -> list[FrameSet]:
    return [frame_set(i + 1, decision=d) for i, d in enumerate(
        ("accepted", "undecided", "rejected", "undecided", "accepted"))]


def test_filters_keep_the_sets_with_their_decision_in_order() -> None:
    sets = decided_sets()
    assert shown_indices(sets, "all") == [0, 1, 2, 3, 4]
    assert shown_indices(sets, "undecided") == [1, 3]
    assert shown_indices(sets, "accepted") == [0, 4]
    assert shown_indices(sets, "rejected") == [2]
    assert shown_indices([], "accepted") == []
    assert passes(sets[0], "all") and not passes(sets[0], "rejected")
    with pytest.raises(ValueError, match="filter must be one of"):
        passes(sets[0], "maybe")


def model_over(sets: list[FrameSet]) -> ReviewModel:
    return ReviewModel(Session(["rec.bag"], None, SyncModel(0), list(sets)))


def test_filter_is_a_model_action_that_tells_listeners_and_keeps_the_current_set() -> None:
    model = model_over(decided_sets())
    seen: list[str] = []
    model.connect("filter", seen.append)
    assert model.filter == "all" and model.shown() == [0, 1, 2, 3, 4]
    model.set_filter("undecided")
    assert model.shown() == [1, 3]
    assert model.current == 0  # hidden now, still the set under review
    model.set_filter("undecided")  # no change, no event
    assert seen == ["undecided"]
    with pytest.raises(ValueError):
        model.set_filter("maybe")


def test_f_cycles_through_the_filters() -> None:
    model = model_over(decided_sets())
    assert KEY_BINDINGS["F"] == "next_filter"
    seen = []
    for _ in FILTERS:
        model.trigger("next_filter")
        seen.append(model.filter)
    assert seen == [*FILTERS[1:], FILTERS[0]]


def test_set_steps_go_through_the_sets_the_filter_shows() -> None:
    model = model_over(decided_sets())
    model.set_filter("undecided")
    model.next_set()  # from the hidden first set to the next shown one
    assert model.current == 1
    model.next_set()
    assert model.current == 3
    model.next_set()  # the last shown: stays
    assert model.current == 3
    model.previous_set()
    assert model.current == 1
    model.last_set()
    assert model.current == 3
    model.first_set()
    assert model.current == 1
    model.set_filter("accepted")  # the current set is hidden: steps start from it
    model.next_set()
    assert model.current == 4
    model.set_filter("undecided")
    model.next_set()  # hidden and nothing shown after it: stays
    assert model.current == 4
    model.previous_set()
    assert model.current == 3


def test_deciding_under_a_filter_keeps_the_set_current_and_steps_skip_it() -> None:
    model = model_over(decided_sets())
    model.set_filter("undecided")
    model.go_to_set(1)
    model.accept()
    assert model.shown() == [3] and model.current == 1
    model.previous_set()  # nothing undecided before it
    assert model.current == 1
    model.next_set()
    assert model.current == 3
    model.set_filter("rejected")
    model.reject()
    model.undo()  # the undone set is brought back into view, hidden or not
    assert model.current == 3 and model.shown() == [2]


def test_with_no_set_shown_steps_do_nothing() -> None:
    model = model_over(decided_sets()[:2])
    model.set_filter("rejected")
    for step in ("next_set", "previous_set", "first_set", "last_set"):
        model.trigger(step)
        assert model.current == 0
    empty = model_over([])
    empty.next_filter()
    empty.next_set()
    empty.last_set()
    assert empty.current == -1 and empty.shown() == []


def test_the_word_column_marks_triggers_the_operator_added_or_searched_for() -> None:
    from speechcal_core.review.model import OPERATOR_SOURCE
    from speechcal_core.review.similar import SIMILAR_SOURCE
    from speechcal_core.review.summary import SOURCE_MARKS, trigger_line, word_text

    assert set(SOURCE_MARKS) == {OPERATOR_SOURCE, SIMILAR_SOURCE}
    heard = frame_set(1)
    added = FrameSet(2, 6 * S, Trigger("capture", 6.0, 6.0, 1.0, OPERATOR_SOURCE),
                     heard.frames)
    found = FrameSet(3, 9 * S, Trigger("capture", 9.0, 9.4, 0.7, SIMILAR_SOURCE),
                     heard.frames)
    assert [word_text(s) for s in (heard, added, found)] == [
        "capture", "capture · added", "capture · similar"]
    assert trigger_line(added) == "trigger 'capture' (manual), at 6.00 s in the audio"
    assert trigger_line(found) == "trigger 'capture' (similar), 9.00-9.40 s in the audio"


def test_after_a_removal_under_a_filter_the_next_shown_set_becomes_current() -> None:
    model = model_over(decided_sets())  # accepted, undecided, rejected, undecided, accepted
    model.set_filter("accepted")
    model.first_set()
    model.remove_set()  # the next set, undecided, is hidden: the next accepted one instead
    assert model.current_set.id == 5 and model.current in model.shown()
    model.undo()
    assert model.current_set.id == 1
    model.last_set()
    model.remove_set()  # nothing shown after it: the last shown before it
    assert model.current_set.id == 1
    model.set_filter("rejected")
    model.first_set()
    model.remove_set()  # the filter shows nothing now: the set that took its place
    assert model.shown() == [] and model.current_set.id == 4


def test_an_empty_session_says_why_and_how_to_get_sets() -> None:
    session = Session(recording=["rec.bag"], audio="mic.ogg", sync=SyncModel(0, 0.0),
                      sets=[], triggers_word=["capture"],
                      extra={"detection_notes": ["mic.ogg: no trigger word (capture) found"]})
    hint = no_sets_hint(session)
    assert hint.startswith("mic.ogg: no trigger word (capture) found. Said another word?")
    assert "Edit ▸ Find trigger words… (Ctrl+F)" in hint
    assert "press T" in hint and "then S" in hint
    session.audio = None  # nothing to find another word in
    assert "Ctrl+F" not in no_sets_hint(session) and "press T" in no_sets_hint(session)
    session.audio = "mic.ogg"
    session.extra = {}  # a session from elsewhere, without the detector's notes
    assert no_sets_hint(session).startswith("No “capture” was found in the audio.")
    # every set found removed in the review (the hint said none was found)
    assert no_sets_hint(session, removed=True).startswith(
        "No frame sets left: every “capture” was removed (Ctrl+Z puts the last back).")
    session.sets = [frame_set(1)]
    assert no_sets_hint(session) == ""


def test_advancing_after_a_decision_goes_to_the_next_set_the_filter_shows() -> None:
    model = model_over(decided_sets())
    model.advance_after_decision = True
    model.set_filter("undecided")
    model.go_to_set(1)
    model.accept()  # set 1 leaves the filter; the next undecided set is 3
    assert model.current == 3 and model.session.sets[1].decision == "accepted"
    model.reject()  # nothing shown after set 3: it stays current, decided
    assert model.current == 3 and model.session.sets[3].decision == "rejected"
    model.undo()
    model.undo()  # each undo brings its set back into view
    assert model.current == 1 and model.session.sets[1].decision == "undecided"

    model.set_filter("all")
    model.go_to_set(0)
    model.accept()  # already accepted: no undo step, yet the operator moves on
    assert model.current == 1 and model.undo_label == ""


def test_a_sets_place_is_counted_among_the_sets_the_filter_lists() -> None:
    sets = [frame_set(1, decision="rejected"), frame_set(2), frame_set(3, decision="rejected"),
            frame_set(4)]
    assert list_place(sets, "all", 2) == "3/4"
    assert list_place(sets, "rejected", 2) == "2/2 rejected"
    assert list_place(sets, "undecided", 3) == "2/2 undecided"
    assert list_place(sets, "undecided", 0) == "not among the 2 undecided"
    assert list_place(sets, "accepted", 0) == "no accepted sets listed"
