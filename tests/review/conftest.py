"""Fixtures of the review tests."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from speechcal_core.session.store import load_session, save_session


@pytest.fixture
def moved_session(processed_tiny, tiny_synth, tmp_path: Path) -> tuple[Path, Path, str, str]:
    """A reviewed session (set 1 accepted) in a folder of its own, whose recording folder
    (bag and audio) moved: (session file, the folder they are in now, the bag's name,
    the audio's name)."""
    _folder, truth = tiny_synth
    shutil.copytree(processed_tiny("reviews/lab.json"), tmp_path, dirs_exist_ok=True)
    recording, audio = tmp_path / "rec" / truth["recording"], tmp_path / "rec" / truth["audio"]
    session_path = tmp_path / "reviews" / "lab.json"
    reviewed = load_session(session_path)
    reviewed.replace_set(reviewed.sets[0].with_decision("accepted"))
    save_session(reviewed, session_path)
    moved = tmp_path / "archive" / "rec"
    shutil.move(str(tmp_path / "rec"), moved)
    return session_path, moved, recording.name, audio.name
