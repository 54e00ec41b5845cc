"""One-line labels that cut their text with "…" when narrow (the tooltip has it whole)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import Qt
from PySide6.QtGui import QPainter
from PySide6.QtWidgets import QLabel, QSizePolicy, QWidget

if TYPE_CHECKING:
    from collections.abc import Sequence

    from PySide6.QtGui import QFontMetrics, QPaintEvent, QResizeEvent


def fitting_text(metrics: QFontMetrics, forms: Sequence[str], width: int) -> str:
    """The first of ``forms`` (longest first) that fits ``width`` pixels, else the last of
    them cut with "…"."""
    text = next((t for t in forms if metrics.horizontalAdvance(t) <= width), forms[-1])
    return metrics.elidedText(text, Qt.TextElideMode.ElideRight, width)


class ElidedLabel(QLabel):
    """Never wraps and never widens the window: too long a text ends in "…". A text of
    items joined by ``separator`` loses whole items from its end ("… · enlarge · …",
    not "… · whole ses…"), where one at least still fits. A text given with shorter
    forms shows the longest of them that fits before any is cut."""

    def __init__(self, text: str, tooltip: str = "", parent: QWidget | None = None,
                 separator: str = "") -> None:
        super().__init__(parent)
        self.separator = separator
        self.shorter: tuple[str, ...] = ()
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.set_full_text(text)
        if tooltip:
            self.setToolTip(tooltip)

    def set_full_text(self, text: str, shorter: Sequence[str] = ()) -> None:
        """Show ``text`` (cut to the label's width; the tooltip holds it whole), or where
        it is too long the first of ``shorter`` (longest first) that fits, else the last
        of them cut."""
        self.full_text = text
        self.shorter = tuple(shorter)
        self.setToolTip(text)
        self._elide()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        width = self.contentsRect().width()
        metrics = self.fontMetrics()
        if self.shorter and metrics.horizontalAdvance(self.full_text) > width:
            self.setText(fitting_text(metrics, (self.full_text, *self.shorter), width))
            return
        if self.separator and metrics.horizontalAdvance(self.full_text) > width:
            items = self.full_text.split(self.separator)
            for n in range(len(items) - 1, 0, -1):
                text = self.separator.join([*items[:n], "…"])
                if metrics.horizontalAdvance(text) <= width:
                    self.setText(text)
                    return
        self.setText(metrics.elidedText(self.full_text, Qt.TextElideMode.ElideRight, width))


class EllipsisLabel(QLabel):
    """A one-line label whose text, when too long for it, is drawn cut with "…" (so the
    reader sees there is more: the tooltip should hold it whole); ``text()`` stays whole.
    A text given with shorter forms is drawn as the longest of them that fits before any
    is cut. Never widens the window."""

    def __init__(self, text: str = "", parent: QWidget | None = None) -> None:
        super().__init__(text, parent)
        self.shorter: tuple[str, ...] = ()
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)

    def setText(self, text: str) -> None:
        """Show ``text``, with no shorter forms."""
        self.shorter = ()
        super().setText(text)

    def set_texts(self, text: str, shorter: Sequence[str] = ()) -> None:
        """Show ``text``, or where it is too long the first of ``shorter`` (longest
        first) that fits, else the last of them cut."""
        super().setText(text)
        self.shorter = tuple(shorter)
        self.update()

    def shown_text(self) -> str:
        """The text as drawn: the longest form that fits, else the shortest cut with "…"
        to the label's width."""
        return fitting_text(self.fontMetrics(), (self.text(), *self.shorter),
                            self.contentsRect().width())

    def paintEvent(self, event: QPaintEvent) -> None:
        painter = QPainter(self)
        self.style().drawItemText(painter, self.contentsRect(), int(self.alignment()),
                                  self.palette(), self.isEnabled(), self.shown_text(),
                                  self.foregroundRole())
