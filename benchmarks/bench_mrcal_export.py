"""End to end: do the exports calibrate? mrcal and OpenCV on them, against the truth.

Makes a synthetic rig (``speechcal synth``: by default two 640x480 cameras, one of them a
fisheye, 90 s, 25 trigger words, seed 7), runs ``speechcal process`` and ``speechcal
export --include-undecided`` in the ``folders`` and ``kalibr`` formats, as a user would
(the command line, in subprocesses), and calibrates each export:

- ``mrcal-calibrate-cameras`` on the export's ``corners.vnl``, run inside the export
  folder with the board figures ``corners.json`` names under ``"mrcal"`` and a rough
  focal length (half the image width): each camera alone, in the lens model matching
  the synthetic one (``LENSMODEL_OPENCV5`` for the pinholes, OpenCV's radial-tangential
  model; ``LENSMODEL_OPENCV8`` for the fisheyes, which mrcal has no equidistant model
  for), then every camera in one run (``LENSMODEL_OPENCV8``) for the rig: the other
  cameras' pose against the first camera's, to the truth;
- OpenCV on ``corners.json`` as the README gives it (``cv2.calibrateCamera``, or
  ``cv2.fisheye.calibrate`` with ``CALIB_RECOMPUTE_EXTRINSIC`` for a fisheye), which needs
  no mrcal.

Prints, per camera, fx fy cx cy recovered against ``truth.json`` and the fit's RMS
reprojection error; for mrcal's fits also how far their projection lies from the true
one over the part of the image the board's corners covered (their convex hull), after the
rotation that best lines the two up (as ``mrcal-show-projection-diff`` does: a centre
a little off is taken up by the board's poses, and moves no projection of the board).
Without mrcal (``apt-get install mrcal``; ``mrcal-calibrate-cameras`` on the PATH) it
says so and prints the OpenCV figures alone. Asserts nothing.

    .venv/bin/python benchmarks/bench_mrcal_export.py [--target checkerboard]
        [--cameras 2 --fisheye 1 --seed 7] [--data DIR] [--keep] [other synth options]

Seed 7, AprilGrid (mrcal 2.2, Debian; mrcal sees each tag's first corner, 36 of a view's
144), recovered - true: pinhole (fx 644.22) fx -0.38, fy -0.31, cx -0.03, cy -0.08 px at
0.055 px RMS, its projection within 0.15 px of the true one where the board was seen;
fisheye (fx 331.30, in OPENCV8) fx +0.09, fy +0.03, cx +0.01, cy -0.25 px at 0.060 px
RMS, within 0.17 px; the rig's baseline 0.12004 m for 0.12000, its rotation 6.847 deg for
6.867; OpenCV on every corner fx -0.01 and +0.17 px at 0.089 and 0.096 px RMS. The same
from both formats. ``--target checkerboard``: fx -0.64 and +0.02 px (mrcal), -0.24 and
+0.05 px (OpenCV), centres within 0.53 px. Three cameras, two of them fisheyes, mono16 in
a ROS2 MCAP recording (seed 3, 60 s, 18 triggers): fx within 0.33 px, centres within
0.40 px, baselines within 0.06 mm. ``--size 1280x720`` (seed 5, 60 s, 18 triggers): fx
+0.39 and -0.12 px, centres within 0.87 px (OpenCV: +0.30 and -0.01 px, within 0.04 px).
mrcal's runs on the same corners differ by up to about 0.05 px in fx. mrcal's
"Noutliers" counts the grid points not seen too (the tags of a board partly out of view:
96 of the 1280x720 pinhole's 648, none rejected); the figures printed tell them apart.
"""

from __future__ import annotations

import argparse
import ast
import json
import math
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import least_squares

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from speechcal_core.synth.camera_model import pixel_rays  # noqa: E402
from speechcal_core.synth.timeline import CameraSpec  # noqa: E402

MRCAL = "mrcal-calibrate-cameras"
FORMATS = ("folders", "kalibr")


