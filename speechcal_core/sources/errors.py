"""The one error type of the recording-sources layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError


class SourceError(SpeechCalError):
    """A recording cannot be read; the message names the file and what to do."""


class BadFrameError(SourceError):
    """One frame cannot be decoded (corrupt or wrong-size payload); the stream still works."""
