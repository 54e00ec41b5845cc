"""Which heard clap is the cameras' clap: the one that lays the audio's sound over the video.

Loudness alone cannot tell the opening clap from the closing one when the microphone ran
long before or after the cameras, or started after the opening clap. Matching a heard
clap with the cameras' clap fixes the offset, and with it where every sound of the audio
falls on the camera clock. The right pairing puts the sound the operator made (speech,
claps) over the video; a wrong one moves it before or after the recording.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import percentile_filter

from speechcal_core.audio.loader import Audio
from speechcal_core.sync.clap_audio import ClapCandidate

BLOCK_S = 0.1  # level blocks
ACTIVE_DB = 6.0  # a block this far above the quiet level around it holds sound
#: the quiet level around a block: this percentile of the blocks within QUIET_SPAN_S
#: (steady noise of any level, a fan or traffic after the cameras stopped, is its own
#: quiet level: only what rises out of it, speech and claps, counts)
QUIET_PERCENTILE = 10.0
QUIET_SPAN_S = 4.0
DIGITAL_SILENCE_DB = -100.0  # blocks below this are padding, not room noise
#: heard claps whose pairing lays this much less of the sound over the video than the
#: best pairing are other sounds; among the rest the clearest clap wins
COVER_SLACK = 0.1
#: below this share of the sound over the video, the pairing is doubted
LOW_COVER = 0.5


@dataclass(frozen=True)
class SoundTimes:
    """Audio seconds of the blocks that hold sound above the room's quiet level."""

    times_s: np.ndarray

    def share_over(self, audio_s: float, video_ns: int, span_ns: tuple[int, int]) -> float:
        """Share of the sound that falls within ``span_ns`` (camera clock) when the audio
        moment ``audio_s`` is the camera moment ``video_ns`` (no drift)."""
        if self.times_s.size == 0:
            return 0.0
        before, after = self.shares_outside(audio_s, video_ns, span_ns)
        return 1.0 - before - after

    def shares_outside(self, audio_s: float, video_ns: int, span_ns: tuple[int, int]
                       ) -> tuple[float, float]:
        """Shares of the sound before ``span_ns`` starts and after it ends, paired as in
        :meth:`share_over` (0, 0 without sound)."""
        if self.times_s.size == 0:
            return 0.0, 0.0
        at_ns = video_ns + (self.times_s - audio_s) * 1e9
        n = self.times_s.size
        return (float(np.count_nonzero(at_ns < span_ns[0])) / n,
                float(np.count_nonzero(at_ns > span_ns[1])) / n)


def sound_times(audio: Audio) -> SoundTimes:
    """Blocks of ``audio`` that stand out of its quiet level (digital silence never does)."""
    hop = max(1, round(audio.rate * BLOCK_S))
    n = audio.samples.size // hop
    if n == 0:
        return SoundTimes(np.zeros(0))
    blocks = audio.samples[: n * hop].reshape(n, hop)
    power = np.einsum("ij,ij->i", blocks, blocks, dtype=np.float64) / hop
    level = 10.0 * np.log10(power + 1e-20)
    live = level > DIGITAL_SILENCE_DB
    if not np.any(live):
        return SoundTimes(np.zeros(0))
    span = max(3, round(QUIET_SPAN_S / BLOCK_S) | 1)
    # padding takes the quietest live level, so the start of the sound after it counts
    filled = np.where(live, level, float(np.min(level[live])))
    quiet = percentile_filter(filled, QUIET_PERCENTILE, size=span, mode="nearest")
    active = np.flatnonzero(live & (level > quiet + ACTIVE_DB))
    return SoundTimes((active + 0.5) * BLOCK_S)


@dataclass(frozen=True)
class OpeningChoice:
    """The heard clap taken for the cameras' clap and the share of sound it lays over them."""

    clap: ClapCandidate
    share: float


def choose_opening(claps: Sequence[ClapCandidate], sound: SoundTimes, video_ns: int,
                   span_ns: tuple[int, int]) -> OpeningChoice:
    """The heard clap to pair with the cameras' clap at ``video_ns``.

    Each heard clap is tried as the cameras' clap; the pairings that lay nearly the most
    sound over the video ``span_ns`` stay, and of those the clearest clap wins, the
    louder of equally clear ones (a knock just before the clap moves the sound only a
    little, and clap-likeness tops out at 1). ``claps`` must not be empty.
    """
    return candidates(claps, sound, video_ns, span_ns)[0]


def candidates(claps: Sequence[ClapCandidate], sound: SoundTimes, video_ns: int,
               span_ns: tuple[int, int]) -> list[OpeningChoice]:
    """The heard claps that may be the cameras' clap at ``video_ns``, best first (see
    :func:`choose_opening`)."""
    shares = [sound.share_over(c.time_s, video_ns, span_ns) for c in claps]
    best = max(shares)
    kept = [OpeningChoice(c, s) for c, s in zip(claps, shares, strict=True)
            if s >= best - COVER_SLACK]
    return sorted(kept, key=lambda o: (clearest_first(o.clap), o.clap.time_s))


def clearest_first(clap: ClapCandidate) -> tuple[float, float]:
    """Sort key putting the clearest claps first, the louder of equally clear ones
    (clap-likeness tops out at 1, so many real claps tie on it)."""
    return -round(clap.score, 2), -clap.peak_dbfs


def claps_after(claps: Sequence[ClapCandidate], first: ClapCandidate,
                min_gap_s: float) -> list[ClapCandidate]:
    """The heard claps at least ``min_gap_s`` after ``first``, clearest first: the
    candidates for the closing clap."""
    return sorted((c for c in claps if c.time_s >= first.time_s + min_gap_s),
                  key=clearest_first)


def closing_after(claps: Sequence[ClapCandidate], first: ClapCandidate,
                  min_gap_s: float) -> ClapCandidate | None:
    """The clearest heard clap at least ``min_gap_s`` after ``first``: the closing clap."""
    late = claps_after(claps, first, min_gap_s)
    return late[0] if late else None
