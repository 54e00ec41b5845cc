"""Calibration target description (Kalibr target yaml) and its 3-D corner layout."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from speechcal_core.errors import SpeechCalError


class TargetError(SpeechCalError):
    """A target file that cannot be read or describes no usable target."""


#: a tag or square larger than this (metres) is a unit slip (millimetres given)
MAX_SIZE_M = 1.0
#: an AprilGrid's tags are the 36h11 codes 0, 1, ...: the family has no more
MAX_APRILGRID_TAGS = 587
#: inner corners of a checkerboard beyond any printed one (a slip of the keyboard)
MAX_CHECKERBOARD_CORNERS = 10_000


@dataclass(frozen=True)
class TargetSpec:
    """A planar calibration target in Kalibr's terms.

    ``aprilgrid``: ``rows`` x ``cols`` tags of edge ``size`` metres, gap ``spacing`` as a
    fraction of ``size`` (Kalibr ``tagSpacing``), family 36h11 with 2-bit black border.
    ``checkerboard``: ``rows`` x ``cols`` inner corners, squares ``size`` metres.
    """

    kind: str = "aprilgrid"
    rows: int = 6
    cols: int = 6
    size: float = 0.055
    spacing: float = 0.3

    def __post_init__(self) -> None:
        if self.kind not in ("aprilgrid", "checkerboard"):
            raise TargetError(f"unknown target type {self.kind!r}; use aprilgrid or checkerboard")
        if self.rows < 2 or self.cols < 2 or not 0 < self.size < math.inf:  # nan too
            raise TargetError("a target needs at least 2x2 tags or corners and a positive size")
        # before laying out its corners, which would run out of memory
        n = self.rows * self.cols
        if self.kind == "aprilgrid" and n > MAX_APRILGRID_TAGS:
            raise TargetError(f"a {self.cols}x{self.rows} AprilGrid has {n} tags, more than "
                              f"the {MAX_APRILGRID_TAGS} codes of the 36h11 family; check "
                              "tagRows and tagCols")
        if self.kind == "checkerboard" and n > MAX_CHECKERBOARD_CORNERS:
            raise TargetError(f"a {self.cols}x{self.rows} checkerboard has {n} inner corners, "
                              "more than any printed board; check targetRows and targetCols")
        if not 0 <= self.spacing < math.inf:
            raise TargetError(f"a tag spacing of {self.spacing} makes no board; Kalibr's "
                              "tagSpacing is the gap as a share of the tag size, e.g. 0.3")

    def describe(self) -> str:
        """The board in words: "6x6 AprilGrid of 0.055 m tags", "8x6 checkerboard of
        0.045 m squares" (columns first, as Kalibr's yaml lists them)."""
        if self.kind == "aprilgrid":
            return f"{self.cols}x{self.rows} AprilGrid of {self.size:g} m tags"
        return f"{self.cols}x{self.rows} checkerboard of {self.size:g} m squares"

    @property
    def pitch(self) -> float:
        """Distance in metres between neighbouring tags (aprilgrid) or corners."""
        return self.size * (1.0 + self.spacing) if self.kind == "aprilgrid" else self.size

    @property
    def extent(self) -> tuple[float, float]:
        """Width and height in metres of the printed pattern (x along cols, y along rows)."""
        if self.kind == "aprilgrid":
            return (self.cols * self.size + (self.cols - 1) * self.size * self.spacing,
                    self.rows * self.size + (self.rows - 1) * self.size * self.spacing)
        return ((self.cols + 1) * self.size, (self.rows + 1) * self.size)

    def object_points(self) -> np.ndarray:
        """Corner positions (N x 3, z = 0), one row per corner id.

        AprilGrid: id ``4 * i + k`` is corner ``k`` of tag ``i``, tags row-major from the
        origin as Kalibr lays the board out (its own point numbering differs: row by row
        over all corners), corners counter-clockwise from the lower left: ``(x, y),
        (x+s, y), (x+s, y+s), (x, y+s)``.
        Checkerboard: inner corners row-major, origin at the first inner corner.
        """
        if self.kind == "aprilgrid":
            pts = []
            s, p = self.size, self.pitch
            for r in range(self.rows):
                for c in range(self.cols):
                    x, y = c * p, r * p
                    pts += [(x, y, 0.0), (x + s, y, 0.0), (x + s, y + s, 0.0), (x, y + s, 0.0)]
            return np.asarray(pts, dtype=np.float64)
        ys, xs = np.mgrid[0 : self.rows, 0 : self.cols]
        grid = np.stack([xs.ravel() * self.size, ys.ravel() * self.size, np.zeros(xs.size)], 1)
        return grid.astype(np.float64)

    def to_kalibr_yaml(self) -> str:
        """The Kalibr ``target.yaml`` text (floats written as floats)."""
        if self.kind == "aprilgrid":
            return (
                "target_type: 'aprilgrid'\n"
                f"tagCols: {self.cols}\ntagRows: {self.rows}\n"
                f"tagSize: {float(self.size)!r}\ntagSpacing: {float(self.spacing)!r}\n"
            )
        return (
            "target_type: 'checkerboard'\n"
            f"targetCols: {self.cols}\ntargetRows: {self.rows}\n"
            f"rowSpacingMeters: {float(self.size)!r}\ncolSpacingMeters: {float(self.size)!r}\n"
        )

    @classmethod
    def from_session(cls, extra: dict) -> tuple[TargetSpec | None, bool | None]:
        """The board a session's frames were checked against (its ``extra``'s
        ``"target"``) and whether ``process`` assumed it for want of ``--target``: True,
        False, or None when the session does not say (made before it did) and the board
        is the one assumed."""
        stored = cls.from_stored(extra.get("target"))
        assumed = extra.get("target_assumed")
        if stored is None:
            return None, None
        if isinstance(assumed, bool):
            return stored, assumed
        return stored, None if stored == cls() else False

    @classmethod
    def from_stored(cls, data: object) -> TargetSpec | None:
        """The target a session file keeps under ``"target"`` (the fields as a dict);
        None when there is none or it does not describe a usable target."""
        if not isinstance(data, dict):
            return None
        try:
            return cls(**data)
        except (TypeError, ValueError, TargetError):
            return None

    @classmethod
    def from_kalibr_yaml(cls, path: str | Path) -> TargetSpec:
        """Read a Kalibr target yaml (flat ``key: value`` lines)."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8-sig")  # an editor's BOM is fine
        except OSError as exc:
            raise TargetError(f"{path}: cannot read target file ({exc.strerror}); give the "
                              "path of the board's Kalibr target yaml") from exc
        except UnicodeDecodeError:
            raise TargetError(f"{path}: not a text file in UTF-8; give a Kalibr target yaml "
                              "(target_type: aprilgrid, tagRows, ...) saved as UTF-8") from None
        values: dict[str, str] = {}
        for line in text.splitlines():
            line = line.split("#", 1)[0].strip()
            if line.startswith("{") or line.endswith("}"):  # YAML's flow style, as JSON too
                entries = line.strip("{}").split(",")
            else:
                entries = [line.removesuffix(",")]  # a line of JSON written over lines
            for entry in entries:
                if ":" in entry:
                    key, value = (part.strip().strip("'\"") for part in entry.split(":", 1))
                    if values.get(key, value) != value:  # Kalibr would take the last, silently
                        raise TargetError(
                            f"{path}: {key} is given twice ({values[key]} and {value}); keep "
                            "the one line that matches the printed board")
                    values[key] = value
        kind = values.get("target_type", "")
        if not kind:
            raise TargetError(
                f"{path}: no 'target_type: aprilgrid' (or checkerboard) line; give a Kalibr "
                "target yaml: target_type, then tagRows, tagCols, tagSize, tagSpacing (or "
                "targetRows, targetCols, rowSpacingMeters, colSpacingMeters)")

        def whole(key: str) -> int:
            try:
                return int(values[key])
            except ValueError:
                raise ValueError(f"{key} is {values[key]!r}, not a whole number") from None

        def number(key: str) -> float:
            try:
                return float(values[key])
            except ValueError:
                raise ValueError(f"{key} is {values[key]!r}, not a number") from None

        size_keys = {"aprilgrid": ["tagSize"],
                     "checkerboard": ["rowSpacingMeters", "colSpacingMeters"]}.get(kind, [])
        try:
            for key in (k for k in size_keys if k in values):
                if (size := number(key)) > MAX_SIZE_M:
                    raise TargetError(
                        f"{path}: {key} {values[key]} m is larger than any board; Kalibr "
                        f"takes metres ({size:g} mm is {size / 1000:g})")
            if kind == "aprilgrid":
                return cls("aprilgrid", whole("tagRows"), whole("tagCols"), number("tagSize"),
                           number("tagSpacing"))
            if kind == "checkerboard":
                _same_spacing(path, values, number)
                return cls("checkerboard", whole("targetRows"), whole("targetCols"),
                           number("rowSpacingMeters"))
        except KeyError as exc:
            needed = {"aprilgrid": "tagRows, tagCols, tagSize, tagSpacing",
                      "checkerboard": "targetRows, targetCols, rowSpacingMeters, "
                                      "colSpacingMeters"}[kind]
            raise TargetError(f"{path}: no '{exc.args[0]}: value' line; a Kalibr {kind} "
                              f"target yaml has target_type and {needed}, one "
                              "'key: value' per line") from exc
        except ValueError as exc:
            raise TargetError(f"{path}: {exc} in this target file") from exc
        except TargetError as exc:
            text = str(exc)
            raise TargetError(text if text.startswith(f"{path}: ") else f"{path}: {text}") \
                from None
        raise TargetError(
            f"{path}: target_type must be 'aprilgrid' or 'checkerboard', found {kind!r}"
        )


def _same_spacing(path: Path, values: dict[str, str], number: Callable[[str], float]) -> None:
    """Refuse a checkerboard whose squares are not square: every step from the corners
    to the calibration assumes one square size, and a silent choice of one of the two
    would scale the calibration along the other axis."""
    if "colSpacingMeters" not in values:
        return
    row, col = number("rowSpacingMeters"), number("colSpacingMeters")
    if not math.isclose(row, col, rel_tol=1e-6):
        raise TargetError(
            f"{path}: rowSpacingMeters {values['rowSpacingMeters']} and colSpacingMeters "
            f"{values['colSpacingMeters']} differ; SpeechCal takes square checkerboard "
            "squares only: measure the board again and give both the same size")
