"""The one error type of the export layer."""

from __future__ import annotations

from speechcal_core.errors import SpeechCalError


class ExportError(SpeechCalError):
    """An export that cannot be made; the message names the file and what to do."""
