"""A camera that never finds the board other cameras find is named, with why, not left at 0."""

from __future__ import annotations

import json

import pytest

from speechcal_core.frames.unseen_cameras import unseen_camera_notes
from speechcal_core.review.checks import UNSEEN_HERE, check_summary
from speechcal_core.session.model import FrameChoice, FrameSet, Session, Trigger
from speechcal_core.target import TargetSpec

#: at 320x240 the fisheye camera of this session shows the tags 9-10 px across
SMALL_FISHEYE = dict(cameras=2, fisheye=1, duration=14.0, width=320, height=240, seed=1,
                     claps=1)
PINHOLE, FISHEYE = "/cam0/image_raw", "/cam1/image_raw"


@pytest.fixture(scope="module")
def small_fisheye_session(tmp_path_factory: pytest.TempPathFactory) -> Session:
    """The 320x240 session processed with its true triggers and offset."""
    from speechcal_core.pipeline import process_recording
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    out = tmp_path_factory.mktemp("small_fisheye") / "session"
    generate_session(out, SynthOptions(**SMALL_FISHEYE))
    truth = json.loads((out / "truth.json").read_text())
    words = out / "words.csv"
    words.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    return process_recording([str(out / truth["recording"])], str(out / truth["audio"]),
                             transcript=str(words), offset_ns=truth["sync"]["offset_ns"])


@pytest.mark.slow
def test_a_fisheye_too_small_to_read_is_named_in_the_notes_and_the_check(
        small_fisheye_session: Session) -> None:
    """The fisheye camera found the board in no set while the pinhole camera found it in
    all: the session said only "fewest corners 0" and "1 of 2 cameras fit". The notes and
    the check's line for that camera now name it and say why."""
    session = small_fisheye_session
    corners = {f.stream: [] for f in session.sets[0].frames}
    for s in session.sets:
        for f in s.frames:
            corners[f.stream].append(f.corners or 0)
    assert len(session.sets) >= 3
    assert all(corners[PINHOLE]) and not any(corners[FISHEYE])
    notes = [n for n in session.extra.get("detection_notes", []) if "found in none" in n]
    assert len(notes) == 1 and notes[0].startswith(f"{FISHEYE}: the 6x6 AprilGrid")
    assert "too small to read" in notes[0] and "higher resolution" in notes[0]
    summary = check_summary(session, [PINHOLE, FISHEYE])
    assert summary is not None and summary.warning
    pinhole_line, fisheye_line = summary.cameras
    assert UNSEEN_HERE in fisheye_line and UNSEEN_HERE not in pinhole_line


def _set(i: int, corners: dict[str, int]) -> FrameSet:
    frames = tuple(FrameChoice(name, 10 + i, 1_000_000 * i, 0.9, n)
                   for name, n in corners.items())
    return FrameSet(i, 1_000_000 * i, Trigger("capture", float(i), i + 0.4), frames)


def test_a_camera_that_found_the_board_once_gets_no_note() -> None:
    target = TargetSpec()
    sets = [_set(0, {PINHOLE: 144, FISHEYE: 0}), _set(1, {PINHOLE: 140, FISHEYE: 88})]
    assert unseen_camera_notes(sets, target) == []
    sets[1] = _set(1, {PINHOLE: 140, FISHEYE: 0})
    [note] = unseen_camera_notes(sets, target)
    assert note.startswith(f"{FISHEYE}: the 6x6 AprilGrid of 0.055 m tags was found in none "
                           "of its 2 frames, though other cameras found it in 2 of the same")


def test_no_camera_finding_the_board_is_left_to_the_wrong_target_note() -> None:
    sets = [_set(0, {PINHOLE: 0, FISHEYE: 0}), _set(1, {PINHOLE: 0, FISHEYE: 0})]
    assert unseen_camera_notes(sets, TargetSpec()) == []


def test_a_checkerboard_note_speaks_of_the_board_not_tags() -> None:
    board = TargetSpec(kind="checkerboard", rows=6, cols=8, size=0.045)
    [note] = unseen_camera_notes([_set(0, {PINHOLE: 48, FISHEYE: 0})], board)
    assert "tags" not in note and "board likely shows too small" in note
