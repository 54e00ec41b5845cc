"""What the status line says of an offset edit: how far the audio moved, and whether
Ctrl+Z takes it back."""

from __future__ import annotations

#: the status line after C in a session whose cameras saw no clap
NO_CAMERA_CLAP = ("the cameras saw no clap in this session (its offset was given): move "
                  "the audio with [ ] { } or drag the clap handle")
UNDO_HINT = "Ctrl+Z takes it back"


def shift_text(shift_ns: int) -> str:
    """A shift of the audio with its sign and the digits it needs: "+1.250 s" from a
    second on, "-33.333 ms" or "+1 ms" from a millisecond, "+412 µs" under it, "+400 ns"
    under half a microsecond (it said "+0.000 s" of any shift under half a millisecond)."""
    micro = round(shift_ns / 1000)
    if micro == 0:
        return f"{shift_ns:+d} ns"
    if abs(micro) < 1000:
        return f"{micro:+d} µs"
    if abs(micro) < 1_000_000:
        return f"{micro / 1000:+g} ms"
    return f"{shift_ns / 1e9:+.3f} s"


def clap_moved_text(shift_ns: int) -> str:
    """The status line after C: how far the audio moved to put the clap at the playhead,
    or that it was there already (then no step was made: nothing to undo)."""
    if shift_ns == 0:
        return "the clap is at the playhead already: the audio did not move, nothing to undo"
    return f"the clap is at the playhead: audio moved {shift_text(shift_ns)} · {UNDO_HINT}"


def clap_drag_text(shift_ns: int, handle: str = "◂ clap ▸") -> str:
    """What the word band says while the clap handle (labelled ``handle``: the audio's
    start where there is no clap) is dragged ``shift_ns`` from where it was: how far the
    audio would move, and what releasing it or a right-click does (it said "between frame
    sets", the playhead being off the sets' times meanwhile)."""
    if shift_ns == 0:
        return f"{handle} where it was · released here, the audio stays"
    return (f"{handle} audio {shift_text(shift_ns)} · release to move it · "
            "right-click to cancel")


def offset_moved_text(shift_ns: int, how: str = "") -> str:
    """The status line after an offset edit ([ ] { }, the clap handle): how far the
    audio moved, after ``how`` ("one frame", "clap handle dragged"), or that it did not
    move (the handle released where it was: no step to undo)."""
    lead = f"{how}: " if how else ""
    if shift_ns == 0:
        return f"{lead}the audio did not move, nothing to undo"
    return f"{lead}audio moved {shift_text(shift_ns)} · {UNDO_HINT}"
