"""How many trigger words fall while the board is held still: a check on the audio and sync.

The operator holds the board still, then says the word, so with the session's own audio
and the right offset nearly every word falls inside a still stretch of the cameras (the
best-still search's ``"stretch": "at"``). With another session's audio, or an offset
seconds off, the words land anywhere, in a move as often as in a hold. On synthetic
sessions (holds 0.8-2.5 s, moves 0.7-1.6 s, 18-33 words each): 0.77-0.96 of the words in
a still stretch with their own audio, 0.32-0.68 with another session's.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from speechcal_core.session.model import FrameSet

#: fewer of the words than this share at a still board is doubtful
STILL_SHARE = 2 / 3
#: below this many words judged, chance decides too much to say anything
MIN_WORDS = 10


@dataclass(frozen=True)
class WordStillness:
    """Of the sets the best-still search judged, how many have their word at a still board."""

    still: int
    judged: int

    @property
    def doubtful(self) -> bool:
        """Too few words at a still board for the audio and offset to be right."""
        return self.judged >= MIN_WORDS and self.still < STILL_SHARE * self.judged


def word_stillness(sets: Iterable[FrameSet], details: Mapping[str, object]) -> WordStillness:
    """Count the sets whose word falls inside a still stretch, per their frame details
    (``details[str(set_id)]["stretch"]``). Sets without one (no frame at the word, not
    searched yet) or with one searched at another time (an offset edit not yet re-scored)
    are not judged."""
    still = judged = 0
    for frame_set in sets:
        entry = details.get(str(frame_set.id))
        if not isinstance(entry, dict) or entry.get("trigger_ns") != frame_set.t_ns:
            continue
        stretch = entry.get("stretch")
        if stretch is None:
            continue
        judged += 1
        still += stretch == "at"
    return WordStillness(still, judged)


def moving_words_note(stillness: WordStillness, audio: str) -> str:
    """The note a doubtful count gets ("" otherwise), naming the audio file to check."""
    if not stillness.doubtful:
        return ""
    return (f"only {stillness.still} of {stillness.judged} trigger words fall while the board "
            f"is held still (with the session's own audio and the right offset nearly all "
            f"do): is {audio} this recording's audio? If it is, check the offset (the clap, "
            "or --offset-ns)")
