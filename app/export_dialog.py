"""The export dialog: format, output folder, whether undecided sets go too."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from app.dialog_fit import fit_height
from speechcal_core.text import counted

#: export format -> what the operator reads in the list
FORMAT_LABELS = {
    "kalibr": "Kalibr — cam0/, cam1/… <stamp>.png + target.yaml + corners",
    "folders": "Folder per camera — calib.io, mrcal, OpenCV (+ corners)",
    "rosbag1": "ROS1 bag — original topics and messages",
    "rosbag2": "ROS2 bag — original topics and messages",
}


class ExportDialog(QDialog):
    """Asks for format and folder; ``choice()`` after it was accepted."""

    def __init__(self, parent: QWidget | None, base_folder: Path, stem: str,
                 counts: dict[str, int],
                 waiting: Callable[[bool], int] | None = None,
                 refusal: Callable[[Path], str] | None = None) -> None:
        super().__init__(parent)
        #: how many of the sets to export (undecided too or not) wait for re-scoring
        self.waiting = waiting or (lambda _include: 0)
        #: why a folder may not be exported into whatever the answer ("" if it may)
        self.refusal = refusal or (lambda _out: "")
        self.setWindowTitle("Export frame sets")
        self.setMinimumWidth(560)
        self.base_folder = base_folder
        self.stem = stem
        self.counts = counts
        self._edited = False
        self.format_box = QComboBox()
        for key, label in FORMAT_LABELS.items():
            self.format_box.addItem(label, key)
        self.path_edit = QLineEdit()
        self.path_edit.textEdited.connect(self._on_edited)
        browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse)
        path_row = QHBoxLayout()
        path_row.addWidget(self.path_edit, 1)
        path_row.addWidget(browse)
        undecided = counts.get("undecided", 0)
        self.undecided_box = QCheckBox(f"also the {counted(undecided, 'undecided set')}")
        self.undecided_box.setVisible(undecided > 0)  # "also the 0 undecided sets"
        self.summary = QLabel("")
        self.summary.setWordWrap(True)  # the notes run longer than the dialog is wide
        form = QFormLayout()
        form.addRow("Format", self.format_box)
        form.addRow("Folder", path_row)
        form.addRow("", self.undecided_box)
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok
                                        | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.button(QDialogButtonBox.StandardButton.Ok).setText("Export")
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.summary)
        layout.addWidget(self.buttons)
        self.format_box.currentIndexChanged.connect(self._update)
        self.undecided_box.toggled.connect(self._update)
        self._update()

    @property
    def format(self) -> str:
        """The chosen export format's key (kalibr, folders, rosbag1, rosbag2)."""
        return str(self.format_box.currentData())

    def set_format(self, fmt: str) -> None:
        """Choose the export format by its key."""
        self.format_box.setCurrentIndex(self.format_box.findData(fmt))

    def set_folder(self, folder: Path) -> None:
        """Export into ``folder`` (kept when the format changes, as if typed)."""
        self.path_edit.setText(str(folder))
        self._on_edited(str(folder))

    def choice(self) -> tuple[str, Path, bool]:
        """Format, output folder and whether undecided sets are included."""
        return self.format, self._output(), self.undecided_box.isChecked()

    def _output(self) -> Path:
        """The output folder as typed (surrounding spaces are not part of it)."""
        return Path(self.path_edit.text().strip()).expanduser()

    def _on_edited(self, _text: str) -> None:
        self._edited = True
        self._update()

    def _browse(self) -> None:
        parent = QFileDialog.getExistingDirectory(self, "Folder to export into",
                                                  str(Path(self.path_edit.text()).parent))
        if parent:
            self.base_folder = Path(parent)
            self._edited = False
            self._update()

    def _update(self) -> None:
        if not self._edited:
            self.path_edit.setText(str(self.base_folder / f"{self.stem}-{self.format}"))
        n = self.counts.get("accepted", 0)
        if self.undecided_box.isChecked():
            n += self.counts.get("undecided", 0)
        text = self.path_edit.text().strip()
        out = self._output()
        why = self.refusal(out.absolute()) if text else ""
        why = why.removeprefix(f"{out.absolute()}: ")  # the field above shows the folder
        note = "\nIt exists: you will be asked before it is replaced" if out.exists() else ""
        later = self.waiting(self.undecided_box.isChecked())
        if later:
            note += (f"\n{later} of them still show{'s' if later == 1 else ''} the frames nearest "
                     "the trigger: the export starts once re-scoring has chosen their best "
                     "still frames")
        sets = "frame set" if n == 1 else "frame sets"
        folder = "the folder above" if out.exists() else "a new folder"
        self.summary.setText(f"{n} {sets} will be written to {folder}{note}")
        ok = self.buttons.button(QDialogButtonBox.StandardButton.Ok)
        ok.setEnabled(n > 0 and bool(text) and not why)
        if n == 0:
            self.summary.setText("No accepted frame sets yet: accept sets (A) first")
        elif why:  # said before any replace question: no answer makes it possible
            self.summary.setText(f"Cannot export there: {why}")
        fit_height(self)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        fit_height(self)  # narrower: the summary wraps onto more lines
