"""Sync a recording with its microphone track: claps in audio and in every camera."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from speechcal_core.sources.depth import stream_depth
from speechcal_core.sources.errors import SourceError
from speechcal_core.sync.clap_audio import ClapCandidate, audio_levels, find_audio_claps
from speechcal_core.sync.clap_video import VideoClap, find_video_claps, gray_full, to_gray_small
from speechcal_core.sync.errors import SyncError
from speechcal_core.sync.estimate import CameraClap, Clap, SyncResult, build_result

if TYPE_CHECKING:
    from speechcal_core.audio.loader import Audio
    from speechcal_core.sources.base import FrameSource

SEARCH_S = 20.0  # the first clap is looked for in this much video from each stream's start
NEAR_S = 2.0  # other cameras (and the closing clap) are looked for this close to the expected time
AGREE_S = 0.3  # camera clocks closer than this count as seeing the same event
MIN_CLAP_GAP_S = 5.0  # a closing clap lies at least this long after the first
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

def audio_claps(audio: Audio) -> tuple[ClapCandidate, ClapCandidate | None, list[str]]:
    """The first clap, the closing clap (or None) and warnings about the audio itself.

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
                            f"of opposite polarity cancel: pick one with --channel (0-{n - 1})"
                            f", or check the microphone, or {BY_HAND}")
        raise SyncError(f"{name}: the audio is silent ({level}); "
                        f"check the microphone and the channel, or {BY_HAND}")
    if levels.clipped:
        notes.append(f"{name}: {levels.clipped_fraction * 100:.3f}% of samples clip at full "
                     "scale; clap timing still works, but lower the input gain next time")
    cands = find_audio_claps(audio, max_candidates=20)
    claps = [c for c in cands if c.is_clap]
    if not claps:
        best = (f"; the sharpest sound, at {cands[0].time_s:.3f} s, does not look like a "
                "clap") if cands else ""
        raise SyncError(f"{name}: no clap found in the audio{best}; clap once, sharply, "
                        f"where camera and microphone both catch it, or {BY_HAND}")
    half = audio.duration_s / 2
    early = [c for c in claps if c.time_s <= half] or claps
    first = max(early, key=lambda c: c.score)
    late = [c for c in claps if c.time_s >= first.time_s + max(MIN_CLAP_GAP_S, 0.4 * half)]
    last = max(late, key=lambda c: c.score) if late else None
    if any(c.clipped for c in (first, last) if c is not None):
        notes.append(f"{name}: the clap clips; its onset is still used")
    return first, last, notes


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
    for i in range(int(i0), int(i1)):
        try:
            img, scale = to_gray_small(source.frame(stream, i), depth=depth)
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
    detail = _detail_reader(source, stream, index, depth)
    return find_video_claps(small[:len(kept)], np.array(kept), stream=stream, scale=scale,
                            detail=detail)


def _detail_reader(source: FrameSource, stream: str, index: list[int],
                   depth: int | None) -> Callable[[int], np.ndarray]:
    """Frame ``index[j]`` at full resolution (:func:`gray_full`), the most recently read
    kept up to DETAIL_CACHE_BYTES."""
    cache: OrderedDict[int, np.ndarray] = OrderedDict()
    held = 0

    def detail(j: int) -> np.ndarray:
        nonlocal held
        img = cache.get(j)
        if img is not None:
            cache.move_to_end(j)
            return img
        img = gray_full(source.frame(stream, index[j]), depth)
        cache[j] = img
        held += img.nbytes
        while held > DETAIL_CACHE_BYTES and len(cache) > 1:
            held -= cache.popitem(last=False)[1].nbytes
        return img

    return detail


