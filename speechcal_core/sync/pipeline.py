"""Sync a recording with its microphone track: claps in audio and in every camera."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.sources.depth import stream_depth
from speechcal_core.sources.errors import SourceError
from speechcal_core.sources.stats import ANOTHER_RECORDING
from speechcal_core.sync.clap_audio import ClapCandidate, audio_levels, find_audio_claps
from speechcal_core.sync.clap_choice import (
    LOW_COVER,
    OpeningChoice,
    SoundTimes,
    candidates,
    choose_opening,
    claps_after,
    clearest_first,
    closing_after,
    sound_times,
)
from speechcal_core.sync.clap_frames import full_gray, small_gray
from speechcal_core.sync.clap_video import VideoClap, find_video_claps
from speechcal_core.sync.errors import SyncError
from speechcal_core.sync.estimate import (
    MAX_DRIFT,
    CameraClap,
    Clap,
    SyncResult,
    build_result,
)

if TYPE_CHECKING:
    from speechcal_core.audio.loader import Audio
    from speechcal_core.sources.base import FrameSource, StreamInfo

SEARCH_S = 20.0  # the first clap is looked for in this much video from each stream's start
NEAR_S = 2.0  # other cameras (and the closing clap) are looked for this close to the expected time
AGREE_S = 0.3  # camera clocks closer than this count as seeing the same event
MIN_CLAP_GAP_S = 5.0  # a closing clap lies at least this long after the first
CLOSING_SHARE = 0.2  # ... and at least this share of the video's length after it
CLOSING_TRIES = 3  # heard claps tried as the closing one in the video, clearest first
GAP_SLACK_S = 0.05  # two clap gaps (audio, video) match this closely beyond the drift
ROW_S = 1.5  # claps this close together are one row (a double clap)
ROW_MATCH_S = 0.06  # a heard clap and a seen event of a row match this closely
#: full-resolution frames kept for the clap timing (events near each other share frames):
#: about 130 gray 1280x720 frames, more than the ~4 s a timing reads at 30 fps
DETAIL_CACHE_BYTES = 128 << 20

Progress = Callable[[str], None]
#: how to go on without a clap heard: ``sync`` takes it by hand, ``process`` the offset
BY_HAND = ("set the clap by hand (speechcal sync --audio-clap SECONDS prints the offset; "
           "process takes it as --offset-ns N)")


#: with one clap, the drift is taken as 0: a note says so when the audio runs this long
#: past the clap (a typical drift then puts the last words more than a few ms off)
ONE_CLAP_NOTE_S = 120.0
TYPICAL_DRIFT = 50e-6

def heard_claps(audio: Audio) -> tuple[list[ClapCandidate], list[str]]:
    """Every clap heard in the audio, in time order, and warnings about the audio itself.

    Raises :class:`SyncError` for silent audio or audio without any clap-like sound.
    """
    name = str(audio.path) if audio.path else "audio"
    levels = audio_levels(audio)
    notes: list[str] = []
    if levels.silent:
        level = ("every sample is zero" if levels.peak_dbfs == -np.inf
                 else f"peak {levels.peak_dbfs:.0f} dBFS")
        n = audio.channels_in_file
        if audio.channel is None and n > 1:  # channels of opposite polarity cancel
            raise SyncError(f"{name}: its {n} channels mixed are silent ({level}); channels "
                            f"of opposite polarity cancel: pick one with --channel (0..{n - 1})"
                            f", or check the microphone, or {BY_HAND}")
        raise SyncError(f"{name}: the audio is silent ({level}){_cut_short(audio, name)}; "
                        f"check the microphone and the channel, or {BY_HAND}")
    if levels.clipped:
        notes.append(f"{name}: {levels.clipped_fraction * 100:.3f}% of samples clip at full "
                     "scale; clap timing still works, but lower the input gain next time")
    cands = find_audio_claps(audio, max_candidates=20)
    claps = sorted((c for c in cands if c.is_clap), key=lambda c: c.time_s)
    if not claps:
        best = (f"; the sharpest sound, at {cands[0].time_s:.3f} s, does not look like a "
                "clap") if cands else ""
        cut = _cut_short(audio, name)
        if cut:  # the clap may lie in the part that does not decode
            raise SyncError(f"{name}: no clap found in the audio{best}{cut}; else {BY_HAND}")
        raise SyncError(f"{name}: no clap found in the audio{best}; clap once, sharply, "
                        f"where camera and microphone both catch it, or {BY_HAND}")
    return claps, notes


def _cut_short(audio: Audio, name: str) -> str:
    """"; only the first 1.4 s of the 32.4 s its header gives decode; ..." when the file
    decoded to well short of its length (``cut_short_note``), else "": what was looked
    for may lie in the rest. ``detect`` says it as a note, but sync fails before that."""
    from speechcal_core.audio.loader import cut_short_note

    note = cut_short_note(audio)
    return "; " + note.removeprefix(f"{name}: ") if note else ""


def audio_claps(audio: Audio) -> tuple[ClapCandidate, ClapCandidate | None, list[str]]:
    """The first clap, the closing clap (or None) and warnings, from the audio alone.

    Without the cameras to pair them with, the first clap is the clearest one in the first
    half of the span the heard claps cover. Raises :class:`SyncError` as :func:`heard_claps`.
    """
    claps, notes = heard_claps(audio)
    middle = (claps[0].time_s + claps[-1].time_s) / 2
    first = max((c for c in claps if c.time_s <= middle), key=lambda c: c.score)
    last = closing_after(claps, first, MIN_CLAP_GAP_S)
    return first, last, notes + _clipped_note(audio, [c for c in (first, last) if c])


def _clipped_note(audio: Audio, used: list[ClapCandidate]) -> list[str]:
    if any(c.clipped for c in used):
        return [f"{audio.path or 'audio'}: the clap clips; its onset is still used"]
    return []


def video_clap(source: FrameSource, stream: str, t0_ns: int, t1_ns: int) -> VideoClap | None:
    """The clap seen by one camera between two of its header stamps."""
    found = video_clap_candidates(source, stream, t0_ns, t1_ns)
    return found[0] if found else None


def video_clap_candidates(source: FrameSource, stream: str, t0_ns: int,
                          t1_ns: int) -> list[VideoClap]:
    """Clap-like events seen by one camera between two of its header stamps, best first."""
    stamps = source.stamps(stream)
    i0, i1 = np.searchsorted(stamps, [t0_ns, t1_ns])
    if i1 - i0 < 5:
        return []
    small: np.ndarray | None = None  # the work-size frames, one float32 stack
    kept: list[int] = []
    scale = 1.0
    depth = stream_depth(source, stream)
    info = next(s for s in source.streams if s.name == stream)
    for i in range(int(i0), int(i1)):
        try:
            img, scale = small_gray(source, info, i, depth)
        except SourceError:  # a bad frame is skipped, not fatal
            continue
        if small is None:
            small = np.empty((int(i1 - i0), *img.shape), np.float32)
        elif img.shape != small.shape[1:]:
            continue
        small[len(kept)] = img
        kept.append(int(stamps[i]))
    if small is None or len(kept) < 5:
        return []
    index = [int(np.searchsorted(stamps, k)) for k in kept]
    detail = _detail_reader(source, info, index, depth)
    return find_video_claps(small[:len(kept)], np.array(kept), stream=stream, scale=scale,
                            detail=detail)


def _detail_reader(source: FrameSource, info: StreamInfo, index: list[int],
                   depth: int | None) -> Callable[[int], np.ndarray]:
    """Frame ``index[j]`` at full resolution (:func:`clap_frames.full_gray`), the most
    recently read kept up to DETAIL_CACHE_BYTES."""
    cache: OrderedDict[int, np.ndarray] = OrderedDict()
    held = 0

    def detail(j: int) -> np.ndarray:
        nonlocal held
        img = cache.get(j)
        if img is not None:
            cache.move_to_end(j)
            return img
        img = full_gray(source, info, index[j], depth)
        cache[j] = img
        held += img.nbytes
        while held > DETAIL_CACHE_BYTES and len(cache) > 1:
            held -= cache.popitem(last=False)[1].nbytes
        return img

    return detail


def video_claps(source: FrameSource, t0: dict[str, int], t1: dict[str, int],
                progress: Progress | None = None, which: str = "clap",
                events: list[VideoClap] | None = None) -> list[VideoClap]:
    """Each stream's clap in its window [t0, t1], chosen so that the cameras agree.

    Every camera proposes its clap-like events; the moment most cameras share (within
    ``AGREE_S``; ties go to the clearer events) is the clap, and each camera contributes
    its event nearest to it. A camera that saw nothing there contributes nothing: its
    best event elsewhere (another sound's motion, frames after the clap) would pull the
    clap's session time off. ``which`` names the clap in the progress messages; every
    camera's clap-like events are added to ``events`` when given.
    """
    proposals: dict[str, list[VideoClap]] = {}
    for name in t0:
        if progress:
            progress(f"looking for the {which} in {name}")
        found = video_clap_candidates(source, name, t0[name], t1[name])
        if found:
            proposals[name] = found
    if not proposals:
        return []
    every = [c for found in proposals.values() for c in found]
    if events is not None:
        events.extend(every)
    agree = int(AGREE_S * 1e9)

    def support(c: VideoClap) -> tuple[int, int, float]:
        cams = {o.stream for o in every if abs(o.clap_ns - c.clap_ns) <= agree}
        return len(cams), int(c.method == "v-fit"), c.score

    anchor = max(every, key=support)
    out = []
    for found in proposals.values():
        near = [c for c in found if abs(c.clap_ns - anchor.clap_ns) <= agree]
        if near:
            out.append(min(near, key=lambda c: abs(c.clap_ns - anchor.clap_ns)))
    return out


def sync_recording(source: FrameSource, audio: Audio, *, search_s: float = SEARCH_S,
                   streams: list[str] | None = None,
                   audio_clap_s: float | None = None,
                   progress: Progress | None = None) -> SyncResult:
    """Find the clap(s) in audio and video and return the sync model with its evidence.

    ``audio_clap_s`` replaces the audio detection with a clap time set by hand.
    Raises :class:`SyncError` when no clap can be found on either side.
    """
    infos = [s for s in source.streams if streams is None or s.name in streams]
    if not infos:
        raise SyncError("the recording has no image streams to find the clap in")
    notes: list[str] = []
    heard: list[ClapCandidate] = []
    if audio_clap_s is None:
        heard, notes = heard_claps(audio)
    t0 = {s.name: s.first_ns for s in infos}
    t1 = {s.name: min(s.last_ns, s.first_ns + int(search_s * 1e9)) for s in infos}
    seen_events: list[VideoClap] = []
    cams1 = video_claps(source, t0, t1, progress, events=seen_events)
    if not cams1:
        # two recordings given as one interleave their frames: that hides any clap
        mixed = [f"{s.name}: {s.stamp_problems}; "
                 + ("give one recording's files, or " if ANOTHER_RECORDING in s.stamp_problems
                    else "")
                 for s in infos if s.stamp_problems]
        raise SyncError(f"no clap seen in the first {search_s:g} s of any camera "
                        f"({', '.join(t0)}); {mixed[0] if mixed else ''}make the clap "
                        "visible to the cameras, search longer (speechcal sync --search-s S), "
                        "or set it by hand (speechcal sync --video-clap-ns NS prints the "
                        "offset; process takes it as --offset-ns N)")
    pairing = None
    if audio_clap_s is None:
        pairing = _pair_heard_with_seen(source, audio, heard, cams1, infos, search_s, progress,
                                        seen_events)
        cams1, notes = pairing.cameras, notes + pairing.notes
        a1, audio_source = pairing.first.time_s, "auto"
    else:
        a1, audio_source = float(audio_clap_s), "manual"
    notes += _unseen_notes(source, cams1, infos)
    claps = [Clap(a1, tuple(_camera(c) for c in cams1), audio_source, "auto")]
    chosen_first, notes_before = claps[0], list(notes)
    tied = pairing.tied if pairing is not None else []
    if pairing is not None and pairing.late:
        claps, more, tied = _closing_from_video(source, claps[0], heard, pairing, infos,
                                                search_s, progress)
        notes += more
    else:
        beyond_s = max(audio.duration_s - a1, a1)  # from the clap to the audio's far end
        if beyond_s >= ONE_CLAP_NOTE_S:
            shift_ms = beyond_s * TYPICAL_DRIFT * 1e3
            notes.append(f"one clap: drift not measured (taken as 0); a typical "
                         f"{TYPICAL_DRIFT * 1e6:.0f} ppm would put the words farthest from "
                         f"it {shift_ms:.0f} ms off: clap again at the end of a long "
                         "recording")
    if tied:  # (a pair at both ends can tie too)
        taken = claps[0].audio_s
        others = ", ".join(f"{c.time_s:.3f} s" for c in tied)
        notes.append(f"claps heard at {taken:.3f} s and {others} fit the cameras' clap "
                     f"alike: {taken:.3f} s was taken; if the cameras saw the other, the offset is "
                     f"off by their gap: check the clap in the review window, or give "
                     f"--audio-clap {tied[0].time_s:.3f}")
    notes += _clipped_note(audio, [c for c in heard if c.time_s in {k.audio_s for k in claps}])
    result = build_result(claps, notes, extra={
        "audio": {"path": str(audio.path) if audio.path else None, "rate": audio.rate,
                  "duration_s": round(audio.duration_s, 6)},
        "video": [c.to_dict() for c in cams1],
    })
    if len(result.claps) == 2 and any("implausible" in w for w in result.warnings):
        # the pair matched only within the slack (a short gap): neither it nor the first
        # clap it may have moved stands; the first clap chosen before it does
        keep = build_result([chosen_first], [*notes_before, "the second clap did not match; "
                                             "drift set to 0"], extra=result.extra)
        return keep
    return result


@dataclass(frozen=True)
class _Pairing:
    """The heard clap matched with the cameras' clap, the closing clap to try, and notes."""

    first: ClapCandidate
    cameras: list[VideoClap]
    #: heard claps that may be the closing one, clearest first (none: one clap only)
    late: list[ClapCandidate]
    notes: list[str]
    #: how far apart the heard claps that could be the first one lie (seconds): the
    #: closing clap is looked for that much wider in the video
    doubt_s: float = 0.0
    #: heard claps right by the first that fit the cameras' clap as well (a second clap
    #: the cameras did not see as one): only a closing clap can tell them apart
    tied: list[ClapCandidate] = field(default_factory=list)
    #: every clap-like event the cameras saw around their first clap, and its time
    events: list[VideoClap] = field(default_factory=list)
    seen_ns: int = 0
    #: the cameras' claps at the video's end, once looked for (None: not yet)
    end_claps: list[VideoClap] | None = None


def _pair_heard_with_seen(source: FrameSource, audio: Audio, heard: list[ClapCandidate],
                          seen: list[VideoClap], infos: list, search_s: float,
                          progress: Progress | None,
                          seen_events: list[VideoClap] | None = None) -> _Pairing:
    """Which heard clap the cameras' first clap is (:mod:`clap_choice`).

    When no heard clap lays most of the audio's sound over the video, the microphone may
    have started after the opening clap: the heard clap is then matched with a clap at
    the end of the video, if the cameras saw one there and that lays the sound over them.
    """
    span = (min(s.first_ns for s in infos), max(s.last_ns for s in infos))
    seen_ns = int(np.median([c.clap_ns for c in seen]))
    sound = sound_times(audio)
    options = candidates(heard, sound, seen_ns, span)
    choice = options[0]
    tied: list[ClapCandidate] = []
    if seen_events:  # two or three claps in a row: the one in the cameras' place
        placed, tied = _in_the_same_place(heard, choice.clap, seen_events, seen_ns)
        choice = OpeningChoice(placed, choice.share)
    video_s = (span[1] - span[0]) / 1e9
    min_gap_s = max(MIN_CLAP_GAP_S, CLOSING_SHARE * video_s)
    doubt_s = max(o.clap.time_s for o in options) - min(o.clap.time_s for o in options)

    def later(first: ClapCandidate) -> list[ClapCandidate]:
        return claps_after(heard, first, min_gap_s)[:CLOSING_TRIES]

    if choice.share >= LOW_COVER or sound.times_s.size == 0:
        return _Pairing(choice.clap, seen, later(choice.clap), [], doubt_s, tied,
                        list(seen_events or []), seen_ns)
    at_end = _claps_at_end(source, infos, search_s, seen_ns, progress)
    name = audio.path.name if audio.path else "the audio"
    if at_end:
        end_ns = int(np.median([c.clap_ns for c in at_end]))
        both = _pair_for_gap(heard, (end_ns - seen_ns) / 1e9)
        if both is not None:  # both claps heard, as far apart as the cameras saw them
            return _Pairing(both[0][0], seen, [both[0][1]], [], end_claps=at_end)
        alt = choose_opening(heard, sound, end_ns, span)
        if alt.share >= LOW_COVER and alt.share >= 2 * choice.share:
            into_s = (end_ns - span[0]) / 1e9
            return _Pairing(alt.clap, at_end, [], [
                f"{name}'s clap at {alt.clap.time_s:.3f} s is the cameras' closing "
                f"clap ({into_s:.1f} s into the recording): the microphone started after "
                "the opening clap; drift not measured (taken as 0)"])
    return _Pairing(choice.clap, seen, later(choice.clap), [
        _outside_note(name, choice, sound, seen_ns, span)], doubt_s, end_claps=at_end)


def _outside_note(name: str, choice: OpeningChoice, sound: SoundTimes, seen_ns: int,
                  span: tuple[int, int]) -> str:
    """Much of the audio's sound falls outside the recording with the clap chosen: where
    it falls, the harmless reading (the microphone ran longer than the cameras) and the
    harmful ones."""
    before, after = sound.shares_outside(choice.clap.time_s, seen_ns, span)
    return (f"with {name}'s clap at {choice.clap.time_s:.3f} s as the cameras' clap, "
            f"{100 * (before + after):.0f}% of its sound falls outside the recording "
            f"({100 * before:.0f}% before the cameras started, {100 * after:.0f}% after "
            "they stopped). That is right if the microphone ran longer than the cameras "
            "(talk before or after the recording); if it started after the opening clap, "
            "or the clap heard is another sound, check the offset in the review window "
            f"or {BY_HAND}")


def _in_the_same_place(heard: list[ClapCandidate], choice: ClapCandidate,
                       events: list[VideoClap], seen_ns: int
                       ) -> tuple[ClapCandidate, list[ClapCandidate]]:
    """Of claps heard in a row (a double clap), the one that stands among the others as
    the cameras' clap stands among the clap-like events they saw around it, and the ones
    that fit as well (the cameras saw one clap where two were heard).

    Each heard clap within ROW_S of ``choice`` is tried in its place: the heard claps'
    offsets from it should be where the cameras saw events (ROW_MATCH_S), and no event
    the cameras saw should lack its heard clap. The best fit wins; ``choice`` on a tie.
    """
    row = [c for c in heard if abs(c.time_s - choice.time_s) <= ROW_S]
    if len(row) < 2:
        return choice, []
    seen = np.array(sorted({round((e.clap_ns - seen_ns) / 1e9, 3) for e in events
                            if abs(e.clap_ns - seen_ns) <= ROW_S * 1e9 + 1}))

    def fit(o: ClapCandidate) -> int:
        offsets = np.array([c.time_s - o.time_s for c in heard
                            if abs(c.time_s - o.time_s) <= ROW_S])
        heard_seen = sum(bool(np.any(np.abs(seen - d) <= ROW_MATCH_S)) for d in offsets)
        seen_heard = sum(bool(np.any(np.abs(offsets - v) <= ROW_MATCH_S)) for v in seen)
        return heard_seen + seen_heard

    best = max(row, key=lambda o: (fit(o), o is choice))
    return best, [o for o in row if o is not best and fit(o) == fit(best)]


def _claps_at_end(source: FrameSource, infos: list, search_s: float, first_ns: int,
                  progress: Progress | None) -> list[VideoClap]:
    """The cameras' clap in the last ``search_s`` of the video, but not before
    MIN_CLAP_GAP_S after the first clap at ``first_ns`` (a short video's end would hold
    the first clap too)."""
    gap = int(MIN_CLAP_GAP_S * 1e9)
    t0 = {s.name: max(s.first_ns, s.last_ns - int(search_s * 1e9), first_ns + gap)
          for s in infos}
    t1 = {s.name: s.last_ns for s in infos}
    return [c for c in video_claps(source, t0, t1, progress, which="closing clap")
            if c.clap_ns - first_ns >= gap]


def _pair_for_gap(heard: list[ClapCandidate], gap_s: float,
                  pairing: _Pairing | None = None
                  ) -> tuple[tuple[ClapCandidate, ClapCandidate], list[ClapCandidate]] | None:
    """Two heard claps as far apart as the cameras saw theirs (``gap_s``, drift and
    timing allowed for): the clearest such pair, or where double claps make several,
    the one whose first clap stands in the cameras' clap's place (``pairing``'s events),
    with the first claps of the pairs that fit as well; None if none."""
    tolerance = MAX_DRIFT * gap_s + GAP_SLACK_S
    pairs = sorted(((a, b) for a in heard for b in heard
                    if b.time_s > a.time_s and abs((b.time_s - a.time_s) - gap_s) <= tolerance),
                   key=_clearest_pair_first)
    if not pairs:
        return None
    if len(pairs) == 1 or pairing is None or not pairing.events:
        return pairs[0], []  # the gap tells claps in a row apart
    openings = [a for a, _b in pairs]
    best, tied = _in_the_same_place(heard, openings[0], pairing.events, pairing.seen_ns)
    return (next((p for p in pairs if p[0] is best), pairs[0]),
            [t for t in tied if t in openings])


def _clearest_pair_first(pair: tuple[ClapCandidate, ClapCandidate]) -> tuple[float, float]:
    """:func:`clap_choice.clearest_first` for two claps together."""
    (score_a, loud_a), (score_b, loud_b) = map(clearest_first, pair)
    return score_a + score_b, loud_a + loud_b


def _closing_from_video(source: FrameSource, first: Clap, heard: list[ClapCandidate],
                        pairing: _Pairing, infos: list, search_s: float,
                        progress: Progress | None
                        ) -> tuple[list[Clap], list[str], list[ClapCandidate]]:
    """The claps (the first, and the closing one when the cameras saw it), notes, and the
    heard claps that fit the cameras' first clap as well as the one taken.

    Each heard clap that may close the recording (clearest first) is looked for in the
    video where the first clap's offset puts it. Where the cameras saw a clap there, the
    heard pair as far apart as the cameras' two claps is taken: that may also correct
    the first clap (a knock or a second clap just after it).
    """
    for late in pairing.late:
        second = _closing_clap(source, first, late.time_s, infos, progress,
                               extra_s=pairing.doubt_s)
        if second is None:
            continue
        found = _pair_for_gap(heard, (second.session_ns - first.session_ns) / 1e9, pairing)
        if found is not None:
            return (*_with_pair(first, second, found[0]), found[1])
    # none of them where the first clap puts it: the cameras' own closing clap, if they
    # saw one at the end, may still match a heard pair (a false start: a clap before the
    # cameras ran was taken for the first)
    at_end = pairing.end_claps if pairing.end_claps is not None else \
        _claps_at_end(source, infos, search_s, first.session_ns, progress)
    if at_end:
        second = Clap(0.0, tuple(_camera(c) for c in at_end), first.audio_source, "auto")
        found = _pair_for_gap(heard, (second.session_ns - first.session_ns) / 1e9, pairing)
        if found is not None:
            return (*_with_pair(first, second, found[0]), found[1])
    late_s = pairing.late[0].time_s
    return [first], [f"the cameras saw no clap where the one heard at {late_s:.3f} s would put "
                     "a closing clap, so the drift is taken as 0; if it is the clap the "
                     f"cameras saw at the start (the one at {first.audio_s:.3f} s came before "
                     f"they ran), give --audio-clap {late_s:.3f}"], pairing.tied


def _with_pair(first: Clap, second: Clap, pair: tuple[ClapCandidate, ClapCandidate]
               ) -> tuple[list[Clap], list[str]]:
    """The two claps timed in audio by the heard ``pair``, with a note when its first is
    not the clap taken before."""
    opening, closing = pair
    notes = [] if opening.time_s == first.audio_s else [
        f"the clap heard at {opening.time_s:.3f} s, not the one at {first.audio_s:.3f} s, "
        "is the cameras' first: it lies as far from the closing clap as the cameras saw"]
    return [replace(first, audio_s=opening.time_s),
            replace(second, audio_s=closing.time_s)], notes


def _unseen_notes(source: FrameSource, seen: list[VideoClap], infos: list) -> list[str]:
    """Why a camera is not in the clap: it started after it, its frames around it are
    missing, or it saw nothing like it."""
    clap_ns = int(np.median([c.clap_ns for c in seen]))
    agree = int(AGREE_S * 1e9)
    start = min(info.first_ns for info in infos)
    seen_by = {c.stream for c in seen}
    late, blind = [], []
    for s in infos:
        if s.name in seen_by:
            continue
        if s.first_ns > clap_ns + agree:
            late.append(f"{s.name} (first frame {(s.first_ns - clap_ns) / 1e9:.1f} s after)")
        elif s.last_ns < clap_ns - agree:
            late.append(f"{s.name} (last frame {(clap_ns - s.last_ns) / 1e9:.1f} s before)")
        elif (gap := _gap_around(source.stamps(s.name), clap_ns, agree)) is not None:
            late.append(f"{s.name} (no frames from {(gap[0] - start) / 1e9:.2f} to "
                        f"{(gap[1] - start) / 1e9:.2f} s into the recording: dropped)")
        else:
            blind.append(s.name)
    notes = []
    if late:
        notes.append(f"the clap is not in {', '.join(late)}: the other cameras set the sync "
                     "alone")
    if blind:
        notes.append(f"no clap seen by {', '.join(blind)} where the other cameras saw it: "
                     "it was out of view, or that camera's clock is off (check it in the "
                     "review)")
    return notes


def _gap_around(stamps: np.ndarray, t_ns: int, reach_ns: int) -> tuple[int, int] | None:
    """The frames either side of ``t_ns`` when none lies within ``reach_ns`` of it."""
    i = int(np.searchsorted(stamps, t_ns))
    if 0 < i < len(stamps) and stamps[i] - t_ns > reach_ns and t_ns - stamps[i - 1] > reach_ns:
        return int(stamps[i - 1]), int(stamps[i])
    return None


def _closing_clap(source: FrameSource, first: Clap, a2: float, infos: list,
                  progress: Progress | None, extra_s: float = 0.0) -> Clap | None:
    """The second clap in video, looked for where the first clap's offset puts it (and
    ``extra_s`` further either side)."""
    expected = first.session_ns + round((a2 - first.audio_s) * 1e9)
    span = int((max(NEAR_S, 3.0) + extra_s) * 1e9)
    # never back to the first clap itself (a wide search in a short video reached it)
    t0 = {s.name: max(s.first_ns, expected - span,
                      first.session_ns + int(MIN_CLAP_GAP_S * 1e9)) for s in infos}
    t1 = {s.name: min(s.last_ns, expected + span) for s in infos}
    cams = [c for c in video_claps(source, t0, t1, progress, which="closing clap")
            if abs(c.clap_ns - expected) < span]
    if not cams:
        return None
    return Clap(a2, tuple(_camera(c) for c in cams), first.audio_source, "auto")


def _camera(c: VideoClap) -> CameraClap:
    return CameraClap(c.stream, c.clap_ns, c.period_ns, c.method, c.frame_index, c.score,
                      c.sigma_ns)


def sync_with_video_clap(audio: Audio, session_ns: int,
                         span_ns: tuple[int, int] | None = None) -> SyncResult:
    """Audio clap found automatically, its session time set by hand.

    With the recording's header-stamp ``span_ns``, the heard clap is the one that lays the
    audio's sound over it (:func:`clap_choice.choose_opening`); without, the clearest in
    the first half of the heard claps' span."""
    if span_ns is None:
        first, _last, notes = audio_claps(audio)
    else:
        heard, notes = heard_claps(audio)
        choice = choose_opening(heard, sound_times(audio), int(session_ns), span_ns)
        first = choice.clap
        if choice.share < LOW_COVER:
            name = audio.path.name if audio.path else "the audio"
            notes.append(f"with {name}'s clap at {first.time_s:.3f} s on the clap set by "
                         f"hand, {100 * (1 - choice.share):.0f}% of its sound falls outside "
                         "the recording: check both, or give the audio's clap too "
                         "(--audio-clap)")
        notes += _clipped_note(audio, [first])
    return build_result([Clap(first.time_s, (), "auto", "manual", int(session_ns))], notes)
