"""What the frame-set list shows per set: worst quality over its cameras, and the filters.

Sharpness is as :mod:`speechcal_core.frames.sets` stores it: each camera's sharpness over
that of its frames of the board held still around the trigger (where the board never
stops there, over the 90th percentile of the camera's chosen frames in the session), so
1.0 is as sharp as the still board, whatever the camera's resolution or optics and the
board's distance, and the figures of different cameras compare. A set is only as good as
its worst camera, so the summary keeps the lowest sharpness and the fewest target corners.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

from speechcal_core.text import WARNING_SYMBOL, counted

if TYPE_CHECKING:
    from collections.abc import Sequence

    from speechcal_core.session.model import FrameChoice, FrameSet, Session

#: the frame-set list's filters, in the order a key press cycles through them
FILTERS = ("all", "undecided", "accepted", "rejected")

#: quality flags each summary figure warns about; any other flag goes with the frame count
SHARPNESS_FLAGS = ("blurred", "moving")
CORNER_FLAGS = ("no-target",)
SKEW_FLAGS = ("skew",)

#: how the window words a flag (a flag not listed reads as it is: "blurred", "moving")
FLAG_WORDS = {"no-target": "target not found", "bad-frame": "unreadable frame",
              "no-frame": "no frame"}


#: the same in a word or two, for a camera tile too narrow for the words above (a
#: 12-camera grid on a 1366 px screen cut "target not found" to "targ…")
FLAG_SHORT_WORDS = {"no-target": "no board", "bad-frame": "bad frame", "blurred": "blur",
                    "no-frame": "no frame"}


def flag_words(flags: Sequence[str]) -> str:
    """Quality flags in the window's words: "blurred, target not found"."""
    return ", ".join(FLAG_WORDS.get(flag, flag) for flag in flags)


def flag_short_words(flags: Sequence[str]) -> str:
    """Quality flags in the fewest words that still say each: "blur, no board"."""
    return ", ".join(FLAG_SHORT_WORDS.get(flag, flag) for flag in flags)


#: how the list marks a trigger the detector did not report, by ``Trigger.source``: added
#: by hand (``T``) or found like another set (``S``)
SOURCE_MARKS = {"manual": "added", "similar": "similar"}


def review_work(session: Session) -> str:
    """What an operator did in ``session`` ("12 decisions, 2 sets added"); "" for nothing.
    (An edited offset does not count: ``--offset-ns`` gives one too.)"""
    decided = len(session.sets) - session.counts()["undecided"]
    added = sum(1 for s in session.sets if s.trigger.source in SOURCE_MARKS)
    work = [counted(decided, "decision")] if decided else []
    if added:
        work.append(f"{counted(added, 'set')} added")
    return ", ".join(work)


def word_text(frame_set: FrameSet) -> str:
    """The set's trigger word, marked when the operator added or searched for it."""
    mark = SOURCE_MARKS.get(frame_set.trigger.source)
    return f"{frame_set.trigger.word} · {mark}" if mark else frame_set.trigger.word


def listed_ids(ids: Sequence[int]) -> str:
    """Set ids as the list's # column shows them: "#10", "#10, #12"."""
    return ", ".join(f"#{i}" for i in ids)


def same_frames_line(ids: Sequence[int]) -> str:
    """Why a set whose frames sets ``ids`` show too is marked, and what to do (tooltip)."""
    return (f"{WARNING_SYMBOL} the same frames as set {listed_ids(ids)}: two trigger words "
            "in one still hold, one of them likely heard by mistake (W plays each set's word). The "
            "calibration check and exports count these frames once")


def trigger_line(frame_set: FrameSet) -> str:
    """Where the trigger came from and where it lies in the audio, for a tooltip."""
    t = frame_set.trigger
    where = (f"at {t.start_s:.2f} s" if t.end_s <= t.start_s
             else f"{t.start_s:.2f}-{t.end_s:.2f} s")
    return f"trigger {t.word!r} ({t.source}), {where} in the audio"


def passes(frame_set: FrameSet, filter_name: str) -> bool:
    """Whether ``filter_name`` (one of :data:`FILTERS`) shows ``frame_set``."""
    if filter_name not in FILTERS:
        raise ValueError(f"filter must be one of {FILTERS}, got {filter_name!r}")
    return filter_name == "all" or frame_set.decision == filter_name


def shown_indices(sets: Sequence[FrameSet], filter_name: str) -> list[int]:
    """Indices into ``sets`` of the sets ``filter_name`` shows, in order."""
    return [i for i, s in enumerate(sets) if passes(s, filter_name)]


