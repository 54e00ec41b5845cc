"""The corners found in each exported image: corners.json calibrates with OpenCV as it
stands, corners.vnl with mrcal (when installed), both as the session found them."""

from __future__ import annotations

import ast
import json
import re
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

from speechcal_core.calibration.collect import detections_from_details
from speechcal_core.export import export_session_file
from speechcal_core.export.corners import CORNERS_JSON, CORNERS_VNL
from speechcal_core.session.store import load_session, save_session
from speechcal_core.target import TargetSpec

PINHOLE = "/cam0/image_raw"


@pytest.fixture(scope="module")
def processed(tiny_synth, tmp_path_factory) -> tuple[Path, dict]:
    """The tiny session processed (transcript and known offset: no recogniser), every
    set accepted: (session file, truth)."""
    from speechcal_core.pipeline import process_recording

    folder, truth = tiny_synth
    root = tmp_path_factory.mktemp("corners")
    words = root / "words.csv"
    words.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    session = process_recording([str(folder / truth["recording"])],
                                str(folder / truth["audio"]), transcript=str(words),
                                offset_ns=truth["sync"]["offset_ns"])
    session.sets = [replace(s, decision="accepted") for s in session.sets]
    path = root / "session.json"
    save_session(session, path)
    return path, truth


@pytest.fixture(scope="module")
def exported(processed, tmp_path_factory) -> tuple[Path, dict, Path]:
    path, truth = processed
    out = tmp_path_factory.mktemp("corners-export") / "folders"
    export_session_file(path, "folders", out)
    return out, truth, path


def _truth_fx(truth: dict, stream: str) -> float:
    return next(c["intrinsics"][0] for c in truth["cameras"] if c["name"] == stream)


def test_corners_json_holds_what_the_session_found_in_each_image(exported) -> None:
    out, _truth, path = exported
    doc = json.loads((out / CORNERS_JSON).read_text())
    session = load_session(path)
    found = detections_from_details(session.extra["frame_details"])
    assert doc["target"] == {"kind": "aprilgrid", "rows": 6, "cols": 6, "size": 0.055,
                             "spacing": 0.3}
    np.testing.assert_allclose(doc["object_points"], TargetSpec().object_points(), atol=1e-6)
    manifest = json.loads((out / "manifest.json").read_text())
    files = {f["file"] for s in manifest["sets"] for f in s["frames"]}
    assert {image["file"] for image in doc["images"]} == files
    with_corners = 0
    for image in doc["images"]:
        assert (out / image["file"]).exists()
        assert image["image_size"] == [256, 192]
        det = found.get((image["set_id"], image["stream"]))
        if image["ids"]:
            with_corners += 1
            assert image["ids"] == det.ids.tolist()
            np.testing.assert_allclose(image["points"], det.points, atol=1e-3)
        else:
            assert det is None or det.count == 0
    assert with_corners >= 6


def test_opencv_calibrates_from_corners_json_alone(exported) -> None:
    out, truth, _path = exported
    doc = json.loads((out / CORNERS_JSON).read_text())
    board = np.asarray(doc["object_points"], np.float32)
    views = [image for image in doc["images"]
             if image["stream"] == PINHOLE and len(image["ids"]) >= 12]
    assert len(views) >= 3
    obj = [board[image["ids"]] for image in views]
    img = [np.asarray(image["points"], np.float32) for image in views]
    rms, k, *_ = cv2.calibrateCamera(obj, img, tuple(views[0]["image_size"]), None, None)
    assert rms < 0.5
    assert k[0, 0] == pytest.approx(_truth_fx(truth, PINHOLE), rel=0.03)


