"""Load a microphone recording (any format libsndfile reads) as float32 mono."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import soundfile as sf

from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.mp3_join import joined_mp3_note, open_mp3_chain
from speechcal_core.audio.ogg_chain import SoundFileChain, open_ogg_chain
from speechcal_core.audio.resampling import resample, resample_blocks
from speechcal_core.audio.wav_length import wav_declared_frames, wav_unfinished_bytes
from speechcal_core.fsutil import shell_quoted

#: endings of audio files libsndfile does not decode (a phone's or Windows' recorder):
#: taken for the audio, and refused naming how to convert them
UNREAD_SUFFIXES = (".m4a", ".aac", ".wma")
#: file endings taken for audio files where inputs are told apart by name (drops, review)
AUDIO_SUFFIXES = (".ogg", ".oga", ".opus", ".wav", ".flac", ".mp3", ".aif", ".aiff", ".caf",
                  ".w64", ".rf64", *UNREAD_SUFFIXES)

BLOCK_FRAMES = 1 << 16
SUPPORTED = "WAV, FLAC, Ogg Vorbis, Opus, MP3"
#: libsndfile reports a length this large (its SF_COUNT_MAX) when the header does not
#: know it: an Ogg file whose pages switch to another stream part way, as when two
#: programs wrote the same file at once
UNKNOWN_FRAMES = 1 << 62
#: a file decoding this much short of its header's length is cut short (codecs' blocks
#: and a Vorbis file's last granule lie well within it)
CUT_SHORT_S = 0.1
#: audio with more than this share of its samples not numbers (NaN, infinite) is damaged;
#: fewer (a glitch in a float file) are read as silence (inf as full scale)
DAMAGED_SHARE = 0.5
#: what :func:`sound_file` opens: libsndfile's file, or a chained Ogg file's links as one
SoundFileLike = sf.SoundFile | SoundFileChain


@dataclass(frozen=True, eq=False)
class Audio:
    """Mono float32 samples at ``rate`` Hz; time 0 is the file's first sample."""

    samples: np.ndarray
    rate: int
    path: Path | None = None
    channels_in_file: int = 1
    rate_in_file: int = 0
    channel: int | None = None  # the channel picked, None when mixed
    header_s: float | None = None  # the length the file's header gives, None if unknown
    #: seconds inside the file read as silence: a chained Ogg file's link that decodes to
    #: less than its pages say (the links after it keep their place in time)
    silent_s: float = 0.0

    @property
    def duration_s(self) -> float:
        """Length in seconds."""
        return self.samples.size / float(self.rate) if self.rate else 0.0

    def time_of(self, index: float | np.ndarray) -> float | np.ndarray:
        """Audio seconds of a sample index."""
        return np.asarray(index, dtype=np.float64) / self.rate

    def resampled(self, rate: int) -> Audio:
        """This audio at another rate."""
        if rate == self.rate:
            return self
        return Audio(resample(self.samples, self.rate, rate), int(rate), self.path,
                     self.channels_in_file, self.rate_in_file, self.channel, self.header_s,
                     self.silent_s)


def load_audio(path: str | Path, *, rate: int | None = None,
               channel: int | None = None) -> Audio:
    """Read an audio file as float32 mono, optionally resampled to ``rate`` Hz.

    ``channel`` picks one channel (0-based); by default all channels are averaged. The
    file is decoded in blocks so memory stays near the size of the mono result.
    Raises :class:`AudioError` for a missing, unreadable or empty file.
    """
    p = Path(path)
    if rate is not None and rate <= 0:
        raise AudioError(f"{p}: cannot resample to {rate} Hz; give a positive rate")
    with open_audio(p, channel) as f:
        channels, rate_in = int(f.channels), int(f.samplerate)
        header_s = _header_seconds(f, p)
        mono = _read_mono(f, p, channel)
        silent_s = _silent_s(f)
    if mono.size == 0:
        raise AudioError(_no_samples(p))
    numbers = NumberCheck(p)
    mono = numbers.clean(mono)
    numbers.check()
    audio = Audio(mono, rate_in, p, channels, rate_in, channel, header_s, silent_s)
    return audio.resampled(int(rate)) if rate is not None else audio


