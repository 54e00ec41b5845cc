"""A check box that Space ticks while it has the focus, although Space is the window's
play key (a QShortcut, which otherwise takes the key before the box sees it)."""

from __future__ import annotations

from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QCheckBox


class SpaceCheckBox(QCheckBox):
    """Space with the focus on the box ticks it (Tab reaches it, and a keyboard user had
    no other way to change it); everywhere else Space still plays."""

    def event(self, event: QEvent) -> bool:
        if event.type() == QEvent.Type.ShortcutOverride and isinstance(event, QKeyEvent) \
                and event.key() == Qt.Key.Key_Space \
                and event.modifiers() == Qt.KeyboardModifier.NoModifier:
            event.accept()  # the box's own key press, not the window's shortcut
            return True
        return super().event(event)