def _accepted_checkerboard_session(root: Path, cameras: int, fisheye: int
                                   ) -> tuple[Path, dict]:
    """``cameras`` (the last ``fisheye`` of them fisheye) filming a checkerboard,
    processed with its target.yaml and the true sync and word times, every set accepted:
    (session file, truth)."""
    from speechcal_core.pipeline import process_recording
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    generate_session(root / "synth", SynthOptions(
        cameras=cameras, fisheye=fisheye, duration=14.0, width=320, height=240, seed=21,
        claps=1, target_kind="checkerboard"))
    truth = json.loads((root / "synth" / "truth.json").read_text())
    words = root / "words.csv"
    words.write_text("word,start,end\n" + "".join(
        f"capture,{t['start_s']:.4f},{t['end_s']:.4f}\n" for t in truth["triggers"]))
    session = process_recording(
        [str(root / "synth" / truth["recording"])], str(root / "synth" / truth["audio"]),
        transcript=str(words), offset_ns=truth["sync"]["offset_ns"],
        target=TargetSpec.from_kalibr_yaml(root / "synth" / "target.yaml"))
    session.sets = [replace(s, decision="accepted") for s in session.sets]
    path = root / "session.json"
    save_session(session, path)
    return path, truth


@pytest.fixture(scope="module")
def fisheye_export(tmp_path_factory) -> tuple[Path, dict]:
    """One fisheye camera filming a checkerboard, exported as folders: (export folder,
    truth)."""
    root = tmp_path_factory.mktemp("fisheye")
    path, truth = _accepted_checkerboard_session(root, cameras=1, fisheye=1)
    export_session_file(path, "folders", root / "folders")
    return root / "folders", truth


def test_opencv_fisheye_calibrates_from_corners_json_as_the_readme_says(
        fisheye_export) -> None:
    """The README's cv2.fisheye.calibrate call: shaped (N, 1, 3) and (N, 1, 2), with
    CALIB_RECOMPUTE_EXTRINSIC (without it every view keeps its first pose: pixels off)."""
    out, truth = fisheye_export
    (fisheye,) = truth["cameras"]
    assert fisheye["model"] == "fisheye"
    doc = json.loads((out / CORNERS_JSON).read_text())
    board = np.asarray(doc["object_points"], np.float32)
    views = [image for image in doc["images"] if len(image["ids"]) >= 6]
    assert len(views) >= 3
    obj = [board[image["ids"]].reshape(-1, 1, 3) for image in views]
    img = [np.asarray(image["points"], np.float32).reshape(-1, 1, 2) for image in views]
    size = tuple(views[0]["image_size"])
    rms, k, *_ = cv2.fisheye.calibrate(obj, img, size, None, None,
                                       flags=cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC)
    assert rms < 0.5
    assert k[0, 0] == pytest.approx(fisheye["intrinsics"][0], rel=0.03)
    unrefined, *_ = cv2.fisheye.calibrate(obj, img, size, None, None)
    assert unrefined > 1.0  # why the README names the flag


def test_tags_found_again_with_opencv_as_the_readme_says_land_on_corners_json(
        exported) -> None:
    """README: DICT_APRILTAG_36h11, markerBorderBits 2, corners refined with
    cv2.cornerSubPix in a window inside the gap between tags (aruco's own corners sit ~2 px
    inside, where Kalibr's corner squares touch the tags), OpenCV corner c is corner
    k = (1, 0, 3, 2)[c]."""
    out, _truth, _path = exported
    doc = json.loads((out / CORNERS_JSON).read_text())
    params = cv2.aruco.DetectorParameters()
    params.markerBorderBits = 2
    detector = cv2.aruco.ArucoDetector(
        cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11), params)
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-3)
    raw, refined = [], []
    for image in doc["images"]:
        if not image["ids"]:
            continue
        grey = cv2.imread(str(out / image["file"]), cv2.IMREAD_GRAYSCALE)
        corners, tags, _ = detector.detectMarkers(grey)
        if tags is None:
            continue
        found = dict(zip(image["ids"], image["points"], strict=True))
        for quad, tag in zip(corners, tags.ravel(), strict=True):
            side = float(np.linalg.norm(quad[0, 1] - quad[0, 0]))
            win = max(2, round(0.4 * doc["target"]["spacing"] * side))  # inside the gap
            better = cv2.cornerSubPix(grey, quad.reshape(-1, 1, 2).copy(), (win, win),
                                      (-1, -1), criteria).reshape(4, 2)
            for c, k in enumerate((1, 0, 3, 2)):
                if 4 * int(tag) + k in found:
                    known = np.asarray(found[4 * int(tag) + k])
                    raw.append(np.linalg.norm(quad.reshape(4, 2)[c] - known))
                    refined.append(np.linalg.norm(better[c] - known))
    assert len(refined) >= 24
    assert np.median(raw) > 1.0  # why the README says to refine them
    assert np.median(refined) < 0.3
    assert np.percentile(refined, 90) < 1.0


