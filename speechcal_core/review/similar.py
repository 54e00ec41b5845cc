"""Find more like this: search the session's audio for the word of one frame set.

:func:`similar_request` snapshots what to search for (the set's trigger, the spans the
session's triggers already cover); :meth:`SimilarRequest.run` does the work on any
thread over a :class:`SessionAudio`, which loads the audio file once per opened session;
the review model adds the result's words as new undecided sets
(:meth:`~speechcal_core.review.model.ReviewModel.apply_similar`).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from speechcal_core.errors import UsageError
from speechcal_core.session.model import FrameSet, Session
from speechcal_core.speech.backend import Word
from speechcal_core.speech.more_like import MIN_WORD_S, RATE, find_more_like, word_near
from speechcal_core.speech.speech_index import SpeechIndex
from speechcal_core.text import new_undecided

Progress = Callable[[str, float], None]

#: ``Trigger.source`` of a set found by "find more like this"
SIMILAR_SOURCE = "similar"


class SessionAudio:
    """The session's audio file, read and indexed for searches on first use (thread-safe).

    The index keeps the voice activity and features (a few tens of MB for two hours), not
    the samples: the few stretches a search needs around its hits are read back from the
    file (a 2-hour file's samples would hold 460 MB at 16 kHz for the whole session).
    """

    def __init__(self, path: str | Path | None, channel: int | None = None) -> None:
        self.path = Path(path) if path else None
        self.channel = channel  # the file's channel the session uses (None: mixed)
        self._index: SpeechIndex | None = None
        self._lock = threading.Lock()

    @property
    def loaded(self) -> bool:
        return self._index is not None

    def index(self, progress: Progress | None = None) -> SpeechIndex:
        """The indexed audio (read now if not yet: about 0.6 s per 200 s of audio)."""
        report = progress or (lambda _t, _f: None)
        with self._lock:
            if self._index is None:
                if self.path is None:
                    raise UsageError("this session has no audio file to search")
                from speechcal_core.audio.file_samples import FileSamples
                from speechcal_core.audio.loader import load_resampled

                report(f"reading {self.path.name} for the search…", 0.05)
                # decoded and resampled block by block: the file's own rate is never
                # held whole (3 times the 16 kHz samples at 48 kHz)
                audio, size_in = load_resampled(self.path, RATE, channel=self.channel)
                reader = FileSamples(self.path, RATE, rate_in=audio.rate_in_file,
                                     size_in=size_in, channel=self.channel)
                samples = audio.samples
                del audio
                report("finding speech in the audio…", 0.4)
                index = SpeechIndex.build(samples, RATE)
                del samples
                self._index = index.with_samples(reader)
            return self._index


@dataclass(frozen=True)
class SimilarResult:
    """Words like the set's (``bounds`` None: no speech near its trigger time)."""

    request: SimilarRequest
    bounds: tuple[float, float] | None
    words: tuple[Word, ...]
    seconds: float = 0.0


@dataclass(frozen=True)
class SimilarRequest:
    """Search for more words like set ``set_id``'s; a snapshot, review goes on meanwhile."""

    set_id: int  # also what the list's first column shows
    word: str
    start_s: float
    end_s: float
    covered: tuple[tuple[float, float], ...]  # audio spans of the session's triggers

    @property
    def text(self) -> str:
        """What the status line says while this runs."""
        return f"finding more like set {self.set_id}…"

    @property
    def has_word_bounds(self) -> bool:
        """Whether the trigger has real word bounds (an added set has only its time)."""
        return self.end_s - self.start_s >= MIN_WORD_S

    def run(self, audio: SessionAudio, progress: Progress | None = None) -> SimilarResult:
        """Find the word (unless the trigger has bounds), then spans like it.

        ``progress(text, fraction)`` may raise to cancel; it is called from this thread.
        """
        report = progress or (lambda _t, _f: None)
        t0 = time.perf_counter()
        report(self.text, 0.0)
        index = audio.index(lambda _t, f: report(self.text, 0.8 * f))
        report(self.text, 0.8)
        if self.has_word_bounds:
            bounds: tuple[float, float] | None = (self.start_s, self.end_s)
        else:
            bounds = word_near(index.activity, (self.start_s + self.end_s) / 2)
        if bounds is None:
            return SimilarResult(self, None, (), time.perf_counter() - t0)
        blocked = [c for c in self.covered if c[1] <= bounds[0] or c[0] >= bounds[1]]
        words = find_more_like(index, bounds[0], bounds[1], self.word, blocked,
                               SIMILAR_SOURCE)
        report(self.text, 1.0)
        return SimilarResult(self, bounds, tuple(words), time.perf_counter() - t0)


def similar_request(session: Session, frame_set: FrameSet) -> SimilarRequest:
    """What to search for to find more like ``frame_set``."""
    covered = tuple((s.trigger.start_s, s.trigger.end_s) for s in session.sets
                    if s.id != frame_set.id)
    t = frame_set.trigger
    return SimilarRequest(frame_set.id, t.word, t.start_s, t.end_s, covered)


def result_message(result: SimilarResult, added: int) -> str:
    """The status line's report of a finished search (``added`` sets were added)."""
    request = result.request
    where = f"set {request.set_id}"
    if result.bounds is None:
        t = (request.start_s + request.end_s) / 2
        return (f"no speech near {where} (audio {t:.2f} s): move the playhead onto the "
                "spoken word, add a set there (T) and search from it")
    # no word times here: the audio's clock is not the list's (the audio starts earlier)
    if not added:
        return f"found nothing more like {where} that no set covers"
    sets, them = new_undecided(added, with_count=False)  # "found 3 more like ..." gave it
    return f"found {added} more like {where}: {sets}, accept or reject {them} as usual"