def speechcal(*args: str) -> None:
    """Run one ``speechcal`` command, as the console script would; raise on failure."""
    cmd = [sys.executable, "-m", "speechcal_core.cli", *args]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(args[:1])} failed ({done.returncode}): "
                         f"{done.stderr.strip().splitlines()[-1:]}")


def camera_spec(cam: dict) -> CameraSpec:
    """The synthetic camera of a truth.json entry (what its projection needs)."""
    return CameraSpec(cam["name"], cam["model"], cam["width"], cam["height"], cam["fps"],
                      tuple(cam["intrinsics"]), tuple(cam["distortion"]),
                      tuple(map(tuple, cam["T_cam_rig"]["R"])), tuple(cam["T_cam_rig"]["t"]),
                      0, 0, 0.0, 0.0, 0.0)


def camera_folders(export: Path) -> dict[str, str]:
    """Stream -> its image folder in the export, from the manifest."""
    manifest = json.loads((export / "manifest.json").read_text())
    return {frame["stream"]: str(Path(frame["file"]).parent)
            for s in manifest["sets"] for frame in s["frames"] if frame.get("file")}


def run_mrcal(export: Path, folders: list[str], lensmodel: str, focal: float,
              out: Path) -> tuple[list[dict], float, str]:
    """``mrcal-calibrate-cameras`` on the export's corners cache: the camera models, the
    RMS reprojection error and the outlier line."""
    grid = json.loads((export / "corners.json").read_text())["mrcal"]
    out.mkdir(parents=True, exist_ok=True)
    cmd = [MRCAL, "--corners-cache", "corners.vnl", "--lensmodel", lensmodel,
           "--focal", f"{focal:g}", "--object-spacing", str(grid["object_spacing"]),
           "--object-width-n", str(grid["object_width_n"]),
           "--object-height-n", str(grid["object_height_n"]), "--outdir", str(out),
           *[f"{folder}/*.png" for folder in folders]]
    done = subprocess.run(cmd, cwd=export, capture_output=True, text=True, check=False)
    log = done.stdout + done.stderr
    if done.returncode != 0:
        raise RuntimeError(f"mrcal failed ({done.returncode}): {log.strip()[-400:]}")
    rms = [float(m) for m in re.findall(r"## RMS error: ([0-9.eE+-]+)", log)]
    counts = re.search(r"Noutliers: (\d+) out of (\d+)", log)
    dropped, total = (int(counts[1]), int(counts[2])) if counts else (0, 0)
    missing = missing_points(export / "corners.vnl", folders)
    models = [ast.literal_eval((out / f"camera-{i}.cameramodel").read_text())
              for i in range(len(folders))]
    return models, rms[-1], (f"{total - dropped} of {total} grid points fitted "
                             f"({missing} not seen, {dropped - missing} rejected)")


def missing_points(vnl: Path, folders: list[str]) -> int:
    """Grid points listed as not seen ('-') in the images mrcal takes (those of
    ``folders`` with more than 3 points seen): mrcal counts them among its outliers."""
    images: dict[str, list[bool]] = {}
    for line in vnl.read_text().splitlines():
        if line.startswith("#"):
            continue
        name, x = line.split()[:2]
        if name.split("/")[0] in folders:
            images.setdefault(name, []).append(x != "-")
    return sum(len(seen) - sum(seen) for seen in images.values()
               if len(seen) > 1 and sum(seen) > 3)


def opencv_fit(export: Path, stream: str, model: str) -> tuple[list[float], float, int]:
    """fx fy cx cy, RMS and views of OpenCV's fit on ``corners.json``, as the README
    gives it."""
    doc = json.loads((export / "corners.json").read_text())
    board = np.float32(doc["object_points"])
    objs, imgs, size = [], [], None
    for image in doc["images"]:
        if image["stream"] != stream or len(image["ids"]) < 6:
            continue
        objs.append(board[image["ids"]])
        imgs.append(np.float32(image["points"]))
        size = tuple(image["image_size"])
    if model == "fisheye":
        flags = cv2.fisheye.CALIB_RECOMPUTE_EXTRINSIC | cv2.fisheye.CALIB_FIX_SKEW
        rms, k, _d, _r, _t = cv2.fisheye.calibrate(
            [o.reshape(-1, 1, 3) for o in objs], [i.reshape(-1, 1, 2) for i in imgs],
            size, None, None, flags=flags,
            criteria=(cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-10))
    else:
        rms, k, _d, _r, _t = cv2.calibrateCamera(objs, imgs, size, None, None)
    return [k[0, 0], k[1, 1], k[0, 2], k[1, 2]], float(rms), len(objs)