def video_claps(source: FrameSource, t0: dict[str, int], t1: dict[str, int],
                progress: Progress | None = None, which: str = "clap") -> list[VideoClap]:
    """Each stream's clap in its window [t0, t1], chosen so that the cameras agree.

    Every camera proposes its clap-like events; the moment most cameras share (within
    ``AGREE_S``; ties go to the clearer events) is the clap, and each camera contributes
    its event nearest to it. A camera that saw nothing there contributes its best event.
    ``which`` names the clap in the progress messages ("clap", "closing clap").
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
    agree = int(AGREE_S * 1e9)

    def support(c: VideoClap) -> tuple[int, int, float]:
        cams = {o.stream for o in every if abs(o.clap_ns - c.clap_ns) <= agree}
        return len(cams), int(c.method == "v-fit"), c.score

    anchor = max(every, key=support)
    out = []
    for found in proposals.values():
        near = [c for c in found if abs(c.clap_ns - anchor.clap_ns) <= agree]
        out.append(min(near, key=lambda c: abs(c.clap_ns - anchor.clap_ns)) if near else found[0])
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
    if audio_clap_s is None:
        first, last, notes = audio_claps(audio)
        a1, a2 = first.time_s, (last.time_s if last else None)
        audio_source = "auto"
    else:
        a1, a2, audio_source = float(audio_clap_s), None, "manual"
    t0 = {s.name: s.first_ns for s in infos}
    t1 = {s.name: min(s.last_ns, s.first_ns + int(search_s * 1e9)) for s in infos}
    cams1 = video_claps(source, t0, t1, progress)
    if not cams1:
        # two recordings given as one interleave their frames: that hides any clap
        mixed = [f"{s.name}: {s.stamp_problems}; give one recording's files, or "
                 for s in infos if s.stamp_problems]
        raise SyncError(f"no clap seen in the first {search_s:g} s of any camera "
                        f"({', '.join(t0)}); {mixed[0] if mixed else ''}make the clap "
                        "visible to the cameras, search longer (--search-s), or set it by "
                        "hand (--video-clap-ns)")
    missing = [n for n in t0 if n not in {c.stream for c in cams1}]
    if missing:
        notes.append(f"no clap seen by {', '.join(missing)}")
    claps = [Clap(a1, tuple(_camera(c) for c in cams1), audio_source, "auto")]
    if a2 is None and audio.duration_s - a1 >= ONE_CLAP_NOTE_S:
        shift_ms = (audio.duration_s - a1) * TYPICAL_DRIFT * 1e3
        notes.append(f"one clap: drift not measured (taken as 0); a typical "
                     f"{TYPICAL_DRIFT * 1e6:.0f} ppm would put the last words "
                     f"{shift_ms:.0f} ms off: clap again at the end of a long recording")
    if a2 is not None:
        second = _closing_clap(source, claps[0], a2, infos, progress)
        if second is not None:
            claps.append(second)
        else:
            notes.append(f"a second clap at {a2:.3f} s of audio was not seen by the cameras; "
                         "drift set to 0")
    result = build_result(claps, notes, extra={
        "audio": {"path": str(audio.path) if audio.path else None, "rate": audio.rate,
                  "duration_s": round(audio.duration_s, 6)},
        "video": [c.to_dict() for c in cams1],
    })
    if len(result.claps) == 2 and any("implausible" in w for w in result.warnings):
        keep = build_result(claps[:1], [*notes, "the second clap did not match; drift set "
                                        "to 0"], extra=result.extra)
        return keep
    return result


def _closing_clap(source: FrameSource, first: Clap, a2: float, infos: list,
                  progress: Progress | None) -> Clap | None:
    """The second clap in video, looked for where the first clap's offset puts it."""
    expected = first.session_ns + round((a2 - first.audio_s) * 1e9)
    span = int(max(NEAR_S, 3.0) * 1e9)
    t0 = {s.name: max(s.first_ns, expected - span) for s in infos}
    t1 = {s.name: min(s.last_ns, expected + span) for s in infos}
    cams = [c for c in video_claps(source, t0, t1, progress, which="closing clap")
            if abs(c.clap_ns - expected) < span]
    if not cams:
        return None
    return Clap(a2, tuple(_camera(c) for c in cams), first.audio_source, "auto")


def _camera(c: VideoClap) -> CameraClap:
    return CameraClap(c.stream, c.clap_ns, c.period_ns, c.method, c.frame_index)


def sync_with_video_clap(audio: Audio, session_ns: int) -> SyncResult:
    """Audio clap found automatically, its session time set by hand."""
    first, _last, notes = audio_claps(audio)
    return build_result([Clap(first.time_s, (), "auto", "manual", int(session_ns))], notes)
