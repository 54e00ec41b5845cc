"""Some of a recording's streams: the others are left out, as if it had not recorded them
(a camera recorded twice as raw and compressed, a depth or infrared topic)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from speechcal_core.sources.base import ClosingContext
from speechcal_core.sources.errors import SourceError

if TYPE_CHECKING:
    import numpy as np

    from speechcal_core.sources.base import FrameSource, RawFrame, StreamInfo


@dataclass(frozen=True)
class StreamChoice:
    """Which streams of a recording to use: ``only`` these (all when empty), less
    ``skip``. False when it chooses nothing (all streams)."""

    only: tuple[str, ...] = ()
    skip: tuple[str, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.only or self.skip)


def chosen_streams(names: Sequence[str], only: Sequence[str] = (),
                   skip: Sequence[str] = ()) -> list[str]:
    """The stream names of ``names`` kept by ``only`` (all when empty) less ``skip``, in
    their order; a topic given without its leading "/" or with a trailing one is found
    too. A name the recording lacks, or nothing left, is a SourceError."""
    unknown = [n for n in [*only, *skip] if stream_named(names, n) is None]
    if unknown:
        raise SourceError(
            f"no stream {', '.join(repr(n) for n in unknown)} in this recording (streams: "
            f"{', '.join(names) or 'none'}); `speechcal index RECORDING` lists them")
    wanted = {stream_named(names, n) for n in only}
    skipped = {stream_named(names, n) for n in skip}
    kept = [n for n in names if (not only or n in wanted) and n not in skipped]
    if not kept:
        raise SourceError(f"no stream left of {', '.join(names)}: keep at least one camera")
    return kept


def stream_named(names: Sequence[str], given: str) -> str | None:
    """The name of ``names`` that ``given`` stands for: itself, or the topic it names
    without its leading "/" or with a trailing one (``cam0/image_raw/``); None if none."""
    if given in names:
        return given
    topic = "/" + given.strip("/")
    return topic if topic in names else None


class SelectedStreams(ClosingContext):
    """The streams ``names`` of ``source``; reading another is a SourceError. Closing it
    closes ``source``."""

    def __init__(self, source: FrameSource, names: Sequence[str]) -> None:
        self._source = source
        self.names = list(names)
        left_out = [s.name for s in source.streams if s.name not in self.names]
        # what indexing noted of a stream left out (a twin of another) is no longer so
        self.notes: list[str] = [n for n in getattr(source, "notes", [])
                                 if not any(_names(n, name) for name in left_out)]

    @property
    def recorded(self) -> list[str]:
        """The names of all the recording's streams, those left out too."""
        return [s.name for s in self._source.streams]

    @property
    def streams(self) -> list[StreamInfo]:
        """The kept streams, in the source's order."""
        return [s for s in self._source.streams if s.name in self.names]

    def _check(self, stream: str) -> str:
        if stream not in self.names:
            raise SourceError(f"stream {stream!r} is left out of this recording (streams: "
                              f"{', '.join(self.names)})")
        return stream

    def stamps(self, stream: str) -> np.ndarray:
        """Sorted int64 header stamps."""
        return self._source.stamps(self._check(stream))

    def frame(self, stream: str, i: int) -> np.ndarray:
        """Decoded frame i."""
        return self._source.frame(self._check(stream), i)

    def nearest(self, stream: str, t_ns: int) -> int:
        """Index of the nearest stamp."""
        return self._source.nearest(self._check(stream), t_ns)

    def raw(self, stream: str, i: int) -> RawFrame:
        """Undecoded payload of frame i."""
        return self._source.raw(self._check(stream), i)

    def close(self) -> None:
        """Close the source."""
        self._source.close()


def select_streams(source: FrameSource, choice: StreamChoice | None) -> FrameSource:
    """``source`` with the streams ``choice`` keeps; ``source`` itself when it chooses
    nothing."""
    if not choice:
        return source
    return SelectedStreams(source, chosen_streams([s.name for s in source.streams],
                                                  choice.only, choice.skip))


def _names(text: str, stream: str) -> bool:
    """Whether ``text`` names ``stream`` (not just a stream under it, such as
    ``/cam0/image_raw/compressed`` for ``/cam0/image_raw``)."""
    return re.search(re.escape(stream) + r"(?![\w/])", text) is not None