def _vnl_images(text: str) -> dict[str, list[list[str]]]:
    images: dict[str, list[list[str]]] = {}
    for line in text.splitlines():
        if line.startswith("#"):
            continue
        name, *fields = line.split()
        images.setdefault(name, []).append(fields)
    return images


def test_corners_vnl_lists_each_tags_first_corner_on_mrcals_grid(exported) -> None:
    out, _truth, _path = exported
    text = (out / CORNERS_VNL).read_text()
    assert text.startswith("# filename x y level\n")
    images = _vnl_images(text)
    doc = json.loads((out / CORNERS_JSON).read_text())
    assert doc["mrcal"] == {"object_spacing": 0.0715, "object_width_n": 6,
                            "object_height_n": 6, "points": "each tag's first corner"}
    assert set(images) == {image["file"] for image in doc["images"]}
    for image in doc["images"]:
        rows = images[image["file"]]
        found = dict(zip(image["ids"], image["points"], strict=True))
        if not any(4 * k in found for k in range(36)):
            assert rows == [["-", "-", "-"]]  # mrcal: no board in this image
            continue
        assert len(rows) == 36
        for k, fields in enumerate(rows):
            if 4 * k in found:
                x, y = found[4 * k]
                assert fields == [f"{x:.3f}", f"{y:.3f}", "0"]
            else:
                assert fields == ["-", "-", "-"]


def test_a_measured_size_for_the_same_board_scales_the_object_points(processed,
                                                                     tmp_path) -> None:
    path, _truth = processed
    measured = TargetSpec("aprilgrid", 6, 6, 0.088, 0.3)
    export_session_file(path, "kalibr", tmp_path / "kalibr", target=measured)
    doc = json.loads((tmp_path / "kalibr" / CORNERS_JSON).read_text())
    np.testing.assert_allclose(doc["object_points"], measured.object_points(), atol=1e-6)
    assert doc["mrcal"]["object_spacing"] == pytest.approx(0.088 * 1.3)
    # another layout: the ids still name the board the frames were checked against
    other = TargetSpec("checkerboard", 6, 8, 0.045)
    export_session_file(path, "kalibr", tmp_path / "other", target=other)
    doc = json.loads((tmp_path / "other" / CORNERS_JSON).read_text())
    assert doc["target"]["kind"] == "aprilgrid"


def test_a_target_of_another_layout_is_named_in_every_format(processed, tmp_path) -> None:
    """--target with a checkerboard for a session checked against the AprilGrid: the
    folders and bag exports used to say nothing. A bag's target.yaml describes the given
    board, and says so as the Kalibr export's does."""
    path, _truth = processed
    other = TargetSpec("checkerboard", 6, 8, 0.045)
    folders = export_session_file(path, "folders", tmp_path / "folders", target=other)
    assert any("corners.json and corners.vnl place the corners on the assumed 6x6 AprilGrid" in n
               and "not on the given" in n and "process the recording again" in n
               for n in folders.notes)
    bag = export_session_file(path, "rosbag1", tmp_path / "bag", target=other)
    assert any("target.yaml describes the given 8x6 checkerboard" in n for n in bag.notes)
    kalibr = export_session_file(path, "kalibr", tmp_path / "kalibr", target=other)
    assert any("target.yaml describes the given" in n for n in kalibr.notes)
    assert any("corners.json and corners.vnl place the corners on the assumed" in n
               for n in kalibr.notes)


@pytest.mark.skipif(shutil.which("mrcal-calibrate-cameras") is None,
                    reason="mrcal is not installed (Debian: apt-get install mrcal)")
