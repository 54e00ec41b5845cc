"""SpeechCal core: headless pipeline from recording + audio to verified calibration frame sets."""

from __future__ import annotations

__version__ = "0.1.0"
