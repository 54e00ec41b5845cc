"""The one error type of the audio layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError


class AudioError(SpeechCalError):
    """Audio that cannot be used; the message names the file and what to do."""
