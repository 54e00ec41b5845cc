"""Synthetic sessions for the sync tests, made once per test run by ``speechcal synth``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

_MADE: dict[tuple, Path] = {}


def make_session(root: Path, *, seed: int, snr: float = 20.0, claps: int = 1,
                 duration: float = 8.0, drift_ppm: float = 40.0,
                 encoding: str = "jpeg") -> tuple[Path, dict]:
    """A small 2-camera 320x240 session (a separate process: the renderer forks workers)."""
    key = (seed, snr, claps, duration, drift_ppm, encoding)
    if key not in _MADE:
        name = f"s{seed}_{snr:g}_{claps}_{duration:g}"
        out = root / (name if encoding == "jpeg" else f"{name}_{encoding}")
        cmd = [sys.executable, "-m", "speechcal_core.cli", "synth", str(out), "--cameras", "2",
               "--duration", str(duration), "--size", "320x240", "--claps", str(claps),
               "--seed", str(seed), "--snr", str(snr), "--drift-ppm", str(drift_ppm),
               "--encoding", encoding]
        subprocess.run(cmd, check=True, capture_output=True, timeout=300)
        _MADE[key] = out
    out = _MADE[key]
    return out, json.loads((out / "truth.json").read_text())


@pytest.fixture(scope="session")
def session_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Folder holding the sessions of this test run."""
    return tmp_path_factory.mktemp("sync_sessions")
