"""Find trigger words again (the window's Ctrl+F): the operator's words and sensitivity,
checked before anything runs; the words found become undecided sets beside the ones
there, whose decisions stay; one undo step; the settings kept in the session file."""

from __future__ import annotations

from pathlib import Path

import pytest
from review_models import open_model

from speechcal_core.errors import UsageError
from speechcal_core.review.detect_again import (
    detect_request,
    detection_settings,
    parse_trigger_text,
    result_message,
)
from speechcal_core.session.model import PRONUNCIATIONS_KEY, SENSITIVITY_KEY
from speechcal_core.session.store import load_session

SLACK_S = 0.1  # a set is on a trigger when its time lies inside the word +- this


def _on_trigger(t_s: float, triggers: list[dict]) -> bool:
    return any(t["start_s"] - SLACK_S <= t_s <= t["end_s"] + SLACK_S for t in triggers)


def test_typed_words_are_split_normalised_and_may_carry_a_pronunciation() -> None:
    assert parse_trigger_text("Capture!, snapshot") == (("capture", "snapshot"), {})
    assert parse_trigger_text(" capture  snapshot ,capture") == (("capture", "snapshot"), {})
    assert parse_trigger_text("capture, Kalibr = k ae l ih b er") == (
        ("capture", "kalibr"), {"kalibr": "K AE L IH B ER"})
    # the word right before "=" takes the phones, up to the next comma
    assert parse_trigger_text("capture kalibr=K AE L IH B ER, snapshot") == (
        ("capture", "kalibr", "snapshot"), {"kalibr": "K AE L IH B ER"})
    with pytest.raises(UsageError, match="gives no word or no phones"):
        parse_trigger_text("=K AE")


def test_words_the_detector_cannot_look_for_are_refused_with_what_to_type(
        wrong_word_session_file: Path) -> None:
    session = load_session(wrong_word_session_file)
    with pytest.raises(UsageError, match=r"no trigger word given: type at least one, e\.g\. "
                                         r"capture"):
        detect_request(session, " , ", 0.5)
    with pytest.raises(UsageError, match="“foo-bar” is not a single word: separate words "
                                         "with commas or spaces"):
        detect_request(session, "capture, foo-bar", 0.5)
    with pytest.raises(UsageError, match=r"“kalibrr” is not in the pocketsphinx dictionary: "
                                         r"write its pronunciation after it in ARPAbet phones, "
                                         r"as in kalibr=K AE L IH B ER; the dictionary "
                                         r"has kalberer = K AE L B ER ER"):
        detect_request(session, "capture, kalibrr", 0.5)
    with pytest.raises(UsageError, match="unknown phones"):
        detect_request(session, "kalibrr=K AE L QQ", 0.5)
    request = detect_request(session, "Snapshot, kalibrr=K AE L IH B ER", 0.7)
    assert request.words == ("snapshot", "kalibrr") and request.sensitivity == 0.7
    assert request.pronunciations == {"kalibrr": "K AE L IH B ER"}
    assert Path(request.audio) == Path(session.audio)


def test_a_processed_session_remembers_its_sensitivity(wrong_word_session_file: Path) -> None:
    session = load_session(wrong_word_session_file)
    assert session.extra[SENSITIVITY_KEY] == 0.5
    assert detection_settings(session) == ("capture", 0.5)
    session.extra[SENSITIVITY_KEY] = "loud"  # damaged or hand-edited: the default
    session.extra[PRONUNCIATIONS_KEY] = {"capture": "K AE P CH ER"}
    assert detection_settings(session) == ("capture=K AE P CH ER", 0.5)


def test_the_word_said_becomes_sets_and_the_session_keeps_it(
        wrong_word_session_file: Path, snapshot_synth: tuple[Path, dict]) -> None:
    truth = snapshot_synth[1]
    saves: list = []
    model = open_model(wrong_word_session_file, saves)
    assert model.session.sets == []  # "capture" was never said
    progress: list[float] = []
    result = detect_request(model.session, "snapshot", 0.6).run(
        lambda _text, f: progress.append(f))
    assert progress[0] == 0.0 and progress[-1] == 1.0 and progress == sorted(progress)
    added = model.apply_detected(result)

    said = truth["triggers"]
    assert len(added) >= len(said) - 1 and len(saves) == 1  # one save for all of them
    new = model.session.sets
    assert {s.id for s in new} == set(added)
    assert all(s.decision == "undecided" and s.trigger.word == "snapshot" for s in new)
    assert all(s.trigger.source.startswith("pocketsphinx") for s in new)
    assert all(_on_trigger(s.trigger.t_s, said) for s in new)
    assert all(model.needs_rescore(s) for s in new)  # best still frames follow
    assert model.undo_label == f"adding {len(added)} sets"
    stored = load_session(wrong_word_session_file)
    assert stored.triggers_word == ["snapshot", "capture"]  # T now adds a "snapshot"
    assert stored.extra[SENSITIVITY_KEY] == 0.6
    assert len(stored.sets) == len(added)
    message = result_message(result, len(added))
    assert message.startswith(f"found {len(result.words)} × “snapshot” at sensitivity 0.60")

    model.undo()  # the sets go, and the settings they were found with
    assert model.session.sets == []
    stored = load_session(wrong_word_session_file)
    assert stored.triggers_word == ["capture"] and stored.extra[SENSITIVITY_KEY] == 0.5
    model.redo()
    stored = load_session(wrong_word_session_file)
    assert len(stored.sets) == len(added) and stored.triggers_word == ["snapshot", "capture"]
    assert stored.extra[SENSITIVITY_KEY] == 0.6


def test_a_detection_stops_between_spans_when_its_progress_raises(
        wrong_word_session_file: Path) -> None:
    class Stop(Exception):
        pass

    calls: list[float] = []

    def progress(_text: str, fraction: float) -> None:
        calls.append(fraction)
        if fraction > 0.1:  # the audio is read: decoding has begun
            raise Stop

    request = detect_request(load_session(wrong_word_session_file), "snapshot", 0.5)
    with pytest.raises(Stop):
        request.run(progress)
    assert calls[-1] < 1.0


def test_detecting_again_keeps_the_sets_there_and_their_decisions(
        wrong_word_session_file: Path) -> None:
    model = open_model(wrong_word_session_file)
    request = detect_request(model.session, "snapshot", 0.5)
    first = model.apply_detected(request.run())
    assert len(first) >= 2
    model.go_to_set(0)
    model.accept()
    model.go_to_set(1)
    model.reject()
    decided = {s.id: s.decision for s in model.session.sets}

    again = request.run()
    assert model.apply_detected(again) == []  # every word found has its set already
    assert {s.id: s.decision for s in model.session.sets} == decided
    assert result_message(again, 0).endswith("every one is in the list already")
    one = result_message(again, 1)  # as if one word had been new
    assert f"a new undecided set; {len(again.words) - 1} already in the list; accept or " \
        "reject it as usual" in one


def test_a_word_not_said_adds_nothing_and_says_so(wrong_word_session_file: Path) -> None:
    model = open_model(wrong_word_session_file)
    result = detect_request(model.session, "calibrate", 0.5).run()
    assert model.apply_detected(result) == []
    assert model.session.triggers_word == ["capture"]  # nothing found: settings unchanged
    assert "no trigger word (calibrate) found" in result_message(result, 0)
