"""A session saved while its review was re-scoring exports best still frames, never the nearest."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from truth_sessions import truth_triggers

from speechcal_core.cli import main
from speechcal_core.export import ExportError, export_frame_sets
from speechcal_core.frames.analysis import analyse_frames, checks_basis
from speechcal_core.review.model import ReviewModel
from speechcal_core.session.store import load_session, save_session
from speechcal_core.sources import open_recording
from speechcal_core.target import TargetSpec

SHIFT_NS = -1_000_000_000


@pytest.fixture
def waiting_session(searched_session_file: Path) -> Path:
    """The searched session with two sets accepted, then the offset edited: saved with
    every set still showing its nearest frames (the review closed before re-scoring)."""
    session = load_session(searched_session_file)
    with open_recording(session.recording) as source:
        model = ReviewModel(session, source,
                            autosave=lambda s: save_session(s, searched_session_file))
        for index in (0, 2):
            model.go_to_set(index)
            model.accept()
        model.nudge_offset(SHIFT_NS)
        assert model.export_waits_for()
    return searched_session_file


def test_cli_export_rescores_waiting_sets_first_and_saves_them(
    waiting_session: Path, tiny_synth: tuple[Path, dict], tmp_path: Path, capsys,
) -> None:
    out = tmp_path / "kalibr"
    code = main(["export", str(waiting_session), "--format", "kalibr", "--out", str(out),
                 "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    session = load_session(waiting_session)
    doc = json.loads(captured.out)
    assert doc["sets"] == 2 and doc["rescored"] == len(session.sets)
    assert f"saved to {waiting_session}" in captured.err

    _folder, truth = tiny_synth
    with open_recording(session.recording) as source:
        pipeline = analyse_frames(source, session.sync, truth_triggers(truth), TargetSpec())
    best = {s.id: s for s in pipeline.sets}
    manifest = json.loads((out / "manifest.json").read_text())
    for entry in manifest["sets"]:
        want = {f.stream: f.stamp_ns for f in best[entry["id"]].frames}
        assert {f["stream"]: f["stamp_ns"] for f in entry["frames"]} == want
        assert all(f["sharpness"] is not None or "no-target" in f["flags"]
                   for f in entry["frames"])
    # the session file says which frames went out, with checks over them
    assert [s.frames for s in session.sets] == [s.frames for s in pipeline.sets]
    assert [s.decision for s in session.sets][:3] == ["accepted", "undecided", "accepted"]
    assert session.extra["checks_basis"] == checks_basis(session.sets)
    assert session.extra["coverage"].keys() == pipeline.extra["coverage"].keys()

    again = tmp_path / "again"
    assert main(["export", str(waiting_session), "--format", "folders", "--out", str(again),
                 "--json"]) == 0
    assert "rescored" not in json.loads(capsys.readouterr().out)


def test_a_session_file_a_window_saved_during_the_export_is_not_overwritten(
    waiting_session: Path, tmp_path: Path,
) -> None:
    from speechcal_core.export import export_session_file

    def window_saves(text: str, _fraction: float) -> None:
        if text.startswith("checking the calibration"):  # re-scored, not yet saved
            decided = load_session(waiting_session)
            decided.replace_set(decided.sets[1].with_decision("rejected"))
            save_session(decided, waiting_session)  # as the review window's autosave
            seen.append(text)

    seen: list[str] = []
    result = export_session_file(waiting_session, "kalibr", tmp_path / "kalibr",
                                 progress=window_saves)
    assert seen and result.sets == 2  # the export is made all the same
    kept = load_session(waiting_session)
    assert kept.sets[1].decision == "rejected"  # the window's decision stays


def test_exporting_an_open_session_with_waiting_sets_is_refused(
    waiting_session: Path, tmp_path: Path,
) -> None:
    session = load_session(waiting_session)
    out = tmp_path / "out"
    with open_recording(session.recording) as source, \
            pytest.raises(ExportError, match="re-scor") as err:
        export_frame_sets(session, source, "kalibr", out, session_path=waiting_session)
    assert str(waiting_session) in str(err.value) and "2 frame sets" in str(err.value)
    assert not out.exists()
    rejected_only = load_session(waiting_session)
    rejected_only.sets = [s.with_decision("rejected") if s.decision == "accepted" else s
                          for s in rejected_only.sets]
    with open_recording(session.recording) as source, pytest.raises(ExportError,
                                                                     match="no accepted"):
        export_frame_sets(rejected_only, source, "kalibr", out)
