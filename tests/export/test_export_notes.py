"""What an export tells the user before they calibrate: an assumed board in target.yaml,
a board other than the one the frames were checked against, frames too far apart for
Kalibr's default pairing of bag images."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from speechcal_core.export import ExportResult, export_session_file
from speechcal_core.export.notes import approx_sync_note
from speechcal_core.session.model import FrameChoice, FrameSet, Trigger
from speechcal_core.session.store import load_session, save_session
from speechcal_core.target import TargetSpec

APRILGRID = TargetSpec()  # what process assumes without --target


def _with_target(path: Path, target: TargetSpec, assumed: bool | None) -> Path:
    """The session at ``path`` holding ``target``, ``assumed`` or given (None: a session
    from before sessions said which)."""
    session = load_session(path)
    session.extra["target"] = asdict(target)
    if assumed is not None:
        session.extra["target_assumed"] = assumed
    save_session(session, path)
    return path


def _board_notes(result: ExportResult) -> list[str]:
    """The notes on target.yaml (the sessions here, made from the synthetic truth, hold
    no found corners: a note on the missing corners files is left out)."""
    return [note for note in result.notes if note.startswith("target.yaml")]


def test_an_assumed_board_is_named_as_an_assumption(session_file, tmp_path: Path) -> None:
    path = _with_target(session_file(), APRILGRID, assumed=True)
    result = export_session_file(path, "kalibr", tmp_path / "kalibr")
    assert result.target == "default"
    assert len(_board_notes(result)) == 1
    note = _board_notes(result)[0]
    assert note.startswith("target.yaml describes the 6x6 AprilGrid of 0.055 m tags process "
                           "assumes without --target (the session was processed without "
                           "--target)")
    # the window has no --target: the note names the command that takes one
    assert "export again with its Kalibr target yaml (speechcal export --target" in note
    assert note in result.to_dict()["notes"]


def test_an_earlier_sessions_default_board_may_be_assumed(session_file, tmp_path) -> None:
    """Sessions made before they said whether the board was given: the default board is
    noted as possibly assumed, another board is taken as given."""
    path = _with_target(session_file(), APRILGRID, assumed=None)
    result = export_session_file(path, "kalibr", tmp_path / "a")
    assert result.target == "default"
    assert "(this session, from an earlier SpeechCal, does not say whether it was given)" \
        in _board_notes(result)[0]
    path = _with_target(path, TargetSpec("aprilgrid", 6, 6, 0.088, 0.3), assumed=None)
    result = export_session_file(path, "kalibr", tmp_path / "b")
    assert result.target == "session" and _board_notes(result) == []


def test_the_board_process_was_given_needs_no_note(session_file, tmp_path: Path) -> None:
    board = TargetSpec("aprilgrid", 6, 6, 0.088, 0.3)
    path = _with_target(session_file(), board, assumed=False)
    result = export_session_file(path, "kalibr", tmp_path / "kalibr")
    assert result.target == "session" and _board_notes(result) == []
    assert TargetSpec.from_kalibr_yaml(tmp_path / "kalibr" / "target.yaml") == board


def test_a_given_size_for_the_checked_layout_needs_no_note(session_file, tmp_path) -> None:
    """Measuring the printed tags after processing with the assumed board is the usual
    correction: same layout, another size."""
    path = _with_target(session_file(), APRILGRID, assumed=True)
    result = export_session_file(path, "kalibr", tmp_path / "kalibr",
                                 target=TargetSpec("aprilgrid", 6, 6, 0.088, 0.3))
    assert result.target == "given" and _board_notes(result) == []


def test_a_given_board_other_than_the_checked_one_is_noted(session_file, tmp_path) -> None:
    path = _with_target(session_file(), APRILGRID, assumed=False)
    result = export_session_file(path, "kalibr", tmp_path / "kalibr",
                                 target=TargetSpec("checkerboard", 6, 8, 0.045))
    assert _board_notes(result) == [
        "target.yaml describes the given 8x6 checkerboard of 0.045 m squares, but the session's "
        "frames were checked against the 6x6 AprilGrid of 0.055 m tags: the manifest's "
        "corner counts are for that board; process the recording again with this --target "
        "to check the frames against it"]


def test_the_cli_prints_the_notes(session_file, tmp_path: Path, capsys) -> None:
    from speechcal_core.cli import main

    path = _with_target(session_file(), APRILGRID, assumed=True)
    assert main(["export", str(path), "--format", "kalibr", "--out",
                 str(tmp_path / "kalibr")]) == 0
    err = capsys.readouterr().err
    assert "note: target.yaml describes the 6x6 AprilGrid of 0.055 m tags process assumes" \
        in err


def _frame_set(set_id: int, *stamps_ns: int) -> FrameSet:
    return FrameSet(set_id, stamps_ns[0], Trigger("capture", 1.0, 1.4),
                    tuple(FrameChoice(f"/cam{k}/image_raw", 10, s)
                          for k, s in enumerate(stamps_ns)))


def test_frames_further_apart_than_kalibrs_default_pairing_are_noted() -> None:
    sets = [_frame_set(1, 1_000_000_000, 1_012_000_000),
            _frame_set(2, 2_000_000_000, 2_023_500_000, 2_005_000_000)]
    note = approx_sync_note(sets)
    assert note.startswith("the frames of one set lie up to 23.5 ms apart")
    assert "--approx-sync 0.03 " in note
    assert "export --format kalibr" in note


def test_the_suggested_tolerance_is_rounded_up_in_whole_nanoseconds() -> None:
    """0.07 s suggested 0.08 and 0.14 s 0.15 when rounded as floats; 20.049 ms read
    "20.0 ms" beside "would drop sets"."""
    assert "--approx-sync 0.07 " in approx_sync_note([_frame_set(1, 0, 70_000_000)])
    assert "--approx-sync 0.14 " in approx_sync_note([_frame_set(1, 0, 140_000_000)])
    note = approx_sync_note([_frame_set(1, 0, 20_049_000)])
    assert note.startswith("the frames of one set lie up to 20.1 ms apart")
    assert "--approx-sync 0.03 " in note


def test_frames_within_kalibrs_default_pairing_need_no_note() -> None:
    assert approx_sync_note([_frame_set(1, 1_000_000_000, 1_020_000_000)]) == ""
    # a camera without a frame in the set does not count
    lone = FrameSet(2, 5, Trigger("capture", 1.0, 1.4),
                    (FrameChoice("/cam0/image_raw", 3, 5), FrameChoice("/cam1/image_raw", -1, 0)))
    assert approx_sync_note([lone]) == ""
