"""The "find trigger words" dialog: which words, and how sensitive the detector is."""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QSlider,
    QVBoxLayout,
    QWidget,
)

from app.dialog_fit import fit_height
from app.style import WARNING_TEXT_COLOUR
from speechcal_core.errors import UsageError
from speechcal_core.review.detect_again import EXAMPLE, DetectRequest

EXPLANATION = (
    "Words found that no set covers become new undecided sets; the sets in the list and "
    "your decisions on them stay as they are. A word the dictionary lacks takes its "
    f"pronunciation after it, up to the next comma: {EXAMPLE}, capture.")


class DetectDialog(QDialog):
    """Asks for trigger words and a sensitivity; ``request`` is set once it is accepted.

    ``make_request(text, sensitivity)`` checks the words (UsageError saying what to type):
    a word it refuses keeps the dialog open with the reason under the field.
    """

    def __init__(self, parent: QWidget | None, words_text: str, sensitivity: float,
                 make_request: Callable[[str, float], DetectRequest]) -> None:
        super().__init__(parent)
        self.make_request = make_request
        self.request: DetectRequest | None = None
        self.setWindowTitle("Find trigger words")
        self.setMinimumWidth(520)
        self.words_edit = QLineEdit(words_text)
        self.words_edit.selectAll()  # typing replaces the words; an arrow key keeps them
        self.words_edit.setPlaceholderText("capture, snapshot")
        self.words_edit.textEdited.connect(self._hide_problem)
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, 100)
        self.slider.setValue(round(sensitivity * 100))
        self.slider.setToolTip("Higher finds more words, and more that are not the trigger")
        self.value_label = QLabel("")
        # as wide as its widest text: the slider does not move under the mouse
        self.value_label.setMinimumWidth(
            self.value_label.fontMetrics().horizontalAdvance("0.00 (default)"))
        self.slider.valueChanged.connect(self._show_value)
        slider_row = QHBoxLayout()
        slider_row.addWidget(QLabel("fewer false alarms"))
        slider_row.addWidget(self.slider, 1)
        slider_row.addWidget(QLabel("find more"))
        slider_row.addWidget(self.value_label)
        self.problem = QLabel("")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet(f"color: {WARNING_TEXT_COLOUR.name()};")
        self.problem.hide()
        note = QLabel(EXPLANATION)
        note.setWordWrap(True)
        form = QFormLayout()
        form.addRow("Trigger words", self.words_edit)
        form.addRow("Sensitivity", slider_row)
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                        | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.button(QDialogButtonBox.StandardButton.Ok).setText("Find")
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.problem)
        layout.addWidget(note)
        layout.addWidget(self.buttons)
        self._show_value(self.slider.value())

    @property
    def sensitivity(self) -> float:
        """The slider's sensitivity, 0..1."""
        return self.slider.value() / 100.0

    def accept(self) -> None:
        """Close only with words the detector can look for; else say what is wrong."""
        try:
            self.request = self.make_request(self.words_edit.text(), self.sensitivity)
        except UsageError as exc:
            self.problem.setText(str(exc))
            self.problem.show()
            fit_height(self)
            return
        super().accept()

    def _hide_problem(self, _text: str) -> None:
        if self.problem.isVisible():
            self.problem.hide()
            self.setMinimumHeight(0)  # fit_height raised it for the reason's lines
            self.adjustSize()

    def _show_value(self, value: int) -> None:
        default = " (default)" if value == 50 else ""
        self.value_label.setText(f"{value / 100:.2f}{default}")
