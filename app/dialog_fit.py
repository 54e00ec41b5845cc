"""Dialogs whose wrapped text grows: tall enough for it at their width."""

from __future__ import annotations

from PySide6.QtWidgets import QWidget


def fit_height(dialog: QWidget, shrink: bool = False) -> None:
    """Make ``dialog`` tall enough for its layout's wrapped lines at its width: a longer
    text grows the dialog instead of squashing the fields above it; ``shrink`` (its
    content changed, e.g. a row hidden) also takes back room no longer needed, which
    otherwise showed as a blank band."""
    layout = dialog.layout()
    if layout is None:
        return
    needed = layout.totalHeightForWidth(dialog.width()) if layout.hasHeightForWidth() \
        else layout.totalSizeHint().height()
    dialog.setMinimumHeight(needed)
    if dialog.height() < needed or (shrink and dialog.height() > needed):
        dialog.resize(dialog.width(), needed)