def test_mrcal_calibrates_from_corners_vnl(exported, tmp_path: Path) -> None:
    out, truth, _path = exported
    doc = json.loads((out / CORNERS_JSON).read_text())["mrcal"]
    result = subprocess.run(
        ["mrcal-calibrate-cameras", "--corners-cache", CORNERS_VNL,
         "--lensmodel", "LENSMODEL_OPENCV4", "--focal", "220",
         "--object-spacing", str(doc["object_spacing"]),
         "--object-width-n", str(doc["object_width_n"]),
         "--object-height-n", str(doc["object_height_n"]),
         "--outdir", str(tmp_path), "cam0_image_raw/*.png", "cam1_image_raw/*.png"],
        cwd=out, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    model = (tmp_path / "camera-0.cameramodel").read_text()
    intrinsics = ast.literal_eval(re.search(r"'intrinsics':\s*(\[[^\]]*\])", model).group(1))
    assert intrinsics[0] == pytest.approx(_truth_fx(truth, PINHOLE), rel=0.02)


def test_a_session_without_found_corners_or_board_gets_no_corners_files(processed,
                                                                       tmp_path) -> None:
    """Sessions made before they named their board: which board the stored ids number
    is unknown, so no corners files rather than ones that may be wrong, and a note."""
    path, _truth = processed
    session = load_session(path)
    del session.extra["target"]
    older = tmp_path / "older.json"
    save_session(session, older)
    result = export_session_file(older, "kalibr", tmp_path / "kalibr")
    assert not (tmp_path / "kalibr" / CORNERS_JSON).exists()
    assert not (tmp_path / "kalibr" / CORNERS_VNL).exists()
    assert any("does not name the board its corners were found on" in note
               for note in result.notes)


def test_a_session_whose_frames_show_no_corners_is_told_so(processed, tmp_path) -> None:
    """Processed, but no corners found in any frame (a board too small in the images):
    processing again would not help, and the note does not say it would."""
    path, _truth = processed
    session = load_session(path)
    for entry in session.extra["frame_details"].values():
        for frame in entry["frames"].values():
            frame.pop("ids", None)
            frame.pop("points", None)
    bare = tmp_path / "bare.json"
    save_session(session, bare)
    result = export_session_file(bare, "folders", tmp_path / "out")
    assert not (tmp_path / "out" / CORNERS_JSON).exists()
    (note,) = [n for n in result.notes if n.startswith("no corners.json")]
    assert "no target corners were found in the session's frames" in note
    assert "process the recording again" not in note

def test_corners_found_in_another_frame_than_the_exported_one_are_left_out(
        processed, tmp_path) -> None:
    """The session says which frame its corners were found in; where that is not the
    frame exported (a hand-edited set), the image lists none rather than another
    frame's."""
    path, _truth = processed
    session = load_session(path)
    chosen = {(s.id, f.stream): f.stamp_ns for s in session.sets for f in s.frames}
    found = [(int(k), stream, entry) for k, d in session.extra["frame_details"].items()
             for stream, entry in d["frames"].items() if "ids" in entry]
    assert found and all(entry["stamp_ns"] == chosen[(k, stream)]
                         for k, stream, entry in found)
    set_id, stream, entry = found[0]
    entry["stamp_ns"] += 1
    edited = tmp_path / "edited.json"
    save_session(session, edited)
    export_session_file(edited, "folders", tmp_path / "out")
    doc = json.loads((tmp_path / "out" / CORNERS_JSON).read_text())
    by_key = {(image["set_id"], image["stream"]): image for image in doc["images"]}
    assert by_key[(set_id, stream)]["ids"] == []
    assert sum(bool(image["ids"]) for image in doc["images"]) == len(found) - 1

def test_found_corners_the_sessions_board_lacks_are_left_out(processed, tmp_path) -> None:
    """A session whose stored board is smaller than its corner ids (edited by hand): an
    image whose ids the board lacks lists no corners instead of ids off the board."""
    path, _truth = processed
    session = load_session(path)
    session.extra["target"] = {"kind": "aprilgrid", "rows": 3, "cols": 3, "size": 0.055,
                               "spacing": 0.3}
    edited = tmp_path / "edited.json"
    save_session(session, edited)
    export_session_file(edited, "folders", tmp_path / "out")
    doc = json.loads((tmp_path / "out" / CORNERS_JSON).read_text())
    assert len(doc["object_points"]) == 36
    assert doc["images"] and all(max(image["ids"], default=0) < 36 for image in doc["images"])


@pytest.fixture(scope="module")
def checkerboard_session(tmp_path_factory) -> tuple[Path, dict]:
    """Two pinhole cameras filming a checkerboard, every set accepted: (session file,
    truth)."""
    return _accepted_checkerboard_session(tmp_path_factory.mktemp("checkerboard"),
                                          cameras=2, fisheye=0)


def _baseline_m(truth: dict) -> float:
    """The distance between the two cameras' centres, from the truth's rig poses."""
    centres = []
    for camera in truth["cameras"][:2]:
        pose = camera["T_cam_rig"]
        r, t = np.asarray(pose["R"]), np.asarray(pose["t"])
        centres.append(-r.T @ t)
    return float(np.linalg.norm(centres[1] - centres[0]))


def test_both_cameras_number_a_checkerboards_corners_alike(checkerboard_session,
                                                           tmp_path) -> None:
    """A checkerboard looks alike turned half round, so its corners may be found from
    either end; a joint calibration needs each id to name one corner in every camera.
    An earlier session stored one camera's corners from the far end: the export numbers
    them from the top-left end as well, and OpenCV's stereo calibration finds the rig."""
    path, truth = checkerboard_session
    session = load_session(path)
    for entry in session.extra["frame_details"].values():
        found = entry["frames"]["/cam1/image_raw"]
        found["points"] = found["points"][::-1]  # as an earlier session could store them
    earlier = tmp_path / "earlier.json"
    save_session(session, earlier)
    export_session_file(earlier, "folders", tmp_path / "out")
    doc = json.loads((tmp_path / "out" / CORNERS_JSON).read_text())
    assert doc["target"] == {"kind": "checkerboard", "rows": 6, "cols": 8, "size": 0.045}
    views: dict[str, dict[int, np.ndarray]] = {}
    for image in doc["images"]:
        assert image["ids"] == list(range(48))
        points = np.asarray(image["points"], np.float32)
        assert points[0].sum() < points[-1].sum()  # first corner nearer the top left
        views.setdefault(image["stream"], {})[image["set_id"]] = points
    sets = sorted(views["/cam0/image_raw"])
    assert len(sets) >= 3 and sets == sorted(views["/cam1/image_raw"])
    board = np.asarray(doc["object_points"], np.float32)
    k, dist = [], []
    for camera in truth["cameras"][:2]:
        fx, fy, cx, cy = camera["intrinsics"]
        k.append(np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]]))
        dist.append(np.asarray(camera["distortion"]))
    rms, *_, t, _e, _f = cv2.stereoCalibrate(
        [board] * len(sets), [views["/cam0/image_raw"][s] for s in sets],
        [views["/cam1/image_raw"][s] for s in sets], k[0], dist[0], k[1], dist[1],
        (320, 240), flags=cv2.CALIB_FIX_INTRINSIC)
    assert rms < 1.0
    assert float(np.linalg.norm(t)) == pytest.approx(_baseline_m(truth), rel=0.1)


def test_corners_on_an_assumed_board_are_noted(processed, tmp_path: Path) -> None:
    """A session processed without --target measured its corners on the board process
    assumes: the folders export says so, as the Kalibr export does for target.yaml, and
    a given board needs no such note."""
    path, _truth = processed
    notes = export_session_file(path, "folders", tmp_path / "assumed").notes
    assumed = [n for n in notes if n.startswith("corners.json and corners.vnl")]
    assert assumed == [
        "corners.json and corners.vnl place the corners on the 6x6 AprilGrid of 0.055 m tags "
        "process assumes without --target (the session was processed without --target): if "
        "your board differs, export again with its Kalibr target yaml (speechcal export "
        "--target TARGET.yaml, or Target file… in the window's export dialog); a wrong tag "
        "size scales everything a calibration measures"]
    given = export_session_file(path, "folders", tmp_path / "given", target=TargetSpec()).notes
    assert not any(n.startswith("corners.json and corners.vnl") for n in given)
