"""The detection facade used by the CLI and the GUI: audio (or transcript) in, triggers out."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from speechcal_core.speech.backend import SpeechBackend, Word
from speechcal_core.speech.errors import SpeechError, SpeechUsageError
from speechcal_core.speech.matching import (
    DEFAULT_SENSITIVITY,
    DEFAULT_TRIGGERS,
    TriggerSpec,
    match_triggers,
)

if TYPE_CHECKING:
    from speechcal_core.audio import Audio

BACKENDS = ("pocketsphinx", "faster-whisper", "whisperx", "transcript", "example")
#: audio sampled more coarsely than this loses the sounds that tell words apart
MIN_SPEECH_RATE = 8000


@dataclass
class Detection:
    """Triggers found, plus notes for the operator (skipped words, no speech, ...)."""

    triggers: list[Word]
    backend: str
    duration_s: float | None = None
    notes: list[str] = field(default_factory=list)

    def to_json(self) -> list[dict]:
        """The ``speechcal detect --json`` document (DESIGN.md §2)."""
        return [w.to_json() for w in self.triggers]


def make_backend(name: str, *, model_dir: str | Path | None = None,
                 transcript: str | Path | None = None,
                 examples: Sequence[tuple[float, float]] = (),
                 example_word: str = "example") -> SpeechBackend:
    """The backend called ``name``; raises SpeechError naming the fix when it cannot run.

    ``examples`` are marked instances (audio seconds) for query by example, whose hits
    are named ``example_word``.
    """
    if transcript is not None:
        from speechcal_core.speech.transcripts import TranscriptBackend

        return TranscriptBackend(transcript)
    if name == "pocketsphinx":
        from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend

        return PocketsphinxBackend()
    if name == "faster-whisper":
        from speechcal_core.speech.whisper_backends import FasterWhisperBackend

        return FasterWhisperBackend(model_dir)
    if name == "whisperx":
        from speechcal_core.speech.whisper_backends import WhisperXBackend

        return WhisperXBackend(model_dir)
    if name == "example":
        from speechcal_core.speech.query_by_example import Example, QueryByExampleBackend

        if not examples:
            raise SpeechUsageError("--backend example needs a marked instance: --example START:END")
        return QueryByExampleBackend([Example(a, b, example_word) for a, b in examples])
    if name == "transcript":
        raise SpeechUsageError("--backend transcript needs the file: --transcript F")
    raise SpeechUsageError(f"unknown backend {name!r}; use one of {', '.join(BACKENDS)}")


def detect_triggers(audio_path: str | Path | Audio | None,
                    triggers: Sequence[str] = DEFAULT_TRIGGERS,
                    *, backend: str = "pocketsphinx", transcript: str | Path | None = None,
                    sensitivity: float = DEFAULT_SENSITIVITY,
                    pronunciations: Mapping[str, str] | None = None,
                    model_dir: str | Path | None = None,
                    examples: Sequence[tuple[float, float]] = (),
                    channel: int | None = None,
                    progress: Callable[[float], None] | None = None) -> Detection:
    """Find the trigger words of an audio file, or take them from a transcript.

    ``audio_path`` may also be an already loaded :class:`~speechcal_core.audio.Audio`;
    ``channel`` picks a file's channel (0-based; None mixes them). ``progress`` is
    called with the share of the work done (pocketsphinx only); it may raise to stop.
    """
    spec = TriggerSpec(tuple(triggers), sensitivity, dict(pronunciations or {}))
    chosen = make_backend(backend, model_dir=model_dir, transcript=transcript,
                          examples=examples, example_word=spec.words[0])
    notes: list[str] = []
    duration = None
    if transcript is not None:
        words = chosen.words(None, spec)  # type: ignore[arg-type]
        note = chosen.transcript.note()  # type: ignore[attr-defined]
        if note:
            notes.append(note)
    else:
        if audio_path is None:
            raise SpeechError("no audio given; pass the microphone recording")
        from speechcal_core.audio import Audio, load_audio
        from speechcal_core.audio.loader import cut_short_note

        if isinstance(audio_path, Audio):
            audio = audio_path if audio_path.rate == 16000 else audio_path.resampled(16000)
            audio_path = audio.path or "audio"
        else:
            audio = load_audio(audio_path, rate=16000, channel=channel)
        duration = audio.duration_s
        cut_short = cut_short_note(audio)
        if cut_short:
            notes.append(cut_short)
        if 0 < audio.rate_in_file < MIN_SPEECH_RATE:
            notes.append(f"{audio_path}: recorded at {audio.rate_in_file} Hz, too coarse for "
                         f"speech (it needs {MIN_SPEECH_RATE} Hz or more); record the "
                         "microphone at 16 kHz")
        if progress is not None and hasattr(chosen, "progress"):
            chosen.progress = progress
        words = chosen.words(audio, spec)
        retried = getattr(chosen, "last_note", None)
        if retried:
            notes.append(f"{audio_path}: {retried}")
    found = match_triggers(words, spec)
    if not found:
        what = f"{audio_path}" if transcript is None else f"{transcript}"
        if duration is not None and not _has_speech(audio, chosen):
            notes.append(f"{what}: no speech found in {duration:.1f} s of audio"
                         + _channel_hint(audio))
        else:
            notes.append(f"{what}: no trigger word ({', '.join(spec.words)}) found"
                         + (_channel_hint(audio) if duration is not None else ""))
    return Detection(found, chosen.name, duration, notes)


def _channel_hint(audio: object) -> str:
    """"; its 2 channels were mixed: ..." for audio of several channels heard mixed (the
    microphone on one, noise or another source on the other), else ""."""
    channels = getattr(audio, "channels_in_file", 1)
    if channels <= 1 or getattr(audio, "channel", None) is not None:
        return ""
    return (f"; its {channels} channels were mixed: if the microphone is on one of them, "
            f"pick it with --channel (0..{channels - 1})")


def _has_speech(audio: object, backend: SpeechBackend) -> bool:
    """Whether voice activity was found (reusing the backend's own analysis if it has one)."""
    activity = getattr(backend, "last_activity", None)
    if activity is not None:
        return bool(activity.segments)
    from speechcal_core.speech.vad import speech_segments

    return bool(speech_segments(audio.samples, audio.rate))  # type: ignore[attr-defined]
