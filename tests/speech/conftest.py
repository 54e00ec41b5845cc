"""Fixtures of the speech tests: one small scene of voices saying "capture" among others."""

from __future__ import annotations

import pytest
from speech_scenes import Scene, make_scene


@pytest.fixture(scope="module")
def capture_scene(tmp_path_factory: pytest.TempPathFactory) -> Scene:
    """Three voices saying "capture", between near-homophones and chatter (~12 s)."""
    items = [
        ("capture", "slt/capture_1"), ("picture", "slt/picture_1"),
        ("capture", "rms/capture_2"), ("captured it", "rms/captured_it_1"),
        ("hold on", "awb/hold_on_1"), ("capture", "awb/capture_3"),
        ("captain", "kal16/captain_1"), ("capture", "kal16/capture_1"),
    ]
    return make_scene(tmp_path_factory.mktemp("speech") / "scene.wav", items)