def load_resampled(path: str | Path, rate: int, *,
                   channel: int | None = None) -> tuple[Audio, int]:
    """``load_audio(path, rate=rate, channel=channel)``, decoded and resampled block by
    block so memory stays near the result (not the file's samples at its own rate), and
    how many samples the file decoded to at its own rate. The same samples."""
    p = Path(path)
    if rate <= 0:
        raise AudioError(f"{p}: cannot resample to {rate} Hz; give a positive rate")
    with open_audio(p, channel) as f:
        channels, rate_in = int(f.channels), int(f.samplerate)
        expected = header_frames(f) or 0
        header_s = _header_seconds(f, p)
        numbers = NumberCheck(p)
        samples, size_in = resample_blocks(map(numbers.clean, mono_blocks(f, p, channel)),
                                           rate_in, int(rate), size_hint=expected)
        silent_s = _silent_s(f)
    if size_in == 0:
        raise AudioError(_no_samples(p))
    numbers.check()
    return (Audio(samples, int(rate), p, channels, rate_in, channel, header_s, silent_s),
            size_in)


class NumberCheck:
    """Samples that are not numbers (NaN, infinite), as every full read of a file takes
    them: :meth:`clean` replaces them in each block (NaN by 0, inf by full scale) and
    counts them; :meth:`check` then refuses the file as damaged when more than
    :data:`DAMAGED_SHARE` of its samples were such: read as silence, such a file was
    "no speech" rather than a damaged file."""

    def __init__(self, path: str | Path) -> None:
        self.path = path
        self.bad = 0
        self.total = 0

    def clean(self, block: np.ndarray) -> np.ndarray:
        """``block`` with its non-numbers replaced (a new array when there are any)."""
        self.total += block.size
        finite = np.isfinite(block)
        if not finite.all():
            self.bad += block.size - int(np.count_nonzero(finite))
            block = np.nan_to_num(block, nan=0.0, posinf=1.0, neginf=-1.0)
        return block

    def check(self) -> None:
        """AudioError naming the file when too many of its samples were no numbers."""
        if self.total and self.bad > DAMAGED_SHARE * self.total:
            share = "all" if self.bad == self.total else f"{100 * self.bad / self.total:.0f}%"
            raise AudioError(
                f"{self.path}: the audio is damaged: {share} of its samples are not numbers "
                "(NaN or infinite), not sound; record, copy or export the take again")


def _no_samples(p: Path) -> str:
    """Why ``p`` decoded to no samples, and what to do."""
    unread = wav_unfinished_bytes(p)
    if unread:
        return (f"{p}: its header says it holds no audio, yet {unread} bytes of it follow "
                "(the recorder stopped before it wrote the length); repair the header, e.g. "
                f"sox --ignore-length {shell_quoted(p.name)} fixed.wav, and give that file")
    return f"{p}: holds no audio samples; record or copy the audio again"


def _silent_s(f: SoundFileLike) -> float:
    """Seconds of ``f`` read as silence (read to its end) where parts did not decode."""
    frames = int(getattr(f, "silent_frames", 0))
    return frames / f.samplerate if frames > 0 and f.samplerate > 0 else 0.0


def header_frames(f: SoundFileLike) -> int | None:
    """The file's length in frames as its header gives it; None where the header does not
    know it (decode the file to its end to learn it)."""
    frames = int(f.frames or 0)
    return frames if 0 <= frames < UNKNOWN_FRAMES else None


def _header_seconds(f: SoundFileLike, path: Path) -> float | None:
    """The length in seconds ``f``'s header gives (for a WAV file its data chunk's size,
    which libsndfile shortens to what is left of a file cut short)."""
    frames = header_frames(f)
    if isinstance(f, sf.SoundFile) and f.format in ("WAV", "WAVEX") and frames is not None:
        frames = max(frames, wav_declared_frames(path) or 0)
    return frames / f.samplerate if frames is not None and f.samplerate > 0 else None


def cut_short_note(audio: Audio) -> str:
    """A note when ``audio`` decoded to well short of the length its file's header gives
    (a copy that stopped early, a recorder that lost power, a damaged file), else "".

    libsndfile keeps what decodes; without this the rest of the take would be missing
    without a word. A chained Ogg file's link that stops decoding part way reads as
    silence to its end (:attr:`Audio.silent_s`), said the same way."""
    if audio.silent_s >= CUT_SHORT_S:
        return (f"{audio.path}: {audio.silent_s:.1f} s of its {audio.duration_s:.1f} s do "
                "not decode (one of the Ogg streams joined in it is damaged or cut short) "
                "and are silence, the rest kept in its place: copy the take again if you "
                "have it whole")
    if audio.header_s is None or audio.header_s - audio.duration_s < CUT_SHORT_S:
        return joined_mp3_note(audio.path, audio.duration_s)
    return (f"{audio.path}: only the first {audio.duration_s:.1f} s of the "
            f"{audio.header_s:.1f} s its header gives decode; the file is cut short or "
            "damaged (a copy that stopped early, a recorder that lost power), and the "
            "rest is left out: copy the take again if you have it whole")


