"""The one error type of the sync layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError


class SyncError(SpeechCalError):
    """The clocks could not be tied together; the message says what to check or set by hand."""