def list_place(sets: Sequence[FrameSet], filter_name: str, index: int) -> str:
    """Where ``sets[index]`` stands among the sets the list shows (J/K step through those):
    "2/14" with every set listed, "2/5 undecided" under a filter, and for a set the filter
    hides (decided there, or a filter chosen after) "not among the 5 undecided", or "no
    accepted sets listed"."""
    shown = shown_indices(sets, filter_name)
    kind = "" if filter_name == "all" else f" {filter_name}"
    if index in shown:
        return f"{shown.index(index) + 1}/{len(shown)}{kind}"
    if not shown:
        return f"no{kind} sets listed"
    return f"not among the {len(shown)}{kind}"


@dataclass(frozen=True)
class SetSummary:
    """One set's quality as the list shows it (None: no camera has the figure)."""

    worst_sharpness: float | None
    fewest_corners: int | None
    frames_found: int
    frames_total: int
    #: (stream, its flags) for every camera whose chosen frame has quality flags
    flagged: tuple[tuple[str, tuple[str, ...]], ...]

    @cached_property  # each warning asks for them (the list: 4 times per set)
    def flags(self) -> tuple[str, ...]:
        """Every flag any camera has, each once, in the order first seen."""
        return tuple(dict.fromkeys(f for _stream, fl in self.flagged for f in fl))

    @property
    def sharpness_warned(self) -> bool:
        return not _SHARPNESS_FLAGS.isdisjoint(self.flags)

    @property
    def corners_warned(self) -> bool:
        return not _CORNER_FLAGS.isdisjoint(self.flags)

    @property
    def skew_warned(self) -> bool:
        return not _SKEW_FLAGS.isdisjoint(self.flags)

    @property
    def frames_warned(self) -> bool:
        """A camera without a frame, or a flag none of the quality figures covers."""
        return (self.frames_found < self.frames_total
                or not _FIGURE_FLAGS.issuperset(self.flags))


#: the flags above as sets (the list asks each set's summary for every warning)
_SHARPNESS_FLAGS, _CORNER_FLAGS, _SKEW_FLAGS = (
    frozenset(SHARPNESS_FLAGS), frozenset(CORNER_FLAGS), frozenset(SKEW_FLAGS))
_FIGURE_FLAGS = _SHARPNESS_FLAGS | _CORNER_FLAGS | _SKEW_FLAGS


def summarize(frame_set: FrameSet) -> SetSummary:
    """The worst sharpness and fewest corners over the cameras that have a chosen frame."""
    chosen = [f for f in frame_set.frames if f.index >= 0]
    sharp = [f.sharpness for f in chosen if f.sharpness is not None]
    corners = [f.corners for f in chosen if f.corners is not None]
    return SetSummary(
        worst_sharpness=min(sharp) if sharp else None,
        fewest_corners=min(corners) if corners else None,
        frames_found=len(chosen),
        frames_total=len(frame_set.frames),
        flagged=tuple((f.stream, f.flags) for f in frame_set.frames if f.flags),
    )


def camera_lines(frame_set: FrameSet) -> str:
    """Per camera its sharpness, corners and flags, one line each (for a tooltip)."""
    return "\n".join(_camera_line(f) for f in frame_set.frames)


def _camera_line(f: FrameChoice) -> str:
    if f.index < 0:
        figures = "no frame"
    else:
        sharp = "–" if f.sharpness is None else f"{f.sharpness:.2f}"
        corners = "–" if f.corners is None else str(f.corners)
        figures = f"sharpness {sharp}, {corners} corners"
    flags = [fl for fl in f.flags if not (f.index < 0 and fl == "no-frame")]
    return f"{f.stream}: {figures}" + (f"  {WARNING_SYMBOL} {flag_words(flags)}" if flags else "")


#: the window's command that detects trigger words again, and its key
FIND_WORDS = "Find trigger words"
FIND_WORDS_KEY = "Ctrl+F"


def no_sets_hint(session: Session, removed: bool = False) -> str:
    """Why a session has no frame sets and what the operator can do ("" when it has some):
    the detector's notes (no speech, no trigger word found, ...), or that the operator
    ``removed`` them, and the ways to sets."""
    if session.sets:
        return ""
    notes = [str(n).rstrip() for n in session.extra.get("detection_notes") or []]
    words = ", ".join(f"“{w}”" for w in session.triggers_word) or "trigger word"
    if removed:
        said = f"No frame sets left: every {words} was removed (Ctrl+Z puts the last back)."
    else:
        said = " ".join(n if n.endswith((".", "?", "!")) else f"{n}." for n in notes if n) \
            or f"No {words} was found in the audio."
    other = f" Said another word? Edit ▸ {FIND_WORDS}… ({FIND_WORDS_KEY}) looks for it." \
        if session.audio else ""
    return (f"{said}{other} Or put the playhead on a spoken trigger, press T to add a set, "
            f"then S to find more like it.")
