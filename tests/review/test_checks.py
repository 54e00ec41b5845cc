"""Coverage and the calibration check follow the frames re-scoring chose and the decisions."""

from __future__ import annotations

from pathlib import Path

import pytest
from review_models import open_model
from truth_sessions import truth_triggers

from speechcal_core.frames.analysis import analyse_frames
from speechcal_core.review.checks import check_summary
from speechcal_core.review.model import ReviewModel
from speechcal_core.session.store import load_session
from speechcal_core.target import TargetSpec

SHIFT_NS = -1_000_000_000  # far enough that re-scoring picks other still frames


def _rescore(model: ReviewModel) -> None:
    model.apply_rescored(model.rescore_request().run(model.source))


def _recheck(model: ReviewModel) -> bool:
    request = model.checks_request()
    assert request is not None
    return model.apply_checks(request.run())


def test_after_an_offset_edit_the_checks_wait_for_rescoring_then_match_the_pipeline(
    searched_session_file: Path, tiny_synth: tuple[Path, dict],
) -> None:
    model = open_model(searched_session_file)
    assert not model.checks_due()  # as process left them
    before = model.session.extra["coverage"]
    model.nudge_offset(SHIFT_NS)
    # nearest frames for now: nothing to check them on, and the window says so
    assert not model.checks_due() and model.checks_request() is None
    summary = check_summary(model.session, model.streams)
    assert summary.line == "calibration check: after re-scoring"
    _rescore(model)
    assert model.checks_due()
    assert check_summary(model.session, model.streams).line == "calibration check: updating…"
    events: list = []
    model.connect("checks", lambda: events.append(True))
    assert _recheck(model) and events == [True] and not model.checks_due()

    _folder, truth = tiny_synth
    pipeline = analyse_frames(model.source, model.session.sync, truth_triggers(truth),
                              TargetSpec())
    coverage = model.session.extra["coverage"]
    assert coverage != before
    assert set(coverage) == set(pipeline.extra["coverage"])
    for stream, want in pipeline.extra["coverage"].items():
        assert coverage[stream]["views"] == want["views"]
        assert coverage[stream]["progress"] == pytest.approx(want["progress"], abs=2e-3)
    calibration = model.session.calibration
    assert set(calibration) == set(pipeline.calibration)
    for stream, want in pipeline.calibration.items():
        assert calibration[stream]["model"] == want["model"]
        assert calibration[stream]["rms_px"] == pytest.approx(want["rms_px"], abs=0.01)
    saved = load_session(searched_session_file)
    assert saved.calibration == calibration and saved.extra["coverage"] == coverage
    summary = check_summary(model.session, model.streams)
    assert summary.line.startswith(f"calibration check over {len(model.session.sets)} sets")
    assert len(summary.cameras) == len(model.streams)


