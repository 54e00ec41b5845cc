"""Trigger words: case and punctuation ignored, inflections kept apart, several at once."""

from __future__ import annotations

import pytest

from speechcal_core.speech import SpeechError, TriggerSpec, Word, match_triggers, normalize_word


def test_case_and_punctuation_are_ignored() -> None:
    assert normalize_word("Capture!") == "capture"
    assert normalize_word("  «CAPTURE», ") == "capture"
    assert normalize_word("that's") == "that's"


def test_inflections_do_not_match_unless_configured() -> None:
    words = [Word("Capture!", 1.0, 1.5), Word("captured", 2.0, 2.6), Word("Mark.", 3.0, 3.3)]
    assert [w.word for w in match_triggers(words, TriggerSpec(("capture",)))] == ["capture"]
    both = TriggerSpec(("capture", "captured", "mark"))
    assert [w.word for w in match_triggers(words, both)] == ["capture", "captured", "mark"]


def test_trigger_time_is_the_mean_of_start_and_end() -> None:
    (hit,) = match_triggers([Word("capture", 1.0, 1.6, 0.9, "csv")], TriggerSpec())
    assert hit.t == pytest.approx(1.3)
    assert hit.to_json() == {"word": "capture", "start": 1.0, "end": 1.6, "t": 1.3,
                             "score": 0.9}


def test_bad_trigger_settings_name_the_fix() -> None:
    with pytest.raises(SpeechError, match="--trigger"):
        TriggerSpec(("",))
    with pytest.raises(SpeechError, match="single word"):
        TriggerSpec(("take picture",))
    with pytest.raises(SpeechError, match=r"0\.\.1"):
        TriggerSpec(("capture",), sensitivity=2.0)


def test_a_word_the_dictionary_lacks_is_answered_with_its_closest_spellings() -> None:
    """The operator writes the phones of a word the dictionary lacks: the message starts
    them from the words spelled most like it, not from an unrelated example."""
    from speechcal_core.speech.lexicon import pronunciations

    with pytest.raises(SpeechError) as err:
        pronunciations("kalibrate")
    assert str(err.value) == (
        "trigger word 'kalibrate' is not in the pocketsphinx dictionary; give its "
        "pronunciation in ARPAbet phones, as --pronounce 'kalibrate=PHONES'; the dictionary "
        "has calibrate = K AE L AH B R EY T, calibrated = K AE L AH B R EY T AH D")
    with pytest.raises(SpeechError, match=r"'qzxv=PHONES'; the dictionary writes capture = "
                                          r"K AE P CH ER$"):
        pronunciations("qzxv")  # nothing spelled like it: how a known word is written