def seen_region(export: Path, stream: str) -> np.ndarray:
    """The convex hull of every corner ``corners.json`` gives in ``stream``'s images."""
    doc = json.loads((export / "corners.json").read_text())
    points = [p for image in doc["images"] if image["stream"] == stream
              for p in image["points"]]
    return cv2.convexHull(np.float32(points).reshape(-1, 1, 2))


def projection_gap(cam: dict, intrinsics: list[float], poly: np.ndarray) -> tuple[float, float]:
    """Median and largest distance (px) between the true projection and an OpenCV-family
    mrcal model's, over the pixels inside ``poly``."""
    rays, valid = pixel_rays(camera_spec(cam), step=4)
    ys, xs = np.mgrid[0 : cam["height"] : 4, 0 : cam["width"] : 4]
    inside = np.array([cv2.pointPolygonTest(poly, (float(x), float(y)), False) >= 0
                       for x, y in zip(xs.ravel(), ys.ravel(), strict=True)])
    keep = valid.ravel() & inside & (rays.reshape(-1, 3)[:, 2] > 1e-3)
    if not keep.any():
        return math.nan, math.nan
    fx, fy, cx, cy, *dist = intrinsics
    k = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]])
    pts = rays.reshape(-1, 3)[keep].astype(np.float64)
    pix = np.stack([xs.ravel()[keep], ys.ravel()[keep]], 1)

    def residual(rvec: np.ndarray) -> np.ndarray:
        proj = cv2.projectPoints(pts, rvec, np.zeros(3), k, np.float64(dist))[0]
        return (proj.reshape(-1, 2) - pix).ravel()

    rvec = least_squares(residual, np.zeros(3)).x
    gap = np.hypot(*residual(rvec).reshape(-1, 2).T)
    return float(np.median(gap)), float(gap.max())


def rig_pose(cams: list[dict]) -> list[tuple[float, float]]:
    """Every camera's true pose against the first one: (baseline m, rotation deg)."""
    r0 = np.array(cams[0]["T_cam_rig"]["R"])
    t0 = np.array(cams[0]["T_cam_rig"]["t"])
    out = []
    for cam in cams:
        r, t = np.array(cam["T_cam_rig"]["R"]), np.array(cam["T_cam_rig"]["t"])
        r_rel = r @ r0.T
        t_rel = t - r_rel @ t0
        angle = math.degrees(np.linalg.norm(cv2.Rodrigues(r_rel)[0]))
        out.append((float(np.linalg.norm(t_rel)), angle))
    return out