def test_a_rejected_set_leaves_the_checks_and_a_stale_result_is_refused(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    first = model.current_set.id
    model.reject()
    assert model.checks_due()
    request = model.checks_request()
    model.accept()  # changed meanwhile: that result is for other decisions
    assert not model.apply_checks(request.run())
    assert not model.checks_due()  # back to what the checks were computed over
    seen = {stream for stream, entry in model.session.extra["frame_details"][str(first)][
        "frames"].items() if entry.get("points")}
    before = {k: v["views"] for k, v in model.session.extra["coverage"].items()}
    model.reject()
    assert _recheck(model)
    after = {k: v["views"] for k, v in model.session.extra["coverage"].items()}
    assert seen and {k: before[k] - (k in seen) for k in before} == \
        {k: after.get(k, 0) for k in before}


def test_a_checks_request_reads_the_corners_where_it_runs_from_a_copy_of_the_details(
    searched_session_file: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Asking for the checks (on the UI thread) only copies what they need: the corners
    are parsed out of the frame details (megabytes with a dozen cameras) by ``run`` on
    the worker, from the details as they were when asked, whatever the review replaces
    meanwhile."""
    import speechcal_core.review.checks as checks

    model = open_model(searched_session_file)
    model.reject()
    parsed: list[int] = []
    real = checks.detections_from_details
    monkeypatch.setattr(checks, "detections_from_details",
                        lambda details: parsed.append(len(details)) or real(details))
    request = model.checks_request()
    assert request is not None and parsed == []
    details = model.session.extra["frame_details"]
    want = real(details)
    some = next(iter(details))
    details.pop(some)  # replaced meanwhile (an offset edit drops a set's details)
    got = request.detections()
    assert parsed and set(got) == set(want)
    assert all((got[k].points == want[k].points).all() for k in want)
    details[some] = request.details[some]
    assert model.apply_checks(request.run()) and not model.checks_due()


def test_a_session_without_target_corners_has_no_checks_to_keep(truth_session_file: Path) -> None:
    model = open_model(truth_session_file)
    model.reject()
    assert not model.checks_due() and model.checks_request() is None
    assert check_summary(model.session, model.streams) is None


def test_export_waits_for_the_sets_it_holds_that_show_nearest_frames(
    searched_session_file: Path,
) -> None:
    model = open_model(searched_session_file)
    ids = [s.id for s in model.session.sets]
    model.go_to_set(0)
    model.accept()
    model.go_to_set(1)
    model.reject()
    assert model.export_waits_for() == []
    model.nudge_offset(SHIFT_NS)
    assert model.export_waits_for() == [ids[0]]
    assert model.export_waits_for(include_undecided=True) == [ids[0], *ids[2:]]
    _rescore(model)
    assert model.export_waits_for(include_undecided=True) == []


def test_no_camera_fitting_says_which_board_was_looked_for(checkerboard_synth,
                                                           tmp_path: Path) -> None:
    """A checkerboard recording processed without --target (so as the default AprilGrid)
    fits no camera: the check line says what it looked for and what to do."""
    from speechcal_core.pipeline import process_recording

    folder, truth = checkerboard_synth
    words = tmp_path / "words.csv"  # the true triggers: this is about the board
    words.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    session = process_recording([str(folder / truth["recording"])],
                                str(folder / truth["audio"]), transcript=str(words),
                                offset_ns=truth["sync"]["offset_ns"])
    assert len(session.sets) >= 4
    summary = check_summary(session, ["/cam0/image_raw"])
    assert summary is not None and " 0 of 1 camera fit" in summary.line
    assert "(looked for a 6x6 AprilGrid of 0.055 m tags: if the board is another one" \
        in summary.line
    assert session.extra["target_assumed"] is True  # no --target: the default board
    assert "--target TARGET.yaml" in summary.line


def test_too_few_sets_are_named_as_the_reason_not_the_board(
        searched_session_file: Path) -> None:
    """With fewer sets kept than a fit needs, the line says so; it does not send the
    operator to process again with another --target."""
    from speechcal_core.calibration.check import MIN_VIEWS

    model = open_model(searched_session_file)
    while sum(s.decision != "rejected" for s in model.session.sets) >= MIN_VIEWS:
        model.go_to_set(next(i for i, s in enumerate(model.session.sets)
                             if s.decision != "rejected"))
        model.reject()
    if model.checks_due():
        _recheck(model)
    summary = check_summary(model.session, model.streams)
    assert summary is not None and summary.warning
    assert summary.line.endswith(f"cameras fit (a fit needs the target in {MIN_VIEWS} sets "
                                 "or more)")


def test_a_board_seen_in_too_few_sets_is_named_as_the_reason_not_the_board(
        searched_session_file: Path) -> None:
    """Enough sets kept, but the board in fewer than a fit needs (the others show no frame,
    as in a recording cut short): the line names the count, not another --target."""
    from speechcal_core.calibration.check import MIN_VIEWS

    session = load_session(searched_session_file)
    assert sum(s.decision != "rejected" for s in session.sets) >= MIN_VIEWS
    for cover in session.extra["coverage"].values():  # as the checks count such sets
        cover["views"] = min(cover["views"], MIN_VIEWS - 1)
    session.calibration = {}
    summary = check_summary(session, list(session.extra["coverage"]))
    assert summary is not None and summary.warning
    assert summary.line.endswith(f"(a fit needs the target in {MIN_VIEWS} sets or more; "
                                 f"no camera saw it in more than {MIN_VIEWS - 1})")
    assert "--target" not in summary.line


def test_a_camera_that_saw_the_board_only_near_its_centre_is_warned_about(
        searched_session_file: Path) -> None:
    """Fisheye cameras whose views all lay near the image centre passed as "4 of 4
    cameras fit, RMS ≤ 0.13 px": their lens toward the edges is barely measured."""
    session = load_session(searched_session_file)
    fitted = [name for name in session.extra["coverage"] if name in session.calibration]
    summary = check_summary(session, fitted)
    assert summary is not None and not summary.warning
    assert "centre" not in summary.line
    progress = session.extra["coverage"][fitted[0]]["progress"]
    progress["x"], progress["y"] = 0.15, 0.18
    summary = check_summary(session, fitted)
    assert summary.warning
    assert summary.line.endswith("; 1 camera saw the board only near the image centre")
    assert "▲ the board stayed near the image centre" in summary.cameras[0]
    progress["y"] = 0.5  # spread down the image: not only near the centre
    assert not check_summary(session, fitted).warning


def test_with_every_set_rejected_the_line_says_so(searched_session_file: Path) -> None:
    """Nothing left to check: the line says why instead of counting a check over 0 sets."""
    model = open_model(searched_session_file)
    for k in range(len(model.session.sets)):
        model.go_to_set(k)
        model.reject()
    if model.checks_due():
        _recheck(model)
    summary = check_summary(model.session, model.streams)
    assert summary is not None and summary.warning
    assert summary.line == ("calibration check: every frame set is rejected; accept some "
                            "to check the calibration")
