"""Microphone audio: loading, resampling, bag-embedded audio and waveform envelopes."""

from __future__ import annotations

from speechcal_core.audio.bag_audio import BagAudio, load_bag_audio
from speechcal_core.audio.envelope import EnvelopePyramid
from speechcal_core.audio.errors import AudioError
from speechcal_core.audio.loader import AUDIO_SUFFIXES, Audio, load_audio
from speechcal_core.audio.resampling import resample

__all__ = [
    "AUDIO_SUFFIXES",
    "Audio",
    "AudioError",
    "BagAudio",
    "EnvelopePyramid",
    "load_audio",
    "load_bag_audio",
    "resample",
]
