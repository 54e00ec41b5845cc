"""The one error type of the speech layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError


class SpeechError(SpeechCalError):
    """Trigger detection cannot run; the message names the file or word and the fix."""
