"""Stretches of an audio file's samples, read back from the file when asked for.

:class:`FileSamples` stands in for the array :func:`~speechcal_core.audio.load_audio`
returns (mono, optionally resampled) where only short stretches are needed after a first
pass over the whole file: ``len``, ``size`` and slicing ``x[a:b]`` give the same values
without holding hours of samples in memory.
"""

from __future__ import annotations

from math import gcd
from pathlib import Path

import numpy as np
import soundfile as sf

from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.loader import sound_file
from speechcal_core.audio.resampling import resample_poly

#: decoded before a stretch and dropped: Ogg Vorbis decodes a few hundred samples after a
#: seek differently (the overlap of the previous block is missing); 4096 was enough on
#: every one of 300 random seeks into a synthetic session, this leaves room
PREROLL = 16384
#: frames read at a time from a file that stops decoding part way, to keep what decodes
SALVAGE_BLOCK = 4096


class FileSamples:
    """The samples of ``path`` at ``rate`` Hz (channels averaged, or ``channel``), as
    :func:`~speechcal_core.audio.load_audio` gives them, read on demand.

    ``rate_in`` and ``size_in`` are the file's rate and its decoded length (from the load
    that came first), so a truncated file ends where that load ended.
    """

    def __init__(self, path: str | Path, rate: int, *, rate_in: int, size_in: int,
                 channel: int | None = None) -> None:
        self.path = Path(path)
        self.rate = int(rate)
        self.rate_in = int(rate_in)
        self.size_in = int(size_in)
        self.channel = channel
        g = gcd(self.rate_in, self.rate)
        self._up, self._down = self.rate // g, self.rate_in // g
        self.size = -(-self.size_in * self._up // self._down)
        # as in ``resampling.resample``: the filter's half length, whole input periods
        margin = -(-10 * max(self._up, self._down) // self._up) + 2
        self._margin = -(-margin // self._down) * self._down

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, key: slice) -> np.ndarray:
        if not isinstance(key, slice) or key.step not in (None, 1):
            raise TypeError("FileSamples takes plain slices x[a:b]")
        a, b, _ = key.indices(self.size)
        return self.read(a, max(a, b))

    def read(self, a: int, b: int) -> np.ndarray:
        """Samples ``a`` .. ``b`` (at ``rate``) as float32."""
        if b <= a:
            return np.zeros(0, dtype=np.float32)
        if self._up == self._down:
            return self._decode(a, b)
        up, down = self._up, self._down
        # whole input periods, so the polyphase filter starts in the same phase as over
        # the whole file, plus the filter's reach either side
        lo = max(0, (a * down // up) // down * down - self._margin)
        hi = min(self.size_in, -(-b * down // up) + self._margin)
        y = resample_poly(self._decode(lo, hi), up, down).astype(np.float32, copy=False)
        skip = a - lo * up // down
        return y[skip:skip + (b - a)]

    def _decode(self, a: int, b: int) -> np.ndarray:
        """File samples ``a`` .. ``b`` at the file's rate, mono float32."""
        b = min(b, self.size_in)
        start = max(0, a - PREROLL)
        try:
            got = self._read(start, b - start)
        except (sf.LibsndfileError, RuntimeError, OSError) as exc:
            raise AudioError(f"{self.path}: could not read the audio again ({exc}); "
                             "was the file moved or changed?") from exc
        got = got[a - start:]
        if self.channel is not None:
            x = np.ascontiguousarray(got[:, self.channel])
        elif got.shape[1] == 1:
            x = np.ascontiguousarray(got[:, 0])
        else:
            x = np.empty(got.shape[0], dtype=np.float32)
            np.mean(got, axis=1, out=x)
        if not np.all(np.isfinite(x)):
            x = np.nan_to_num(x, nan=0.0, posinf=1.0, neginf=-1.0)
        return x

    def _read(self, start: int, n: int) -> np.ndarray:
        """File frames ``start`` .. ``start + n`` (all channels). Where the file stops
        decoding part way (cut short, damaged: its header promises more, as a playback
        past the end of what loaded asks for), what decodes and then silence."""
        with sound_file(self.path) as f:
            try:
                f.seek(start)
                return f.read(n, dtype="float32", always_2d=True)
            except (sf.LibsndfileError, RuntimeError):
                pass
        with sound_file(self.path) as f:
            out = np.zeros((n, f.channels), np.float32)
            done = 0
            try:
                f.seek(start)
                while done < n:
                    got = f.read(min(SALVAGE_BLOCK, n - done), dtype="float32",
                                 always_2d=True)
                    if got.shape[0] == 0:
                        break
                    out[done:done + got.shape[0]] = got
                    done += got.shape[0]
            except (sf.LibsndfileError, RuntimeError):
                pass  # the rest does not decode: silence
            return out
