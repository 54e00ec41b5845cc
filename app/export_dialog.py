"""The export dialog: format, output folder, board, whether undecided sets go too."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

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
from speechcal_core.export.earlier import TARGET_FORMATS
from speechcal_core.target import TargetError, TargetSpec
from speechcal_core.text import counted

if TYPE_CHECKING:
    from PySide6.QtGui import QResizeEvent

#: export format -> what the operator reads in the list
FORMAT_LABELS = {
    "kalibr": "Kalibr — cam0/, cam1/… <stamp>.png + target.yaml + corners",
    "folders": "Folder per camera — calib.io, mrcal, OpenCV (+ corners)",
    "rosbag1": "ROS1 bag — original topics and messages + target.yaml",
    "rosbag2": "ROS2 bag — original topics and messages + target.yaml",
}
#: where the board the export describes comes from -> how the dialog says so
BOARD_ORIGINS = {
    "session": "the board the session was processed with",
    "default": "assumed, not measured: if your board differs, choose its target file",
}


class ExportDialog(QDialog):
    """Asks for format and folder; ``choice()`` after it was accepted."""

    def __init__(self, parent: QWidget | None, base_folder: Path, stem: str,
                 counts: dict[str, int],
                 waiting: Callable[[bool], int] | None = None,
                 refusal: Callable[[Path, TargetSpec | None], str] | None = None,
                 board: tuple[TargetSpec, str] = (TargetSpec(), "default")) -> None:
        super().__init__(parent)
        #: how many of the sets to export (undecided too or not) wait for re-scoring
        self.waiting = waiting or (lambda _include: 0)
        #: why a folder may not be exported into whatever the answer ("" if it may), for
        #: an export writing this board's target.yaml (None: a format that writes none)
        self.refusal = refusal or (lambda _out, _board: "")
        #: the board the export describes and where it comes from (BOARD_ORIGINS)
        self.board, self.board_origin = board
        #: the target file chosen here (None: the session's board), and why the last one
        #: chosen could not be read ("" if it could)
        self.target_file: Path | None = None
        self.target_problem = ""
        self.setWindowTitle("Export frame sets")
        self.setMinimumWidth(560)
        self.base_folder = base_folder
        #: where a folder typed as a relative path lies (the session's folder, where the
        #: folder offered lies: not the program's working folder, wherever it was started)
        self.relative_to = base_folder
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
        self.board_label = QLabel("")
        self.board_label.setWordWrap(True)
        self.target_button = QPushButton("Target file…")
        self.target_button.setToolTip("A Kalibr target yaml describing your board")
        self.target_button.clicked.connect(self._browse_target)
        self.board_row = QWidget()
        board_layout = QHBoxLayout(self.board_row)
        board_layout.setContentsMargins(0, 0, 0, 0)
        board_layout.addWidget(self.board_label, 1)
        board_layout.addWidget(self.target_button)
        self.summary = QLabel("")
        self.summary.setWordWrap(True)  # the notes run longer than the dialog is wide
        form = QFormLayout()
        form.addRow("Format", self.format_box)
        form.addRow("Folder", path_row)
        form.addRow("Board", self.board_row)
        self.form = form
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

    def choice(self) -> tuple[str, Path, bool, TargetSpec | None]:
        """Format, output folder, whether undecided sets are included, and the board a
        target file chosen here describes (None: the session's, as ``export`` takes it)."""
        target = self.board if self.target_file is not None else None
        return self.format, self._output(), self.undecided_box.isChecked(), target

    def set_target_file(self, path: Path) -> None:
        """Describe the board of the Kalibr target yaml ``path``; one that cannot be read
        leaves the board as it was and says why."""
        try:
            board = TargetSpec.from_kalibr_yaml(path)
        except (TargetError, OSError) as exc:
            named = str(exc) if str(path) in str(exc) else f"{path}: {exc}"
            self.target_problem = named
        else:
            self.board, self.target_file, self.target_problem = board, Path(path), ""
        self._update()

    def _browse_target(self) -> None:
        start = self.target_file or self._output()
        path, _filter = QFileDialog.getOpenFileName(
            self, "Kalibr target yaml of your board", str(start),
            "Kalibr target (*.yaml *.yml);;All files (*)")
        if path:
            self.set_target_file(Path(path))

    def _output(self) -> Path:
        """The output folder as typed (surrounding spaces are not part of it; a relative
        one in :attr:`relative_to`)."""
        typed = Path(self.path_edit.text().strip()).expanduser()
        return typed if typed.is_absolute() else self.relative_to / typed

    def _on_edited(self, _text: str) -> None:
        self._edited = True
        self._update()

    def _browse(self) -> None:
        parent = QFileDialog.getExistingDirectory(self, "Folder to export into",
                                                  str(self._output().parent))
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
        origin = f"from {self.target_file}" if self.target_file is not None \
            else BOARD_ORIGINS.get(self.board_origin, self.board_origin)
        self.board_label.setText(f"{self.board.describe()} ({origin})")
        board = self.board if self.format in TARGET_FORMATS else None
        why = self.refusal(out.absolute(), board) if text else ""
        why = why.removeprefix(f"{out.absolute()}: ")  # the field above shows the folder
        note = "\nIt exists: you will be asked before it is replaced" if out.exists() else ""
        later = self.waiting(self.undecided_box.isChecked())
        if later:
            note += (f"\n{later} of them still show{'s' if later == 1 else ''} the frames nearest "
                     "the trigger: the export starts once re-scoring has chosen their best "
                     "still frames")
        sets = "frame set" if n == 1 else "frame sets"
        folder = "the folder above" if out.exists() else "a new folder"
        if not Path(text).expanduser().is_absolute():  # typed short: say where it goes
            folder += f", {out}"
        self.summary.setText(f"{n} {sets} will be written to {folder}{note}")
        ok = self.buttons.button(QDialogButtonBox.StandardButton.Ok)
        ok.setEnabled(n > 0 and bool(text) and not why and not self.target_problem)
        if n == 0:
            self.summary.setText("No accepted frame sets yet: accept sets (A) first")
        elif why:  # said before any replace question: no answer makes it possible
            self.summary.setText(f"Cannot export there: {why}")
        if self.target_problem:
            self.summary.setText(f"Cannot use that target file: {self.target_problem}")
        # a shorter summary takes fewer lines: shrink
        fit_height(self, shrink=True)

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        fit_height(self)  # narrower: the summary wraps onto more lines
