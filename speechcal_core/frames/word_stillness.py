"""How many trigger words fall while the board is held still: a check on the audio and sync.

The operator holds the board still, then says the word, so with the session's own audio
and the right offset most words fall inside a still stretch of the cameras (the
best-still search's ``"stretch": "at"``; a word said as the board comes to rest does
not). With another session's audio, or an offset a second off, the words land anywhere,
in a move about as often as in a hold. On synthetic sessions (holds 0.8-2.5 s, moves
0.7-1.6 s, 11-33 words each) 0.65-0.96 of the words were at a still board with their own
audio (21 sessions) and 0.25-0.68 with another session's (13 pairs): too close for a
share to tell them apart in a short session. The count is judged by how much likelier
it is from words placed at random than from words said at a held board; 20 times
likelier flagged 9 of the 13 pairs and none of the 21 sessions. (Those shares count
"at" alone; a word inside the chosen stretch named "after" it counts too since a
12-camera session's words were mostly so: see ``_inside``.)
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from speechcal_core.session.model import FrameSet

#: the share of words at a still board with the session's own audio and offset
RIGHT_SHARE = 0.8
#: the share for words placed at random (the holds' share of the session)
CHANCE_SHARE = 0.5
#: a count this many times likelier by chance than from the right audio is doubtful
ODDS = 20.0
#: below this many words judged, nothing is said
MIN_WORDS = 10


@dataclass(frozen=True)
class WordStillness:
    """Of the sets the best-still search judged, how many have their word at a still board."""

    still: int
    judged: int

    @property
    def odds_of_chance(self) -> float:
        """How many times likelier this count is from words placed at random than from
        words said at a held board (binomial likelihood ratio)."""
        moving = self.judged - self.still
        return math.exp(self.still * math.log(CHANCE_SHARE / RIGHT_SHARE)
                        + moving * math.log((1 - CHANCE_SHARE) / (1 - RIGHT_SHARE)))

    @property
    def doubtful(self) -> bool:
        """Too few words at a still board for the audio and offset to be right."""
        return self.judged >= MIN_WORDS and self.odds_of_chance > ODDS


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
        still += stretch == "at" or _inside(frame_set.t_ns, entry.get("still_ns"))
    return WordStillness(still, judged)


def _inside(t_ns: int, still_ns: object) -> bool:
    """Whether ``t_ns`` lies in the still stretch around the chosen frame. The search
    names a stretch "after" the word where the one around it was cut short at times a
    camera had no frame near (12 cameras: 34 of 102 words said at a held board)."""
    return (isinstance(still_ns, list) and len(still_ns) == 2
            and still_ns[0] <= t_ns <= still_ns[1])


def moving_words_note(stillness: WordStillness, audio: str,
                      transcript: str | None = None) -> str:
    """The note a doubtful count gets ("" otherwise), naming the files to check: the
    audio, and the transcript when the words' times came from one."""
    if not stillness.doubtful:
        return ""
    files = f"{audio} this recording's audio" + (
        f" and {transcript} its transcript" if transcript else "")
    return (f"only {stillness.still} of {stillness.judged} trigger words fall while the board "
            f"is held still (with the session's own audio and the right offset most do): "
            f"is {files}? If so, check the offset (the clap, or --offset-ns)")