def decoded_frames(f: SoundFileLike, path: str | Path) -> int:
    """How many frames of ``f`` decode, counted by decoding them all (from its start)."""
    return sum(block.size for block in mono_blocks(f, path))


def sound_file(path: str | Path) -> SoundFileLike:
    """``path`` opened for reading by soundfile, also where its name is not UTF-8 (a
    Latin-1 name from a FAT card: libsndfile takes names as text, so such a file is
    opened by descriptor). A chained Ogg file (streams one after another) or MP3 files
    joined byte by byte read through all their parts; libsndfile alone stops after the
    first."""
    chain = open_ogg_chain(path) or open_mp3_chain(path)
    if chain is not None:
        return chain
    name = str(path)
    try:
        name.encode()
    except UnicodeEncodeError:
        fd = os.open(name, os.O_RDONLY)
        try:
            return sf.SoundFile(fd, closefd=True)
        except BaseException:
            with contextlib.suppress(OSError):
                os.close(fd)
            raise
    return sf.SoundFile(name)


def open_audio(path: str | Path, channel: int | None = None) -> SoundFileLike:
    """The opened file, after the checks :func:`load_audio` makes (:class:`AudioError`)."""
    p = Path(path)
    if not p.exists():
        raise AudioError(f"{p}: audio file not found; check the path")
    if p.is_dir():
        raise AudioError(f"{p}: is a folder, not an audio file; give the audio file itself")
    if p.stat().st_size == 0:
        raise AudioError(f"{p}: the file is empty (0 bytes); record or copy the audio again")
    try:
        f = sound_file(p)
    except (sf.LibsndfileError, RuntimeError, TypeError) as exc:
        if p.suffix.lower() in UNREAD_SUFFIXES:
            raise AudioError(
                f"{p}: {p.suffix[1:].upper()} audio is not read; convert it to WAV or FLAC "
                f"first, e.g. ffmpeg -i {shell_quoted(p.name)} "
                f"{shell_quoted(p.stem + '.wav')}") from exc
        from speechcal_core.sources.sniff import looks_like

        seen = looks_like(p)
        if seen and "audio" not in seen:  # the recording or the session in its place
            raise AudioError(f"{p}: this is {seen.split(' (')[0]}, not an audio file; give "
                             f"the microphone's audio file ({SUPPORTED})") from exc
        raise AudioError(
            f"{p}: not a readable audio file ({_short(exc)}); convert it to {SUPPORTED}"
        ) from exc
    channels = int(f.channels)
    if channel is not None and not 0 <= channel < channels:
        f.close()
        raise AudioError(
            f"{p}: has {channels} channel(s), channel {channel} asked; "
            f"pick 0..{channels - 1} or leave the channel unset to mix"
        )
    return f


def mono_blocks(f: SoundFileLike, path: str | Path,
                channel: int | None = None) -> Iterator[np.ndarray]:
    """The file decoded in blocks of :data:`BLOCK_FRAMES` (only the last one shorter), each
    mixed (or picked) to mono float32 as :func:`load_audio` does; NaN and inf left as read.

    The yielded array is reused for the next block: copy what you keep. A file that
    stops decoding part way ends there (a truncated file keeps what decoded).
    """
    p = Path(path)
    buf = np.empty((BLOCK_FRAMES, f.channels), dtype=np.float32)
    mono = np.empty(BLOCK_FRAMES, dtype=np.float32)
    n = 0
    while True:
        try:
            got = f.read(BLOCK_FRAMES, dtype="float32", always_2d=True, out=buf)
        except (sf.LibsndfileError, RuntimeError) as exc:
            if n == 0:
                raise AudioError(
                    f"{p}: could not decode the audio ({_short(exc)}); "
                    f"convert it to {SUPPORTED}"
                ) from exc
            return  # a truncated file: keep what decoded
        k = got.shape[0]
        if k == 0:
            return
        if channel is not None:
            mono[:k] = got[:, channel]
        elif f.channels == 1:
            mono[:k] = got[:, 0]
        else:
            np.mean(got, axis=1, out=mono[:k])
        n += k
        yield mono[:k]
        if k < BLOCK_FRAMES:
            return


def _read_mono(f: SoundFileLike, p: Path, channel: int | None) -> np.ndarray:
    """Decode block by block into one preallocated mono array."""
    out = np.empty(max(header_frames(f) or 0, BLOCK_FRAMES), dtype=np.float32)
    n = 0
    for block in mono_blocks(f, p, channel):
        k = block.size
        if n + k > out.size:
            out = np.resize(out, max(out.size * 2, n + k))
        out[n:n + k] = block
        n += k
    return out[:n].copy() if n != out.size else out


def _short(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[-1] if text else type(exc).__name__
