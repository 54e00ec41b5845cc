"""Shared fixtures: one tiny synthetic session per test run, and a review session over it."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

TINY = dict(cameras=3, fisheye=1, duration=14.0, width=256, height=192, seed=21, claps=1)


@pytest.fixture(scope="session")
def tiny_synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 14 s, 3-camera synthetic session (folder, truth) made once per test run."""
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    out = tmp_path_factory.mktemp("tiny") / "session"
    generate_session(out, SynthOptions(**TINY))
    return out, json.loads((out / "truth.json").read_text())


@pytest.fixture
def truth_session_file(tiny_synth: tuple[Path, dict], tmp_path: Path) -> Path:
    """A session file whose sets come from the truth's triggers (for review tests)."""
    from speechcal_core.frames.nearest import nearest_frame_sets
    from speechcal_core.session.model import Session, Trigger
    from speechcal_core.session.store import save_session
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.model import SyncModel

    folder, truth = tiny_synth
    recording = str(folder / truth["recording"])
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")
    triggers = [Trigger(t["word"], t["start_s"], t["end_s"], 1.0, "truth")
                for t in truth["triggers"]]
    with open_recording([recording]) as source:
        sets = nearest_frame_sets(source, sync, triggers)
    session = Session([recording], str(folder / truth["audio"]), sync, sets)
    session.sync_evidence = {"claps": truth["claps"]}
    path = tmp_path / "review.json"
    save_session(session, path)
    return path
