"""Kalibr target yaml files: read as Kalibr writes them, bad ones named with the fix."""

from __future__ import annotations

from pathlib import Path

import pytest

from speechcal_core.errors import SpeechCalError
from speechcal_core.target import TargetSpec

APRILGRID = """target_type: 'aprilgrid' # grid of AprilTags
tagCols: 6
tagRows: 7
tagSize: 0.088  # metres
tagSpacing: 0.3
"""
CHECKERBOARD = """target_type: 'checkerboard'
targetCols: 8
targetRows: 6
rowSpacingMeters: 0.045
colSpacingMeters: 0.045
"""


@pytest.mark.parametrize("bom", [b"", b"\xef\xbb\xbf"])  # Notepad's byte-order mark
def test_an_aprilgrid_file_as_kalibr_documents_it(tmp_path: Path, bom: bytes) -> None:
    path = tmp_path / "april.yaml"
    path.write_bytes(bom + APRILGRID.encode())
    spec = TargetSpec.from_kalibr_yaml(path)
    assert (spec.kind, spec.rows, spec.cols) == ("aprilgrid", 7, 6)
    assert spec.size == pytest.approx(0.088) and spec.spacing == pytest.approx(0.3)


def test_a_line_given_twice_alike_is_read(tmp_path: Path) -> None:
    path = tmp_path / "target.yaml"
    path.write_text(APRILGRID + "tagSize: '0.088'\n")
    assert TargetSpec.from_kalibr_yaml(path).size == 0.088


def test_the_one_line_flow_style_of_yaml_is_read_too(tmp_path: Path) -> None:
    path = tmp_path / "flow.yaml"
    path.write_text("{target_type: aprilgrid, tagCols: 6, tagRows: 7, tagSize: 0.088, "
                    "tagSpacing: 0.3}\n")
    assert TargetSpec.from_kalibr_yaml(path) == TargetSpec("aprilgrid", 7, 6, 0.088, 0.3)


@pytest.mark.parametrize("text", [
    '{"target_type": "aprilgrid", "tagCols": 6, "tagRows": 7, "tagSize": 0.088, '
    '"tagSpacing": 0.3}\n',
    '{\n  "target_type": "aprilgrid",\n  "tagCols": 6,\n  "tagRows": 7,\n'
    '  "tagSize": 0.088,\n  "tagSpacing": 0.3\n}\n',
])
def test_a_target_written_as_json_is_read(tmp_path: Path, text: str) -> None:
    """JSON is YAML too (Kalibr reads it): its quoted keys were not found, and the file
    was said to have no target_type line."""
    path = tmp_path / "target.yaml"
    path.write_text(text)
    assert TargetSpec.from_kalibr_yaml(path) == TargetSpec("aprilgrid", 7, 6, 0.088, 0.3)


@pytest.mark.parametrize("content", [
    CHECKERBOARD,
    CHECKERBOARD.replace("colSpacingMeters: 0.045\n", ""),  # one size for both axes
])
def test_a_checkerboard_file_as_kalibr_documents_it(tmp_path: Path, content: str) -> None:
    path = tmp_path / "board.yaml"
    path.write_text(content)
    assert TargetSpec.from_kalibr_yaml(path) == TargetSpec("checkerboard", 6, 8, 0.045)


def test_a_target_file_that_is_not_there_says_what_to_give(tmp_path: Path) -> None:
    """A typo in --target, or a folder given: the reason alone named no way on."""
    for path, why in ((tmp_path / "aprilgird.yaml", "No such file or directory"),
                      (tmp_path, "Is a directory")):
        with pytest.raises(SpeechCalError) as exc:
            TargetSpec.from_kalibr_yaml(path)
        assert str(exc.value) == (f"{path}: cannot read target file ({why}); give the path "
                                  "of the board's Kalibr target yaml")


@pytest.mark.parametrize(("content", "says"), [
    (APRILGRID.replace("tagSize: 0.088  # metres\n", ""),
     "no 'tagSize: value' line; a Kalibr aprilgrid target yaml has target_type and tagRows"),
    (APRILGRID.replace("0.088", "0,088"), "tagSize is '0,088', not a number in this "),
    (APRILGRID.replace("tagRows: 7", "tagRows: six"), "tagRows is 'six', not a whole number"),
    (APRILGRID.replace("0.088", "nan"), "a positive size"),
    (APRILGRID.replace("tagSpacing: 0.3", "tagSpacing: -1"), "a tag spacing of -1.0 makes no"),
    ("", "no 'target_type: aprilgrid' (or checkerboard) line; give a Kalibr target yaml"),
    (APRILGRID.replace("0.088", "88"), "tagSize 88 m is larger than any board; Kalibr takes "
     "metres (88 mm is 0.088)"),
    (APRILGRID.replace("0.088", "55"), "(55 mm is 0.055)"),
    (CHECKERBOARD.replace("colSpacingMeters: 0.045", "colSpacingMeters: 0.030"),
     "rowSpacingMeters 0.045 and colSpacingMeters 0.030 differ; SpeechCal takes square "
     "checkerboard squares only"),
    (CHECKERBOARD.replace("colSpacingMeters: 0.045", "colSpacingMeters: 45"),
     "colSpacingMeters 45 m is larger than any board"),
    (APRILGRID.replace("tagRows: 7", "tagRows: 1"), "at least 2x2 tags"),
    # a slip of the keyboard: no board has the tags (36h11 has 587 codes), and laying out
    # its corners ran out of memory with a traceback
    (APRILGRID.replace("tagRows: 7", "tagRows: 100000").replace("tagCols: 6", "tagCols: 100000"),
     "a 100000x100000 AprilGrid has 10000000000 tags, more than the 587 codes of the 36h11 "
     "family; check tagRows and tagCols"),
    (APRILGRID.replace("tagRows: 7", "tagRows: 25").replace("tagCols: 6", "tagCols: 24"),
     "more than the 587 codes"),
    (CHECKERBOARD.replace("targetRows: 6", "targetRows: 600000"),
     "a 8x600000 checkerboard has 4800000 inner corners, more than any printed board; "
     "check targetRows and targetCols"),
    ("# Gitter für die Kalibrierung\n".encode("latin-1") + APRILGRID.encode(),
     "not a text file in UTF-8"),
    # an edit that left the old line in: Kalibr would take the last value without a word
    (APRILGRID + "tagSize: 0.055\n", "tagSize is given twice (0.088 and 0.055); keep the "
     "one line that matches the printed board"),
])
def test_a_bad_target_file_is_named_with_what_is_wrong(tmp_path: Path, content,
                                                        says: str) -> None:
    path = tmp_path / "target.yaml"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    with pytest.raises(SpeechCalError) as exc:
        TargetSpec.from_kalibr_yaml(path)
    assert str(exc.value).startswith(f"{path}: ") and says in str(exc.value)
    assert "\n" not in str(exc.value)
