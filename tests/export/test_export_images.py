"""Kalibr and per-camera folder exports: layout, shared names, lossless pixels, target.yaml."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest
from ruamel.yaml import YAML

from speechcal_core.export import export_session_file
from speechcal_core.session.store import load_session
from speechcal_core.sources import open_recording
from speechcal_core.target import TargetSpec


def _accepted(session_path: Path):
    return [s for s in load_session(session_path).sets if s.decision == "accepted"]


def _assert_pixels_equal_source(session_path: Path, out: Path, folders: dict[str, str]) -> int:
    session = load_session(session_path)
    checked = 0
    with open_recording(session.recording) as source:
        for s in _accepted(session_path):
            for f in s.frames:
                if f.index < 0:
                    continue
                written = cv2.imread(str(out / folders[f.stream] / f"{s.t_ns}.png"),
                                     cv2.IMREAD_UNCHANGED)
                expected = source.frame(f.stream, f.index)
                assert written.dtype == expected.dtype and written.shape == expected.shape
                assert np.array_equal(written, expected)
                checked += 1
    return checked


def test_kalibr_export_names_files_alike_across_cameras(session_file, tmp_path: Path) -> None:
    path = session_file()
    out = tmp_path / "kalibr"
    result = export_session_file(path, "kalibr", out)
    accepted = _accepted(path)
    assert result.sets == len(accepted) == 3
    names = {f"{s.t_ns}.png" for s in accepted}
    cams = sorted(p.name for p in out.iterdir() if p.is_dir())
    assert cams == ["cam0", "cam1"]
    for cam in cams:
        assert {p.name for p in (out / cam).iterdir()} == names
    # a session made from the synthetic truth holds no found corners: no corners files
    assert sorted(p.name for p in out.iterdir() if p.is_file()) == [
        "manifest.csv", "manifest.json", "target.yaml"]
    assert any(note.startswith("no corners.json or corners.vnl: the session holds no found "
                               "corners") for note in result.notes)


def test_a_camera_without_frames_leaves_its_kalibr_number_free(session_file,
                                                                tmp_path: Path) -> None:
    from dataclasses import replace

    from speechcal_core.session.store import save_session

    path = session_file()
    session = load_session(path)
    for s in list(session.sets):  # /cam0 has no frame in any set: /cam1 stays cam1
        session.replace_set(replace(s, frames=tuple(
            replace(f, index=-1) if f.stream.startswith("/cam0") else f for f in s.frames)))
    save_session(session, path)
    result = export_session_file(path, "kalibr", tmp_path / "kalibr")
    assert sorted(p.name for p in (tmp_path / "kalibr").iterdir() if p.is_dir()) == ["cam1"]
    assert ("/cam0/image_raw has no frame in any exported set and is left out; the other "
            "cameras keep their numbers (no cam0 folder)") in result.notes
    folders = export_session_file(path, "folders", tmp_path / "folders")
    assert "/cam0/image_raw has no frame in any exported set and is left out" in folders.notes


def test_kalibr_pngs_hold_exactly_the_decoded_source_frames(session_file, tmp_path) -> None:
    path = session_file("ros1", "jpeg")
    out = tmp_path / "kalibr"
    export_session_file(path, "kalibr", out)
    with open_recording(load_session(path).recording) as source:
        streams = [s.name for s in source.streams]
    assert _assert_pixels_equal_source(path, out, {n: f"cam{k}" for k, n in enumerate(streams)})


def test_target_yaml_is_kalibr_yaml_with_float_sizes(session_file, tmp_path: Path) -> None:
    out = tmp_path / "kalibr"
    result = export_session_file(session_file(), "kalibr", out)
    doc = YAML(typ="safe").load((out / "target.yaml").read_text())
    assert doc == {"target_type": "aprilgrid", "tagCols": 6, "tagRows": 6,
                   "tagSize": 0.055, "tagSpacing": 0.3}
    assert isinstance(doc["tagSize"], float) and isinstance(doc["tagSpacing"], float)
    assert result.target == "default"


def test_a_given_checkerboard_target_is_written_with_float_spacings(session_file, tmp_path):
    out = tmp_path / "kalibr"
    target = TargetSpec("checkerboard", 7, 9, 0.04)
    result = export_session_file(session_file(), "kalibr", out, target=target)
    doc = YAML(typ="safe").load((out / "target.yaml").read_text())
    assert doc["target_type"] == "checkerboard"
    assert (doc["targetRows"], doc["targetCols"]) == (7, 9)
    assert isinstance(doc["rowSpacingMeters"], float) and doc["colSpacingMeters"] == 0.04
    assert TargetSpec.from_kalibr_yaml(out / "target.yaml") == target
    assert result.target == "given"


@pytest.mark.parametrize(("fmt", "encoding", "dtype", "channels"), [
    ("ros2-sqlite3", "mono16", np.uint16, 1),
    ("ros2-mcap", "bayer_rggb8", np.uint8, 3),
    ("ros1", "mono8", np.uint8, 1),
])
def test_folders_export_keeps_depth_and_demosaics_bayer(
    session_file, tmp_path: Path, fmt: str, encoding: str, dtype, channels: int
) -> None:
    path = session_file(fmt, encoding)
    out = tmp_path / "folders"
    export_session_file(path, "folders", out)
    folders = {"/cam0/image_raw": "cam0_image_raw", "/cam1/image_raw": "cam1_image_raw"}
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == sorted(folders.values())
    names = {f"{s.t_ns}.png" for s in _accepted(path)}
    for folder in folders.values():
        assert {p.name for p in (out / folder).iterdir()} == names
    one = cv2.imread(str(out / "cam0_image_raw" / sorted(names)[0]), cv2.IMREAD_UNCHANGED)
    assert one.dtype == dtype and (one.ndim == 2) == (channels == 1)
    assert _assert_pixels_equal_source(path, out, folders) == 6


def test_a_frame_that_cannot_be_decoded_is_left_out_and_named(session_file, tmp_path) -> None:
    import json

    from export_sessions import accepted_sets_over

    from speechcal_core.export import export_frame_sets

    kalibr = tmp_path / "kalibr"
    export_session_file(session_file(), "kalibr", kalibr)
    damaged = sorted((kalibr / "cam1").iterdir())[0]
    damaged.write_bytes(damaged.read_bytes()[:200])  # truncated PNG
    with open_recording([kalibr]) as folder_source:
        session = accepted_sets_over(folder_source, ["cam0", "cam1"])
        result = export_frame_sets(session, folder_source, "folders", tmp_path / "out")
    assert result.sets == 3 and result.frames == 5
    assert len(result.skipped) == 1 and damaged.name in result.skipped[0]
    assert not (tmp_path / "out" / "cam1" / damaged.name).exists()
    assert (tmp_path / "out" / "cam0" / damaged.name).exists()
    doc = json.loads((tmp_path / "out" / "manifest.json").read_text())
    frame = next(f for s in doc["sets"] for f in s["frames"] if "skipped" in f)
    assert frame["stream"] == "cam1" and frame["file"] is None


def test_an_export_whose_every_frame_is_damaged_is_refused_and_writes_nothing(
        session_file, tmp_path) -> None:
    """It said "exported 3 frame sets (0 frames, 2 files)" and exited 0: an empty export
    (a manifest, empty camera folders) taken for a good one."""
    from export_sessions import accepted_sets_over

    from speechcal_core.export import ExportError, export_frame_sets

    kalibr = tmp_path / "kalibr"
    export_session_file(session_file(), "kalibr", kalibr)
    for image in (kalibr / "cam0").iterdir():
        image.write_bytes(image.read_bytes()[:200])  # truncated PNGs
    out = tmp_path / "out"
    with open_recording([kalibr]) as folder_source:
        session = accepted_sets_over(folder_source, ["cam0"])
        with pytest.raises(ExportError) as err:
            export_frame_sets(session, folder_source, "folders", out)
    assert str(err.value).startswith("the session: none of the frames to export could be "
                                     "read (set 1 cam0: ")
    assert "nothing was exported: reject those sets in the review window" in str(err.value)
    assert not out.exists() and not [p for p in tmp_path.iterdir() if "out" in p.name]


def test_kalibr_names_of_sets_under_a_second_read_as_kalibr_bagcreater_reads_them(
        session_file, tmp_path: Path) -> None:
    """A camera clock that starts at 0 (a video, an image folder, simulated time): a set
    at 0.6 s was named "600000000.png", and kalibr_bagcreater, which takes all but the
    last nine digits of a name as its seconds (``int(name[0:-9])``), failed on it; a set
    at 9.5 s sorted after one at 12 s, as it sorts names as text. Every name now has 19
    digits, zeros in front."""
    import shutil

    from export_sessions import accepted_sets_over

    from speechcal_core.export import export_frame_sets

    made = tmp_path / "made"
    export_session_file(session_file(), "kalibr", made)
    early = tmp_path / "early"  # the same frames on a clock started at 0
    times = [600_000_000, 9_500_000_000, 12_000_000_000]
    for cam in ("cam0", "cam1"):
        (early / cam).mkdir(parents=True)
        for t, image in zip(times, sorted((made / cam).iterdir()), strict=True):
            shutil.copy(image, early / cam / f"{t}.png")
    out = tmp_path / "kalibr"
    with open_recording([early]) as source:
        export_frame_sets(accepted_sets_over(source, ["cam0", "cam1"]), source, "kalibr", out)
    for cam in ("cam0", "cam1"):
        stems = sorted(p.stem for p in (out / cam).iterdir())  # as kalibr_bagcreater sorts
        assert stems == ["0000000000600000000", "0000000009500000000", "0000000012000000000"]
        assert [int(s[0:-9]) * 10**9 + int(s[-9:]) for s in stems] == times
    with open_recording([out]) as again:  # and SpeechCal reads such a folder back
        assert list(again.stamps("cam0")) == times
