"""Exports of reviewed frame sets for calibration tools (DESIGN.md §4).

One module per job: ``selection`` (which sets), ``plan`` (which frame goes to which file or
topic), ``images`` (lossless PNG), ``kalibr`` and ``folders`` (image layouts),
``bag_messages`` and ``bags`` (rosbag1/rosbag2), ``manifest`` (json + csv), and ``run``,
the facade the CLI and the review window both call.
"""

from __future__ import annotations

from speechcal_core.export.errors import ExportError
from speechcal_core.export.run import FORMATS, ExportResult, export_frame_sets, export_session_file
from speechcal_core.export.selection import select_sets

__all__ = [
    "FORMATS",
    "ExportError",
    "ExportResult",
    "export_frame_sets",
    "export_session_file",
    "select_sets",
]
