"""Calibration target detection per frame: AprilGrid (Kalibr order), checkerboard, ChArUco."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from speechcal_core.frames.grid_fill import fill_missing_tags
from speechcal_core.sources.decode import to_uint8
from speechcal_core.target import TargetSpec

#: longest image side used for the coarse search; corners are refined at full resolution
DETECT_MAX_SIDE = 800
_SUBPIX = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)
# OpenCV's corners run TL, TR, BR, BL around its marker image, which is the AprilTag turned
# by 180 degrees. Kalibr prints the AprilTag upright (y up) and numbers corners
# counter-clockwise from the lower left: (x, y), (x+s, y), (x+s, y+s), (x, y+s).
_KALIBR_FROM_CV = np.array([1, 0, 3, 2])
# the same sheet drawn with y pointing down (tags upright in image rows)
_MIRRORED_FROM_CV = np.array([2, 3, 0, 1])


@dataclass(frozen=True)
class CharucoSpec:
    """A ChArUco board: ``squares_x`` x ``squares_y`` squares of ``square`` metres."""

    squares_x: int = 7
    squares_y: int = 5
    square: float = 0.04
    marker: float = 0.03
    dictionary: int = cv2.aruco.DICT_5X5_100
    kind: str = "charuco"

    def describe(self) -> str:
        """The board in words: "7x5 ChArUco board of 0.04 m squares"."""
        return f"{self.squares_x}x{self.squares_y} ChArUco board of {self.square:g} m squares"

    def board(self) -> cv2.aruco.CharucoBoard:
        """The OpenCV board object."""
        d = cv2.aruco.getPredefinedDictionary(self.dictionary)
        return cv2.aruco.CharucoBoard((self.squares_x, self.squares_y), self.square,
                                      self.marker, d)

    def object_points(self) -> np.ndarray:
        """Inner chessboard corners (N x 3), ids as OpenCV numbers them."""
        return np.asarray(self.board().getChessboardCorners(), np.float64).reshape(-1, 3)


Target = TargetSpec | CharucoSpec
#: corners in the searched image, their object ids, corner refinement half-window (px)
_Found = tuple[np.ndarray, np.ndarray, float]


@dataclass(frozen=True)
class Detection:
    """Corners found in one image: ``points`` (N x 2 px, full resolution) for object ``ids``."""

    points: np.ndarray
    ids: np.ndarray

    @property
    def count(self) -> int:
        """Number of corners."""
        return int(self.ids.size)

    def hull(self) -> np.ndarray:
        """Convex hull of the corners (M x 2 int32, none for no corners), for masks and
        overlays."""
        if self.count == 0:
            return np.zeros((0, 2), np.int32)  # OpenCV's hull of no points is None
        return cv2.convexHull(self.points.astype(np.float32)).reshape(-1, 2).astype(np.int32)


def upright_checkerboard(points: np.ndarray) -> np.ndarray:
    """A checkerboard's corners (all of them, row-major) in the order whose first corner
    lies nearer the image's top left than its last. A checkerboard looks alike turned half
    round, so a detector numbers it from either end; in this one order the cameras of a
    rig (mounted alike) number each corner alike, as a joint calibration needs."""
    if points.shape[0] > 1 and points[0].sum() > points[-1].sum():
        return points[::-1].copy()
    return points


def to_gray(image: np.ndarray, depth: int | None = None) -> np.ndarray:
    """Mono uint8 view of a mono uint8/uint16 or BGR frame (``depth``: a 16-bit stream's
    sensor depth, see ``sources.decode.to_uint8``)."""
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    return to_uint8(image, depth)


class TargetDetector:
    """Finds one target in frames; reuse one instance per thread for speed."""

    def __init__(self, target: Target, max_side: int = DETECT_MAX_SIDE) -> None:
        self.target = target
        self.max_side = max_side
        self.object_points = target.object_points()
        self._order: np.ndarray | None = None  # AprilGrid corner order, once known
        self._dictionary: cv2.aruco.Dictionary | None = None  # AprilGrid: the board's tags
        #: checkerboard: whether the last search that failed saw an AprilGrid's tags
        self._tags_seen = False
        full = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
        if isinstance(target, CharucoSpec):
            self._charuco = cv2.aruco.CharucoDetector(target.board())
        elif target.kind == "aprilgrid":
            # only the board's own ids: identification time grows with the dictionary
            n = target.rows * target.cols
            d = cv2.aruco.Dictionary(full.bytesList[:n], full.markerSize, full.maxCorrectionBits)
            self._dictionary = d
            self._aruco = cv2.aruco.ArucoDetector(d, _kalibr_tag_parameters())
        else:  # a checkerboard: tags say an AprilGrid was filmed instead (4 ms a frame)
            self._aruco = cv2.aruco.ArucoDetector(full, _kalibr_tag_parameters())

    def detect(self, image: np.ndarray) -> Detection | None:
        """Corners of the target in ``image`` (None when it is not found).

        The search runs on a shrunk copy first; when it finds less than most of the
        target it looks again at full resolution (and 1.5x), around what it found. AprilGrid
        tags still missing are then looked for from the tags around them (``grid_fill``).
        A checkerboard not found where the frame shows AprilTags gets no closer look.
        """
        gray = to_gray(image)
        h, w = gray.shape[:2]
        best: _Found | None = None
        scales = [min(1.0, self.max_side / max(h, w))]
        scales += [s for s in (1.0, 1.5) if s > scales[0]]
        x0, y0, x1, y1 = 0, 0, w, h
        for scale in scales:
            crop = gray[y0:y1, x0:x1]
            interp = cv2.INTER_AREA if scale < 1 else cv2.INTER_LINEAR
            small = crop if scale == 1.0 else cv2.resize(crop, None, fx=scale, fy=scale,
                                                         interpolation=interp)
            found = self._detect_kind(small)
            if found is not None:
                points, ids, win = found
                found = (points / scale + (x0, y0), ids, win / scale)
                if best is None or found[1].size > best[1].size:
                    best = found
            if best is not None and (best[1].size >= 0.6 * len(self.object_points)
                                     or not isinstance(self.target, TargetSpec)
                                     or self.target.kind != "aprilgrid"):
                break
            if best is None and self._tags_seen:
                break  # an AprilGrid, not the checkerboard: no closer look finds it
            if best is not None:  # look closer around what was found
                lo, hi = best[0].min(axis=0), best[0].max(axis=0)
                pad = np.maximum((hi - lo) * 0.4 + 16, self._unseen_reach(best, hi - lo))
                x0, y0 = (int(v) for v in np.maximum(lo - pad, 0))
                x1, y1 = (int(v) for v in np.minimum(hi + pad, (w, h)))
        if best is None:
            return None
        points, ids, win = best
        win = max(2, round(win))
        start = points.reshape(-1, 1, 2).astype(np.float32)
        refined = cv2.cornerSubPix(gray, start.copy(), (win, win), (-1, -1),
                                   _SUBPIX).reshape(-1, 2)
        # OpenCV hands back the start of a corner whose refinement ran out of its window:
        # a raw marker corner that far off is no corner to calibrate on (2-5 px off)
        lost = np.all(refined == start.reshape(-1, 2), axis=1)
        if self._dictionary is not None:  # the whole tag goes: grid_fill may place it again
            lost = np.isin(ids // 4, ids[lost] // 4)
        points, ids = refined[~lost].astype(np.float64), ids[~lost]
        # Tried and left out: dropping corners off the map that the tags around their
        # tag give (a local homography; off by over 2 px and a tenth of the tag's side).
        # On 11-camera sessions (3 fisheye; seeds 5-8, untouched while tuning it) it
        # dropped 30 of the 50 corners over 2 px off the truth and no corner within
        # 0.5 px, but OpenCV calibrations of the pinhole cameras came out no closer to the
        # true intrinsics (median |fx - truth| 0.111 -> 0.112 px, worst 1.78 -> 2.10)
        if self._dictionary is not None:
            assert isinstance(self.target, TargetSpec)
            points, ids = fill_missing_tags(gray, points, ids, self.object_points,
                                            self.target.pitch, self._dictionary, win)
        if ids.size == 0:
            return None  # every tag found had a corner refinement lost, none placed again
        return Detection(points, ids.astype(np.int32))

    def _unseen_reach(self, found: _Found, seen: np.ndarray) -> np.ndarray:
        """How far (x, y pixels) the rest of an AprilGrid may reach beyond the part found:
        one tag found on a small image says the board spans about six tags around it."""
        points = found[0]
        assert isinstance(self.target, TargetSpec)
        side = float(np.median(np.linalg.norm(points[1::4] - points[0::4], axis=1)))
        extent = side * (1 + self.target.spacing) * max(self.target.rows, self.target.cols)
        return np.maximum(1.2 * (extent - seen), 0.0)

    def _detect_kind(self, small: np.ndarray) -> _Found | None:
        if isinstance(self.target, CharucoSpec):
            return self._detect_charuco(small)
        if self.target.kind == "aprilgrid":
            return self._detect_aprilgrid(small)
        return self._detect_checkerboard(small)

    # -- per kind: (points in the small image, ids, refinement half-window in small px) ---

    def _detect_aprilgrid(self, small: np.ndarray) -> _Found | None:
        corners, tag_ids, _ = self._aruco.detectMarkers(small)
        assert isinstance(self.target, TargetSpec)
        n_tags = self.target.rows * self.target.cols
        if tag_ids is None:
            return None
        keep = [k for k, t in enumerate(tag_ids.ravel()) if 0 <= t < n_tags]
        if not keep:
            return None
        quads = np.stack([corners[k].reshape(4, 2) for k in keep])  # (T, 4, 2) TL TR BR BL
        tags = tag_ids.ravel()[keep]
        order = self._order
        if order is None:
            order, decisive = _tag_corner_order(quads, tags, self.object_points)
            if decisive:
                self._order = order
        points = quads[:, order, :].reshape(-1, 2)
        ids = (tags[:, None] * 4 + np.arange(4)[None, :]).ravel()
        side = float(np.median(np.linalg.norm(quads[:, 1] - quads[:, 0], axis=1)))
        # corners of neighbouring tags sit spacing*size apart: keep the window inside the gap
        win = max(1.5, min(side * self.target.spacing * 0.45, side / 8))
        return points, ids, win

    def _detect_checkerboard(
        self, small: np.ndarray
    ) -> _Found | None:
        assert isinstance(self.target, TargetSpec)
        size = (self.target.cols, self.target.rows)
        ok, corners = cv2.findChessboardCornersSB(small, size, flags=cv2.CALIB_CB_NORMALIZE_IMAGE)
        # An AprilGrid filmed (a wrong --target) passes OpenCV's quick check, and on a
        # 1280x720 frame the classic detector and the looks at 1.0x and 1.5x then cost
        # 2.3 s (``benchmarks/bench_wrong_target.py``). A checkerboard that the shrunk
        # frame shows no trace of (far, blurred) may still be found at 1.0x: its tags
        # are what tells an AprilGrid apart
        self._tags_seen = not ok and _shows_tags(self._aruco, small)
        if self._tags_seen:
            return None
        if not ok and _classic_finds_checkerboard(small, size):
            # the exhaustive search took 1-3 s on each 256x192 frame without the board (a
            # wrong --target cost minutes); on 413 synthetic frames and 150 rendered views
            # (tilted, blurred, dim, noisy) it found no board the plain search missed.
            # OpenCV's quick check alone lets an AprilGrid close-up through: the classic
            # detector finding the whole board is the gate
            flags = cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE
            ok, corners = cv2.findChessboardCornersSB(small, size, flags=flags)
        if not ok:
            return None
        points = upright_checkerboard(corners.reshape(-1, 2).astype(np.float64))
        step = np.linalg.norm(points[1] - points[0])
        return points, np.arange(points.shape[0]), max(1.5, step * 0.3)

    def _detect_charuco(self, small: np.ndarray) -> _Found | None:
        corners, ids, _, _ = self._charuco.detectBoard(small)
        if ids is None or len(ids) < 4:
            return None
        points = corners.reshape(-1, 2).astype(np.float64)
        d = np.linalg.norm(points[:, None] - points[None], axis=2)
        np.fill_diagonal(d, np.inf)
        assert isinstance(self.target, CharucoSpec)
        gap = (1 - self.target.marker / self.target.square) / 2  # corner to marker, in squares
        return points, ids.ravel(), max(1.5, float(np.median(d.min(axis=1))) * gap * 0.8)


def _kalibr_tag_parameters() -> cv2.aruco.DetectorParameters:
    """OpenCV's marker search set for the AprilTags of Kalibr's AprilGrid."""
    params = cv2.aruco.DetectorParameters()
    params.markerBorderBits = 2
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_NONE
    # small threshold windows keep tags apart from Kalibr's corner squares
    params.adaptiveThreshWinSizeMin = 3
    params.adaptiveThreshWinSizeMax = 5
    params.adaptiveThreshWinSizeStep = 2
    params.minMarkerPerimeterRate = 0.03
    return params


def _shows_tags(finder: cv2.aruco.ArucoDetector, image: np.ndarray, least: int = 2) -> bool:
    """Whether ``image`` shows at least ``least`` AprilTags (36h11, Kalibr's border)."""
    _, ids, _ = finder.detectMarkers(image)
    return ids is not None and len(ids) >= least


def _classic_finds_checkerboard(image: np.ndarray, size: tuple[int, int]) -> bool:
    """Whether OpenCV's classic detector, quick check first, finds the whole board (a few
    milliseconds on a frame without one)."""
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_FAST_CHECK
    return bool(cv2.findChessboardCorners(image, size, flags=flags)[0])


def _tag_corner_order(
    quads: np.ndarray, tags: np.ndarray, obj: np.ndarray
) -> tuple[np.ndarray, bool]:
    """Corner order mapping OpenCV tag corners to Kalibr's object points, and if it is sure.

    A board printed as Kalibr prints it (tags upright with y up) needs the reversed order; a
    board drawn with y pointing down needs OpenCV's own. Tags spanning two rows and two
    columns tell them apart (only the right order fits one homography); otherwise Kalibr's.
    """
    src_all = obj[(tags[:, None] * 4 + np.arange(4)[None, :]).ravel(), :2]
    spread = np.ptp(src_all, axis=0)
    pitch = float(np.linalg.norm(obj[4, :2] - obj[0, :2])) if len(obj) > 4 else 0.0
    if len(tags) < 3 or min(spread) <= pitch:
        return _KALIBR_FROM_CV, False
    errors = []
    for order in (_KALIBR_FROM_CV, _MIRRORED_FROM_CV):
        img = quads[:, order, :].reshape(-1, 2)
        h, _ = cv2.findHomography(src_all, img, 0)
        if h is None:
            errors.append(np.inf)
            continue
        proj = cv2.perspectiveTransform(src_all.reshape(-1, 1, 2), h).reshape(-1, 2)
        errors.append(float(np.mean(np.linalg.norm(proj - img, axis=1))))
    k = int(np.argmin(errors))
    decisive = errors[k] * 4 < errors[1 - k]
    return (_KALIBR_FROM_CV, _MIRRORED_FROM_CV)[k], decisive
