"""Small synthetic recordings for the sync tests, each made once per test run by
``speechcal synth`` in a separate process.

A helper module of its own (not ``conftest``): every test folder has a ``conftest.py``,
so ``from conftest import ...`` finds whichever folder's conftest pytest imported last."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

_MADE: dict[tuple, Path] = {}


def make_session(root: Path, *, seed: int, snr: float = 20.0, claps: int = 1,
                 duration: float = 8.0, drift_ppm: float = 40.0,
                 encoding: str = "jpeg", cameras: int = 2,
                 size: str = "320x240") -> tuple[Path, dict]:
    """A small session, 2 cameras at 320x240 unless told (a separate process: the renderer
    forks workers)."""
    key = (seed, snr, claps, duration, drift_ppm, encoding, cameras, size)
    if key not in _MADE:
        name = f"s{seed}_{snr:g}_{claps}_{duration:g}"
        if (cameras, size) != (2, "320x240"):
            name += f"_n{cameras}_{size}"
        out = root / (name if encoding == "jpeg" else f"{name}_{encoding}")
        cmd = [sys.executable, "-m", "speechcal_core.cli", "synth", str(out), "--cameras",
               str(cameras), "--duration", str(duration), "--size", size, "--claps", str(claps),
               "--seed", str(seed), "--snr", str(snr), "--drift-ppm", str(drift_ppm),
               "--encoding", encoding]
        subprocess.run(cmd, check=True, capture_output=True, timeout=300)
        _MADE[key] = out
    out = _MADE[key]
    return out, json.loads((out / "truth.json").read_text())
