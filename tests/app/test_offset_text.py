"""How the status line puts an offset edit's shift: to the millisecond in seconds or
milliseconds, and a shift under a millisecond in µs (or ns), never "+0.000 s"."""

from __future__ import annotations

import pytest

from app.offset_text import clap_drag_text, clap_moved_text, shift_text


@pytest.mark.parametrize(("shift_ns", "said"), [
    (1_250_000_000, "+1.250 s"),
    (-2_000_400_000, "-2.000 s"),
    (250_000_000, "+250 ms"),
    (-33_333_333, "-33.333 ms"),
    (1_000_000, "+1 ms"),
    (999_999_700, "+1.000 s"),  # rounds up to a second: said in seconds
    (412_345, "+412 µs"),
    (-999_600, "-1 ms"),
    (-600, "-1 µs"),
    (-400, "-400 ns"),
    (1, "+1 ns"),
])
def test_a_shift_is_said_with_the_digits_it_needs(shift_ns: int, said: str) -> None:
    assert shift_text(shift_ns) == said


def test_c_that_moved_nothing_says_there_is_nothing_to_undo() -> None:
    assert clap_moved_text(400_000) == \
        "the clap is at the playhead: audio moved +400 µs · Ctrl+Z takes it back"
    text = clap_moved_text(0)
    assert "nothing to undo" in text and "Ctrl+Z" not in text and "moved" not in text


def test_a_clap_drag_says_how_far_the_audio_would_move_and_how_to_cancel() -> None:
    assert clap_drag_text(-250_000_000) == \
        "◂ clap ▸ audio -250 ms · release to move it · right-click to cancel"
    assert clap_drag_text(0) == "◂ clap ▸ where it was · released here, the audio stays"
