"""Which sets are exported: accepted by default, undecided on request, rejected never."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from speechcal_core.export import ExportError, export_session_file, select_sets
from speechcal_core.session.store import load_session


def test_only_accepted_sets_by_default(session_file) -> None:
    session = load_session(session_file())
    assert [s.decision for s in session.sets] == [
        "accepted", "undecided", "accepted", "rejected", "accepted"]
    assert [s.id for s in select_sets(session)] == [1, 3, 5]


def test_include_undecided_adds_undecided_never_rejected(session_file, tmp_path) -> None:
    path = session_file()
    assert [s.id for s in select_sets(load_session(path), include_undecided=True)] == [
        1, 2, 3, 5]
    result = export_session_file(path, "kalibr", tmp_path / "k", include_undecided=True)
    assert result.sets == 4
    assert len(list((tmp_path / "k" / "cam0").iterdir())) == 4


def test_no_accepted_sets_says_to_accept_sets_in_review_first(session_file, tmp_path) -> None:
    path = session_file(decisions=("undecided", "rejected"))
    with pytest.raises(ExportError) as exc:
        export_session_file(path, "folders", tmp_path / "out")
    message = str(exc.value)
    assert "\n" not in message and str(path) in message
    assert "no accepted frame sets" in message and "accept sets in the review" in message
    assert not (tmp_path / "out").exists()


def test_sets_without_any_chosen_frame_are_left_out(session_file) -> None:
    session = load_session(session_file())
    first = session.sets[0]
    session.replace_set(replace(first, frames=tuple(replace(f, index=-1) for f in first.frames)))
    assert [s.id for s in select_sets(session)] == [3, 5]


def test_a_session_from_another_recording_is_refused_before_writing(
    session_file, tmp_path: Path
) -> None:
    from speechcal_core.session.store import save_session

    path = session_file()
    session = load_session(path)
    s = session.sets[0]
    session.replace_set(replace_stamp(s))
    save_session(session, path)
    with pytest.raises(ExportError, match="differs from the one this session was made from"):
        export_session_file(path, "kalibr", tmp_path / "out")
    assert [p.name for p in tmp_path.iterdir()] == ["s0"]  # only the session's folder


def replace_stamp(frame_set):
    f = frame_set.frames[0]
    return replace(frame_set, frames=(replace(f, stamp_ns=f.stamp_ns + 1), *frame_set.frames[1:]))


@pytest.mark.parametrize("fmt", ["kalibr", "rosbag1"])
def test_two_accepted_sets_with_the_same_frames_are_written_once(
        session_file, tmp_path: Path, fmt: str) -> None:
    """A false trigger in the same still hold took the real set's frames: accepting both
    wrote the same images under two names (two views of one for the calibration), and a
    bag export counted six frames where it held three."""
    from speechcal_core.session.store import save_session

    path = session_file()
    session = load_session(path)
    first, third = session.sets[0], session.sets[2]
    session.replace_set(replace(third, frames=first.frames))
    save_session(session, path)
    result = export_session_file(path, fmt, tmp_path / fmt)
    assert result.sets == 2
    assert result.skipped == [
        "set 3: the same frames as set 1 (two trigger words in one still hold): written once"]
    manifest = json.loads((tmp_path / fmt / "manifest.json").read_text())
    assert [s["id"] for s in manifest["sets"]] == [1, 5]
