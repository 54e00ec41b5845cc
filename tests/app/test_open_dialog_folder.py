"""File ▸ Open session… starts where the operator works: the open session's folder."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QFileDialog


def test_open_starts_in_the_open_sessions_folder(qtbot, window, truth_session_file: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    offered: list[str] = []
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        lambda _parent, _title, start, _filter: offered.append(start) or ("", ""))
    qtbot.keyClick(window, Qt.Key.Key_O, Qt.KeyboardModifier.ControlModifier)
    assert offered == [str(truth_session_file.resolve().parent)]  # not the program's cwd
    assert window.model is not None  # declined: the session stays open


def test_open_on_the_first_page_starts_in_the_working_folder(
        qtbot, new_window, monkeypatch: pytest.MonkeyPatch) -> None:
    offered: list[str] = []
    monkeypatch.setattr(QFileDialog, "getOpenFileName",
                        lambda _parent, _title, start, _filter: offered.append(start) or ("", ""))
    window = new_window()
    window.open_button.click()
    assert offered == [""]  # nothing open yet: Qt's default, the working folder
