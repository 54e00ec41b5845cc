"""Counts in words: one camera, two cameras."""

from speechcal_core.text import counted, shown_name


def test_counted_words_agree_with_their_number() -> None:
    assert counted(1, "camera") == "1 camera"
    assert counted(0, "frame set") == "0 frame sets"
    assert counted(12, "camera") == "12 cameras"
    assert counted(2, "match", "matches") == "2 matches"


def test_a_name_that_is_not_utf8_is_shown_with_a_replacement_mark() -> None:
    """A window title dropped the byte: "rec.bag" named a file that does not exist."""
    import os

    assert shown_name(os.fsdecode(b"r\xe9c.bag")) == "r\ufffdc.bag"
    assert shown_name("réc.bag") == "réc.bag"