def row(label: str, got: list[float], true: list[float], rms: float, extra: str = "") -> str:
    diffs = " ".join(f"{g - t:+7.2f}" for g, t in zip(got, true, strict=True))
    values = " ".join(f"{g:7.2f}" for g in got)
    return f"  {label:<24} {values}   {diffs}   {rms:6.3f}  {extra}"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cameras", type=int, default=2)
    ap.add_argument("--fisheye", type=int, default=1)
    ap.add_argument("--duration", type=float, default=90)
    ap.add_argument("--triggers", type=int, default=25)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--target", choices=("aprilgrid", "checkerboard"), default="aprilgrid")
    ap.add_argument("--data", help="work in this folder (session, exports, models), kept; "
                    "a session already there is used as it is")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder")
    args, synth_args = ap.parse_known_args()

    work = Path(args.data) if args.data else Path(tempfile.mkdtemp(prefix="speechcal-bench-"))
    have_mrcal = shutil.which(MRCAL) is not None
    try:
        session = work / "session"
        if not (session / "truth.json").exists():
            print(f"making the session in {session} ...", file=sys.stderr)
            speechcal("synth", str(session), "--cameras", str(args.cameras),
                      "--fisheye", str(args.fisheye), "--duration", str(args.duration),
                      "--triggers", str(args.triggers), "--seed", str(args.seed),
                      "--target", args.target, "--force", *synth_args)
        truth = json.loads((session / "truth.json").read_text())
        session_file = session / "session.json"
        if not session_file.exists():
            print("processing ...", file=sys.stderr)
            speechcal("process", str(session / truth["recording"]), "--audio",
                      str(session / truth["audio"]), "--target", str(session / "target.yaml"),
                      "-o", str(session_file))
        cams = truth["cameras"]
        print(f"{len(cams)} cameras, {truth['target']['kind']}, seed {truth['seed']}, "
              f"{truth['encoding']}; {len(truth['triggers'])} trigger words")
        if not have_mrcal:
            print(f"mrcal is missing ({MRCAL} not on the PATH; Debian/Ubuntu: apt-get "
                  "install mrcal): its figures are left out, OpenCV's follow")
        for fmt in FORMATS:
            export = work / f"export-{fmt}"
            speechcal("export", str(session_file), "--format", fmt, "--out", str(export),
                      "--include-undecided", "--force")
            folders = camera_folders(export)
            print(f"\n{fmt} export ({export}):")
            print(f"  {'':<24} {'fx':>7} {'fy':>7} {'cx':>7} {'cy':>7}   "
                  f"{'recovered - true':^31}   {'RMS px':>6}")
            for i, cam in enumerate(cams):
                folder = folders.get(cam["name"])
                print(f" {cam['name']} ({cam['model']}, {folder}/)")
                true = cam["intrinsics"]
                print(f"  {'truth':<24} " + " ".join(f"{v:7.2f}" for v in true))
                if folder is None:
                    print("  not in the export")
                    continue
                if have_mrcal:
                    lens = "LENSMODEL_OPENCV8" if cam["model"] == "fisheye" \
                        else "LENSMODEL_OPENCV5"
                    try:
                        models, rms, outliers = run_mrcal(
                            export, [folder], lens, cam["width"] / 2,
                            work / f"mrcal-{fmt}-cam{i}")
                    except RuntimeError as exc:
                        print(f"  mrcal {lens}: {exc}")
                    else:
                        got = models[0]["intrinsics"]
                        med, worst = projection_gap(cam, got,
                                                    seen_region(export, cam["name"]))
                        print(row(f"mrcal {lens[10:]}", got[:4], true, rms, outliers))
                        print(f"  {'':<24} |projection - true| where the board was "
                              f"seen: median {med:.2f} px, max {worst:.2f} px")
                got, rms, views = opencv_fit(export, cam["name"], cam["model"])
                name = "cv2.fisheye.calibrate" if cam["model"] == "fisheye" \
                    else "cv2.calibrateCamera"
                print(row(name, got, true, rms, f"{views} views"))
            if have_mrcal and len(cams) > 1 and all(c["name"] in folders for c in cams):
                try:
                    models, rms, outliers = run_mrcal(
                        export, [folders[c["name"]] for c in cams], "LENSMODEL_OPENCV8",
                        cams[0]["width"] / 2, work / f"mrcal-{fmt}-rig")
                except RuntimeError as exc:
                    print(f"  rig, mrcal OPENCV8: {exc}")
                    continue
                print(f"  rig, one mrcal OPENCV8 run: RMS {rms:.3f} px, {outliers}")
                for cam, model, (base, angle) in list(zip(cams, models, rig_pose(cams),
                                                          strict=True))[1:]:
                    rt = np.float64(model["extrinsics"])
                    print(f"   {cam['name']} from {cams[0]['name']}: baseline "
                          f"{np.linalg.norm(rt[3:]):.5f} m (true {base:.5f}), rotation "
                          f"{math.degrees(np.linalg.norm(rt[:3])):.3f} deg "
                          f"(true {angle:.3f})")
    finally:
        if args.data is None and not args.keep:
            shutil.rmtree(work, ignore_errors=True)
        elif args.data is None:
            print(f"data kept in {work}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
