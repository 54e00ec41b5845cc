"""Fixtures: small seeded recordings and session files with reviewed frame sets."""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path

import pytest
from export_sessions import PATTERN, write_session

#: a short two-camera recording; one per (format, encoding), made once per test run
SMALL = dict(cameras=2, fisheye=0, duration=20.0, width=160, height=120, seed=5, claps=1)


@pytest.fixture(scope="session")
def small_recording(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., tuple[Path, dict]]:
    """Factory ``(format, encoding) -> (folder, truth)`` of small synthetic recordings."""
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    made: dict[tuple[str, str], tuple[Path, dict]] = {}

    def make(fmt: str = "ros1", encoding: str = "jpeg") -> tuple[Path, dict]:
        if (fmt, encoding) not in made:
            out = tmp_path_factory.mktemp(f"rec-{fmt}-{encoding}") / "session"
            generate_session(out, SynthOptions(**SMALL, format=fmt, encoding=encoding))
            made[fmt, encoding] = (out, json.loads((out / "truth.json").read_text()))
        return made[fmt, encoding]

    return make


@pytest.fixture
def session_file(small_recording, tmp_path: Path) -> Callable[..., Path]:
    """Factory ``(format, encoding, decisions) -> SESSION.json`` under tmp_path."""
    counter = iter(range(100))

    def make(fmt: str = "ros1", encoding: str = "jpeg",
             decisions: Sequence[str] = PATTERN) -> Path:
        folder, truth = small_recording(fmt, encoding)
        return write_session(folder, truth, tmp_path / f"s{next(counter)}" / "session.json",
                             decisions)

    return make

