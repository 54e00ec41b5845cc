"""Find more like this (S): a trigger the operator added by hand finds the others that
sound like it; they become undecided sets, one undo step, autosaved."""

from __future__ import annotations

from review_models import open_model
from truth_sessions import quiet_time_s

from speechcal_core.review.model import ADD_MIN_GAP_NS, set_time_ns
from speechcal_core.review.similar import SIMILAR_SOURCE, SessionAudio, result_message
from speechcal_core.session.store import load_session

SLACK_S = 0.1  # a set is on a trigger when its time lies inside the word +- this


def _on_trigger(t_s: float, triggers: list[dict]) -> bool:
    return any(t["start_s"] - SLACK_S <= t_s <= t["end_s"] + SLACK_S for t in triggers)


def _search(model, audio: SessionAudio):
    model.find_similar()
    assert model.similar_wanted is not None, model.similar_refused
    return model.similar_wanted.run(audio)


def test_marked_missed_trigger_finds_the_others_of_its_voice(missed_voice_file, noisy_synth):
    path, missed = missed_voice_file
    truth = noisy_synth[1]
    saves: list = []
    model = open_model(path, saves)
    before = {s.id: s for s in model.session.sets}
    model.set_playhead(missed[0]["session_ns"])  # the operator heard one and added it
    model.add_set()
    marked = model.current_set
    result = _search(model, SessionAudio(model.session.audio))

    assert result.bounds is not None  # the spoken word was found near the added set
    assert abs(result.bounds[0] - missed[0]["start_s"]) < 0.1
    assert abs(result.bounds[1] - missed[0]["end_s"]) < 0.1
    n_saves = len(saves)
    added = model.apply_similar(result)

    assert len(saves) == n_saves + 1  # one save for the whole search
    assert model.current_set == marked  # the operator stays where they were
    new = [s for s in model.session.sets if s.id in added]
    assert all(s.trigger.source == SIMILAR_SOURCE and s.decision == "undecided" for s in new)
    assert all(_on_trigger(s.trigger.t_s, truth["triggers"]) for s in new)
    found_missed = [m for m in missed[1:] if any(_on_trigger(s.trigger.t_s, [m]) for s in new)]
    assert len(found_missed) >= len(missed) - 2  # most of the voice's other triggers
    for s in new:  # no set lands on one the session had
        assert all(abs(s.t_ns - set_time_ns(o)) >= ADD_MIN_GAP_NS for o in before.values())
        assert all(f.index >= 0 for f in s.frames)  # nearest frames, re-scored later
        assert model.needs_rescore(s)
    stored = load_session(path)
    assert {s.id for s in stored.sets} >= set(added)
    assert "found" in result_message(result, len(added)) and f"set {marked.id}" in \
        result_message(result, len(added))


def test_searching_again_adds_nothing_twice(missed_voice_file):
    path, missed = missed_voice_file
    model = open_model(path)
    model.set_playhead(missed[0]["session_ns"])
    model.add_set()
    audio = SessionAudio(model.session.audio)
    first = model.apply_similar(_search(model, audio))
    assert first
    assert model.apply_similar(_search(model, audio)) == []  # all covered now


def test_undo_removes_every_set_one_search_added(missed_voice_file):
    path, missed = missed_voice_file
    model = open_model(path)
    model.set_playhead(missed[0]["session_ns"])
    model.add_set()
    with_marked = [s.id for s in model.session.sets]
    added = model.apply_similar(_search(model, SessionAudio(model.session.audio)))
    assert len(added) >= 2
    assert model.undo_label == f"adding {len(added)} sets"

    model.undo()
    assert model.redo_label == f"adding {len(added)} sets"  # not the inverse it holds
    assert [s.id for s in model.session.sets] == with_marked
    assert [s.id for s in load_session(path).sets] == with_marked  # autosaved
    model.redo()
    assert {s.id for s in model.session.sets} == set(with_marked) | set(added)
    model.undo()
    model.undo()  # and then the added set itself
    assert len(model.session.sets) == len(with_marked) - 1


def test_no_speech_near_the_set_says_so_and_adds_nothing(missed_voice_file, noisy_synth):
    path, _missed = missed_voice_file
    model = open_model(path)
    model.set_playhead(int(model.session.sync.to_session(quiet_time_s(noisy_synth[1]))))
    model.add_set()
    result = _search(model, SessionAudio(model.session.audio))
    assert result.bounds is None
    assert "no speech near" in result_message(result, 0)
    n = len(model.session.sets)
    assert model.apply_similar(result) == []
    assert len(model.session.sets) == n
    model.undo()  # the undo step is the added set's, not an empty search's
    assert len(model.session.sets) == n - 1


def test_no_set_to_search_from_says_what_to_do(missed_voice_file):
    model = open_model(missed_voice_file[0])
    while model.session.sets:
        model.remove_set()
    model.find_similar()
    assert model.similar_wanted is None
    assert "add a set there (T)" in model.similar_refused
