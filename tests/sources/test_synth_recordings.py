"""Sessions from ``speechcal synth`` read back with the counts and drops in truth.json."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from speechcal_core.cli import main
from speechcal_core.sources import open_recording


@pytest.mark.slow
@pytest.mark.parametrize(
    ("fmt", "extra"),
    [
        ("ros1", ["--encoding", "bayer_rggb8", "--compression", "lz4"]),
        ("ros2-mcap", ["--encoding", "jpeg"]),
    ],
)
def test_synth_session_streams_match_the_truth(
    tmp_path: Path, capsys, fmt: str, extra: list[str]
) -> None:
    out = tmp_path / "session"
    args = ["synth", str(out), "--cameras", "2", "--duration", "5", "--format", fmt]
    assert main([*args, "--size", "320x240", *extra]) == 0
    capsys.readouterr()
    truth = json.loads((out / "truth.json").read_text())
    with open_recording([out / truth["recording"]]) as src:
        info = {s.name: s for s in src.streams}
        assert set(info) == {c["name"] for c in truth["cameras"]}
        for cam in truth["cameras"]:
            s = info[cam["name"]]
            assert (s.width, s.height) == (cam["width"], cam["height"])
            assert s.count == cam["count"] and s.dropped == cam["dropped"]
            assert s.nominal_rate_hz == pytest.approx(cam["fps"], rel=0.02)
            assert s.bad_frames == () and s.stamp_problems == ""
            assert src.frame(s.name, s.count // 2).shape == (240, 320, 3)
