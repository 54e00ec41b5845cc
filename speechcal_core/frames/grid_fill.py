"""Find the AprilGrid tags the marker detector missed, from the tags around them.

OpenCV's AprilTag detector loses tags under about 30 px (a fisheye's board edge, a board
held far away), although the operator sees them plainly. Where a missing tag has found
neighbours, their corners map the board plane locally (a homography over a small patch
holds even under fisheye distortion); the tag's four corners are predicted through it,
refined on the image, and kept only if the tag read there carries the expected id's code
(all its bits bar MAX_BIT_ERRORS of 36) turned as the found tags' codes are turned (how a
print lays the codes out is read from the found tags). Newly found tags predict their own
neighbours, so the grid fills from what was found outward.
"""

from __future__ import annotations

import functools

import cv2
import numpy as np

#: a tag is predicted from found tags whose centres lie within this many pitches
NEIGHBOUR_PITCHES = 1.5
#: ... of which at least this many are needed (one tag's four corners fix a homography)
MIN_NEIGHBOURS = 1
#: a read tag may differ from the expected code, turned as the board's codes are, in this
#: many of its 36 bits; 36h11 codes differ in at least 11 however turned, so a wrong tag
#: or a blank patch cannot pass (other turns or a mirror image of a code may differ from
#: it in only 6: hence one turn, learnt from the found tags)
MAX_BIT_ERRORS = 3
#: cells across a tag with its 2-bit black border (6 data bits + 2 + 2)
CELLS = 10
BORDER = 2
SAMPLES_PER_CELL = 3
#: grey levels between the border's mean and the lightest code cell: less is no tag
MIN_CONTRAST = 20.0
#: a refined corner may move at most this fraction of the refinement window
MAX_SHIFT = 1.0
#: a tag that does not read after refinement is refined again in this share of the window
NARROW = 0.6
_SUBPIX = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.01)


