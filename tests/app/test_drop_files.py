"""Files dropped on the review window: which of them it opens, and how."""

from __future__ import annotations

from pathlib import Path

import pytest
from PySide6.QtCore import QMimeData, QPointF, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDragMoveEvent, QDropEvent
from PySide6.QtWidgets import QApplication

from app.main_window import ReviewWindow


def drop(win: ReviewWindow, paths: list[Path]) -> None:
    """Drag ``paths`` (file URLs, as from a file manager) over the middle of the shown
    window and drop them, through its platform window as a real drop comes."""
    data = QMimeData()
    data.setUrls([QUrl.fromLocalFile(str(p)) for p in paths])
    pos = QPointF(win.rect().center())
    actions = Qt.DropAction.CopyAction | Qt.DropAction.MoveAction
    args = (data, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier)
    handle = win.windowHandle()
    enter = QDragEnterEvent(pos.toPoint(), actions, *args)
    QApplication.sendEvent(handle, enter)
    assert enter.isAccepted()
    move = QDragMoveEvent(pos.toPoint(), actions, *args)
    move.setDropAction(enter.dropAction())  # as the platform carries on the enter's answer
    move.accept()
    QApplication.sendEvent(handle, move)
    assert move.isAccepted()
    QApplication.sendEvent(handle, QDropEvent(pos, actions, *args))


@pytest.fixture
def opened(qtbot, monkeypatch: pytest.MonkeyPatch) -> tuple[ReviewWindow, list[dict]]:
    """An empty window whose ``open`` only records what it was asked to open."""
    win = ReviewWindow()
    win.setProperty("headless", True)
    qtbot.addWidget(win)
    win.show()
    calls: list[dict] = []
    monkeypatch.setattr(win, "open", lambda **kwargs: calls.append(kwargs))
    return win, calls


def test_what_speechcal_synth_writes_opens_the_recording_and_audio_not_truth_json(
        opened, tmp_path: Path) -> None:
    win, calls = opened
    audio, bag, truth = tmp_path / "audio.ogg", tmp_path / "recording.bag", tmp_path / "truth.json"
    drop(win, [audio, bag, truth])  # a file manager's (alphabetical) order
    assert calls == [{"recording": [str(bag)], "audio": str(audio)}]


@pytest.mark.parametrize("name", ["mic.aiff", "mic.m4a", "MIC.CAF"])
def test_a_recording_with_audio_of_another_kind_opens_them(opened, tmp_path: Path,
                                                           name: str) -> None:
    """AIFF (a Mac's recorder) reads; an M4A (a phone's) is opened to say how to convert it.
    Both were taken for a second recording, and the drop opened nothing."""
    win, calls = opened
    audio, bag = tmp_path / name, tmp_path / "recording.bag"
    drop(win, [audio, bag])
    assert calls == [{"recording": [str(bag)], "audio": str(audio)}]


def test_a_session_file_with_unrelated_files_opens_the_session(opened, tmp_path: Path) -> None:
    win, calls = opened
    session = tmp_path / "review.json"
    drop(win, [tmp_path / "notes.txt", session])
    assert calls == [{"session_path": str(session)}]


def test_a_session_file_named_in_upper_case_is_opened(opened, tmp_path: Path) -> None:
    win, calls = opened
    session = tmp_path / "SESSION.JSON"
    drop(win, [session])
    assert calls == [{"session_path": str(session)}]


@pytest.mark.parametrize("name", ["review.json.bak", "review.json.bak.2"])
def test_a_kept_previous_version_of_a_session_is_opened_as_one(opened, tmp_path: Path,
                                                               name: str) -> None:
    """The file a damaged session's error points to, as ``speechcal review`` opens it; it
    was taken for a recording without audio."""
    win, calls = opened
    drop(win, [tmp_path / name])
    assert calls == [{"session_path": str(tmp_path / name)}]


def test_a_recording_without_audio_is_not_opened(opened, tmp_path: Path) -> None:
    win, calls = opened
    drop(win, [tmp_path / "recording.bag"])
    assert calls == []
    assert "Drop a recording together with its audio file" in win.status_text.text()


def test_a_session_file_dropped_with_a_recording_and_audio_opens_that_session(
        opened, tmp_path: Path, truth_session_file: Path) -> None:
    # e.g. a session kept elsewhere with Save as, dropped with what it reviews
    win, calls = opened
    drop(win, [tmp_path / "audio.ogg", tmp_path / "recording.bag", truth_session_file])
    assert calls == [{"session_path": str(truth_session_file)}]
