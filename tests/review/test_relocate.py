"""A session whose recording moved away from it: what is missing, and the files to open it
with once the operator shows where they went (the window's "Locate recording…")."""

from __future__ import annotations

from pathlib import Path

import pytest

from speechcal_core.errors import UsageError
from speechcal_core.review.loading import load_for_review
from speechcal_core.review.relocate import moved_recording, relocated_inputs


def test_what_is_missing_is_named(moved_session, tiny_synth) -> None:
    session_path, _moved, bag, _audio = moved_session
    moved = moved_recording(session_path)
    assert moved is not None and moved.names == bag
    assert moved_recording(tiny_synth[0] / "no-such-session.json") is None


@pytest.mark.parametrize("show", ["bag", "folder", "audio"])
def test_one_file_or_the_folder_shown_gives_the_recording_and_audio(moved_session,
                                                                    show: str) -> None:
    session_path, moved, bag, audio = moved_session
    chosen = {"bag": moved / bag, "folder": moved, "audio": moved / audio}[show]
    recording, new_audio = relocated_inputs(session_path, chosen)
    assert recording == [str(moved / bag)] and new_audio == str(moved / audio)
    inputs = load_for_review(recording=recording, audio=new_audio,
                             new_session_path=session_path)
    inputs.close()
    assert "(1 decision kept)" in inputs.note and "its recording moved from" in inputs.note
    assert moved_recording(session_path) is None  # pointed there for good


def test_a_folder_without_the_recording_is_refused_naming_it(moved_session,
                                                             tmp_path: Path) -> None:
    session_path, _moved, bag, _audio = moved_session
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    with pytest.raises(UsageError) as refused:
        relocated_inputs(session_path, elsewhere)
    assert f"{elsewhere} holds no {bag}: choose the session's recording ({bag})" \
        in str(refused.value)


def test_a_ros2_bag_folder_is_found_from_its_metadata_file(tmp_path: Path) -> None:
    """The window's dialog picks files: a ROS2 bag folder is shown by its metadata.yaml."""
    from speechcal_core.session.model import Session
    from speechcal_core.session.store import save_session
    from speechcal_core.sync.model import SyncModel

    session_path = tmp_path / "reviews" / "lab.json"
    session_path.parent.mkdir()
    save_session(Session(recording=[str(tmp_path / "gone" / "take1")], audio=None,
                         sync=SyncModel(0)), session_path)
    bag = tmp_path / "disk" / "take1"
    bag.mkdir(parents=True)
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    assert relocated_inputs(session_path, bag / "metadata.yaml") == ([str(bag)], None)
    assert relocated_inputs(session_path, bag) == ([str(bag)], None)