def fill_missing_tags(gray: np.ndarray, points: np.ndarray, ids: np.ndarray,
                      object_points: np.ndarray, pitch: float,
                      dictionary: cv2.aruco.Dictionary, window: float
                      ) -> tuple[np.ndarray, np.ndarray]:
    """``points``/``ids`` (Kalibr corner ids, four per tag) plus the tags found around them.

    ``object_points`` are the grid's corners in board metres (N x 3, four per tag in
    Kalibr order), ``pitch`` the distance between neighbouring tags, ``dictionary`` the
    board's tags (id = tag number), ``window`` the corner refinement half-window in px.
    """
    n_tags = object_points.shape[0] // 4
    board = object_points[:, :2].reshape(n_tags, 4, 2)
    centres = board.mean(axis=1)
    apart = np.linalg.norm(centres[:, None] - centres[None], axis=2)
    around = [np.flatnonzero((apart[t] <= NEIGHBOUR_PITCHES * pitch) & (apart[t] > 0))
              for t in range(n_tags)]
    found: dict[int, np.ndarray] = {}
    for tag in np.unique(ids // 4):
        corners = points[ids // 4 == tag]
        if corners.shape[0] == 4:
            found[int(tag)] = corners[np.argsort(ids[ids // 4 == tag])]
    if len(found) < MIN_NEIGHBOURS or len(found) == n_tags:
        return points, ids
    codes = _expected_codes(dictionary, n_tags)
    turn = _board_turn(gray, board, found, codes)
    if turn is None:
        return points, ids
    tried: set[tuple[int, frozenset[int]]] = set()
    grew = True
    while grew:
        grew = False
        for tag in range(n_tags):
            if tag in found:
                continue
            near = [int(t) for t in around[tag] if t in found]
            if len(near) < MIN_NEIGHBOURS:
                continue
            # all neighbours together, else each alone: one slightly off corner among
            # them can tilt the joint map, while a single tag maps its own patch
            for group in [near, *([t] for t in near if len(near) > 1)]:
                key = (tag, frozenset(group))
                if key in tried:
                    continue
                tried.add(key)
                # a small tag's refinement may lock onto its corner squares: then a
                # narrower window, still inside the gap, is tried
                for win in (window, max(1.0, NARROW * window)):
                    refined = _place(gray, board, found, group, tag, win)
                    if refined is not None and _reads_as(gray, board[tag], refined,
                                                         codes[tag, turn]):
                        found[tag] = refined
                        grew = True
                        break
                if tag in found:
                    break
    added = sorted(set(found) - set((ids // 4).tolist()))
    if not added:
        return points, ids
    new_ids = (np.asarray(added)[:, None] * 4 + np.arange(4)[None, :]).ravel()
    return (np.concatenate([points, *(found[t] for t in added)]),
            np.concatenate([ids, new_ids.astype(ids.dtype)]))


def _place(gray: np.ndarray, board: np.ndarray, found: dict[int, np.ndarray],
           near: list[int], tag: int, window: float) -> np.ndarray | None:
    """The tag's corners predicted from ``near`` and refined on the image; None when the
    prediction leaves the image or the refinement moves a corner too far."""
    corners = _predict(board, found, near, tag)
    h, w = gray.shape[:2]
    if corners is None or not _inside(corners, w, h, window):
        return None
    refined = cv2.cornerSubPix(gray, corners.reshape(-1, 1, 2).astype(np.float32),
                               (round(window), round(window)), (-1, -1),
                               _SUBPIX).reshape(4, 2).astype(np.float64)
    if np.linalg.norm(refined - corners, axis=1).max() > MAX_SHIFT * window:
        return None
    return refined


def _reads_as(gray: np.ndarray, board_corners: np.ndarray, corners: np.ndarray,
              code: np.ndarray) -> bool:
    """Whether the tag at ``corners`` carries ``code`` (up to MAX_BIT_ERRORS bits)."""
    bits = _read_bits(gray, board_corners, corners)
    return bits is not None and int(np.sum(bits != code)) <= MAX_BIT_ERRORS


def _predict(board: np.ndarray, found: dict[int, np.ndarray], near: list[int],
             tag: int) -> np.ndarray | None:
    """The tag's four corners in the image, through the neighbours' board-to-image map."""
    src = np.concatenate([board[t] for t in near]).astype(np.float64)
    dst = np.concatenate([found[t] for t in near]).astype(np.float64)
    hom, _ = cv2.findHomography(src, dst, 0)
    if hom is None:
        return None
    return cv2.perspectiveTransform(board[tag].reshape(-1, 1, 2), hom).reshape(4, 2)


def _inside(corners: np.ndarray, w: int, h: int, margin: float) -> bool:
    return bool(np.all(corners >= margin + 1) and np.all(corners[:, 0] < w - margin - 1)
                and np.all(corners[:, 1] < h - margin - 1))


def _expected_codes(dictionary: cv2.aruco.Dictionary, n_tags: int) -> np.ndarray:
    """Each tag's 6 x 6 code bits in all eight turns and mirrorings (n_tags x 8 x 6 x 6)."""
    return _codes(dictionary.bytesList[:n_tags].tobytes(), n_tags, dictionary.markerSize)


@functools.lru_cache(maxsize=8)
def _codes(byte_list: bytes, n_tags: int, size: int) -> np.ndarray:
    table = np.frombuffer(byte_list, np.uint8).reshape(n_tags, -1, 4)
    out = np.zeros((n_tags, 8, size, size), bool)
    for tag in range(n_tags):
        bits = cv2.aruco.Dictionary.getBitsFromByteList(table[tag:tag + 1], size).astype(bool)
        turns = [np.rot90(bits, k) for k in range(4)]
        out[tag] = turns + [t[::-1] for t in turns]
    return out


def _board_turn(gray: np.ndarray, board: np.ndarray, found: dict[int, np.ndarray],
                codes: np.ndarray) -> int | None:
    """Which of the eight turns and mirrorings of the codes the found tags show, read as
    :func:`_read_bits` reads them (the most common; None when none reads clearly)."""
    votes = np.zeros(codes.shape[1], int)
    for tag, corners in list(found.items())[:8]:
        bits = _read_bits(gray, board[tag], corners)
        if bits is None:
            continue
        errors = np.sum(bits != codes[tag], axis=(1, 2))
        if errors.min() <= MAX_BIT_ERRORS:
            votes[int(np.argmin(errors))] += 1
    return int(np.argmax(votes)) if votes.any() else None


def _read_bits(gray: np.ndarray, board_corners: np.ndarray, corners: np.ndarray
               ) -> np.ndarray | None:
    """The 6 x 6 code bits of the tag whose board corners lie at image ``corners`` (rows
    along the board's y), or None where no black-bordered tag shows."""
    hom = cv2.getPerspectiveTransform(board_corners.astype(np.float32),
                                      corners.astype(np.float32))
    n = CELLS * SAMPLES_PER_CELL
    steps = (np.arange(n) + 0.5) / n
    # board_corners run (x, y), (x+s, y), (x+s, y+s), (x, y+s)
    x0, y0 = board_corners[0]
    side = board_corners[1, 0] - board_corners[0, 0]
    gx, gy = np.meshgrid(x0 + steps * side, y0 + steps * side)
    grid = np.stack([gx, gy], axis=-1).reshape(-1, 1, 2)
    pix = cv2.perspectiveTransform(grid, hom).reshape(n, n, 2).astype(np.float32)
    samples = cv2.remap(gray, pix[..., 0], pix[..., 1], cv2.INTER_LINEAR)
    cells = samples.astype(np.float64).reshape(CELLS, SAMPLES_PER_CELL, CELLS,
                                               SAMPLES_PER_CELL).mean(axis=(1, 3))
    ring = np.ones((CELLS, CELLS), bool)
    ring[BORDER:-BORDER, BORDER:-BORDER] = False
    inner = cells[BORDER:-BORDER, BORDER:-BORDER]
    dark, light = float(cells[ring].mean()), float(inner.max())
    if light - dark < MIN_CONTRAST:
        return None  # no contrast: no tag here
    threshold = (dark + light) / 2.0
    if np.mean(cells[ring] < threshold) < 0.9:
        return None  # no black border around it
    return inner > threshold
