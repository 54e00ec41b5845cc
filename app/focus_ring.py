"""A frame around a widget while it has the keyboard focus, for the widgets that draw
none of their own (the camera grid, the waveform): a keyboard user saw no sign of which
one Tab had reached."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QEvent, QObject, QRectF, Qt
from PySide6.QtGui import QPainter, QPen
from PySide6.QtWidgets import QWidget

from app.style import FOCUS_COLOUR

if TYPE_CHECKING:
    from PySide6.QtGui import QPaintEvent

#: the frame's width, pixels (a widget that keeps its content off its edges by this
#: much, as the grid does, has the frame hide none of it)
FOCUS_RING_PX = 2


class FocusRing(QWidget):
    """Drawn over the edges of the widget it is made for (its parent) while that widget
    has the focus, in a window that is active; it takes no mouse event and no focus."""

    def __init__(self, target: QWidget) -> None:
        super().__init__(target)
        self.setAttribute(Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.hide()
        target.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        kind = event.type()
        if kind in (QEvent.Type.FocusIn, QEvent.Type.FocusOut):
            self.follow()
        elif kind == QEvent.Type.Resize and self.isVisible():
            self.setGeometry(self.parentWidget().rect())
        return False

    def follow(self) -> None:
        """Shown (over the widget's children) while the widget has the focus, else hidden."""
        target = self.parentWidget()
        if target.hasFocus():
            self.setGeometry(target.rect())
            self.raise_()  # over children made since (the waveform's buttons)
            self.show()
        else:
            self.hide()

    def paintEvent(self, event: QPaintEvent) -> None:
        p = QPainter(self)
        pen = QPen(FOCUS_COLOUR, FOCUS_RING_PX)
        pen.setJoinStyle(Qt.PenJoinStyle.MiterJoin)
        p.setPen(pen)
        half = FOCUS_RING_PX / 2
        p.drawRect(QRectF(self.rect()).adjusted(half, half, -half, -half))
        p.end()
