"""The one error type of the speech layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError, UsageError


class SpeechError(SpeechCalError):
    """Trigger detection cannot run; the message names the file or word and the fix."""


class SpeechUsageError(SpeechError, UsageError):
    """An option value detection cannot use (no trigger word, a phrase as one trigger, an
    unknown phone or backend): the CLI exits with code 2, as for any bad usage."""
