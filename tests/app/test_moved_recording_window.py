"""A session whose recording moved away from it, opened in the window: the first page says
why it cannot open, in full, and "Locate recording…" opens it from where the operator
shows the recording went, its review work kept."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from speechcal_core.session.store import load_session, save_session


@pytest.fixture
def moved(processed_tiny, tiny_synth, tmp_path: Path) -> tuple[Path, Path, str]:
    """(session file, the folder its recording and audio are in now, the bag's name)."""
    _folder, truth = tiny_synth
    shutil.copytree(processed_tiny("reviews/lab.json"), tmp_path, dirs_exist_ok=True)
    recording = tmp_path / "rec" / truth["recording"]
    session_path = tmp_path / "reviews" / "lab.json"
    reviewed = load_session(session_path)
    reviewed.replace_set(reviewed.sets[1].with_decision("rejected"))
    save_session(reviewed, session_path)
    shutil.move(str(tmp_path / "rec"), tmp_path / "archive")
    return session_path, tmp_path / "archive", recording.name


def test_locate_recording_opens_the_session_with_its_decisions(qtbot, new_window,
                                                               moved) -> None:
    session_path, now_in, bag = moved
    asked: list = []
    window = new_window()
    window.ask_recording_place = lambda m: asked.append(m.names) or str(now_in / bag)
    window.open(session_path=str(session_path))
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    assert asked == [bag]  # asked at once, naming what to look for
    assert window.model.session.sets[1].decision == "rejected"
    assert "its recording moved from" in window.status_text.toolTip() + \
        window.status_text.text()
    window.saver.flush()  # the autosave is written off the UI thread
    assert Path(load_session(session_path).recording[0]).resolve() == now_in / bag
    assert window.open_problem.isHidden() and window.locate_button.isHidden()


def test_declined_the_first_page_says_why_and_offers_it_again(qtbot, new_window, moved,
                                                              tmp_path: Path) -> None:
    session_path, now_in, bag = moved
    answers = [None, str(tmp_path), str(now_in)]  # no; a folder without it; its folder
    window = new_window()
    window.ask_recording_place = lambda _m: answers.pop(0)
    window.open(session_path=str(session_path))
    qtbot.waitUntil(lambda: window.task is None, timeout=30_000)
    assert window.model is None
    said = window.open_problem.text()  # whole: the status line cuts it short
    assert f"its recording {session_path.parent.parent / 'rec' / bag} is missing" in said
    assert "to keep the review decisions" in said
    assert window.locate_button.isVisible()

    window.locate_button.click()  # the wrong folder: said, nothing opened
    assert f"{tmp_path} holds no {bag}" in window.open_problem.text()
    window.locate_button.click()
    qtbot.waitUntil(lambda: window.model is not None, timeout=30_000)
    assert window.model.session.sets[1].decision == "rejected"


def test_locate_audio_reads_the_moved_audio_and_keeps_the_review(
        qtbot, open_window, tiny_synth, tmp_path: Path) -> None:
    from truth_sessions import truth_session

    folder, truth = tiny_synth
    copy = tmp_path / "session"
    shutil.copytree(folder, copy)
    save_session(truth_session(copy, truth), tmp_path / "review.json")
    session = load_session(tmp_path / "review.json")
    session.replace_set(session.sets[0].with_decision("accepted"))
    save_session(session, tmp_path / "review.json")
    audio = Path(session.audio)
    (tmp_path / "usb").mkdir()
    audio.rename(tmp_path / "usb" / audio.name)
    window = open_window(tmp_path / "review.json")
    assert window.inputs.pyramid is None and window.locate_audio_action.isEnabled()
    assert "File ▸ Locate audio…" in window.waveform.message.text()

    window.ask_audio_place = lambda _gone: str(tmp_path / "usb" / "other.ogg")
    window.locate_audio()  # another file: refused, said
    assert f"is not {audio.name}, the session's audio" in window.status_text.toolTip() + \
        window.status_text.text()
    window.ask_audio_place = lambda _gone: str(tmp_path / "usb" / audio.name)
    old = window.model
    window.locate_audio()
    qtbot.waitUntil(lambda: window.model is not old, timeout=30_000)
    assert window.inputs.pyramid is not None and not window.locate_audio_action.isEnabled()
    assert window.model.session.sets[0].decision == "accepted"
    window.saver.flush()
    assert Path(load_session(tmp_path / "review.json").audio) == tmp_path / "usb" / audio.name


def test_opened_over_another_session_it_still_asks_where_the_recording_went(
        qtbot, open_window, truth_session_file: Path, moved) -> None:
    session_path, now_in, bag = moved
    window = open_window(truth_session_file)  # the operator is reviewing another session
    first = window.model
    asked: list = []
    window.ask_recording_place = lambda m: asked.append(m.names) or str(now_in / bag)
    window.open(session_path=str(session_path))  # File ▸ Open: its recording has moved
    qtbot.waitUntil(lambda: window.model is not first, timeout=30_000)
    assert asked == [bag]  # asked, not sent to the command line
    assert window.model.session.sets[1].decision == "rejected"
    assert window.inputs.session_path == session_path
