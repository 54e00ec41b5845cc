"""Trigger-word detection: backends (pocketsphinx, Whisper, transcripts, examples) and matching."""

from __future__ import annotations

from speechcal_core.speech.backend import SpeechBackend, Word
from speechcal_core.speech.detect import Detection, detect_triggers, make_backend
from speechcal_core.speech.errors import SpeechError
from speechcal_core.speech.matching import TriggerSpec, match_triggers, normalize_word

__all__ = [
    "Detection",
    "SpeechBackend",
    "SpeechError",
    "TriggerSpec",
    "Word",
    "detect_triggers",
    "make_backend",
    "match_triggers",
    "normalize_word",
]
