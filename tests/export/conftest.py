"""Fixtures: small seeded recordings and session files with reviewed frame sets."""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import pytest

#: a short two-camera recording; one per (format, encoding), made once per test run
SMALL = dict(cameras=2, fisheye=0, duration=20.0, width=160, height=120, seed=5, claps=1)
#: decisions given to the sets in turn
PATTERN = ("accepted", "undecided", "accepted", "rejected")


def write_session(folder: Path, truth: dict, path: Path,
                  decisions: Sequence[str] = PATTERN) -> Path:
    """A session file over ``folder``'s recording: one set per true trigger, with
    ``decisions`` in turn and made-up quality figures on every chosen frame."""
    from speechcal_core.frames.nearest import nearest_frame_sets
    from speechcal_core.session.model import Session, Trigger
    from speechcal_core.session.store import save_session
    from speechcal_core.sources import open_recording
    from speechcal_core.sync.model import SyncModel

    recording = str(folder / truth["recording"])
    sync = SyncModel(truth["sync"]["offset_ns"], truth["sync"]["drift"], "auto")
    triggers = [Trigger(t["word"], t["start_s"], t["end_s"], 1.0, "truth")
                for t in truth["triggers"]]
    with open_recording([recording]) as source:
        sets = nearest_frame_sets(source, sync, triggers)
    sets = [
        replace(s, decision=decisions[k % len(decisions)], frames=tuple(
            replace(f, sharpness=round(100.0 + 10 * k + j + 0.25, 2), corners=140 + j,
                    flags=("blur",) if j == 1 else ())
            for j, f in enumerate(s.frames)))
        for k, s in enumerate(sets)
    ]
    session = Session([recording], str(folder / truth["audio"]), sync, sets)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_session(session, path)
    return path


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
