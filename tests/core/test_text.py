"""Counts in words: one camera, two cameras."""

from speechcal_core.text import counted


def test_counted_words_agree_with_their_number() -> None:
    assert counted(1, "camera") == "1 camera"
    assert counted(0, "frame set") == "0 frame sets"
    assert counted(12, "camera") == "12 cameras"
    assert counted(2, "match", "matches") == "2 matches"
