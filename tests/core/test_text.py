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


def test_a_figure_keeps_its_unit_and_sign_on_one_line() -> None:
    """The calibration check's line wrapped "RMS ≤ 0.22" and "px" apart at 1366 px."""
    from speechcal_core.text import unbroken_figures

    assert unbroken_figures("RMS ≤ 0.22 px; 2 cameras") == "RMS ≤\u00a00.22\u00a0px; 2 cameras"
    assert unbroken_figures("skew 4.1 ms, 3 s, 12 ppm, 5 %") == \
        "skew 4.1\u00a0ms, 3\u00a0s, 12\u00a0ppm, 5\u00a0%"
    assert unbroken_figures("2 sets, 3 spans") == "2 sets, 3 spans"  # words, not units
