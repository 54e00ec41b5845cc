"""Shared fixtures: one tiny synthetic session per test run, and a review session over it."""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

TINY = dict(cameras=3, fisheye=1, duration=14.0, width=256, height=192, seed=21, claps=1)
SNAPSHOT = dict(cameras=1, duration=14.0, width=160, height=120, seed=21, claps=1,
                trigger_word="snapshot")
#: one pinhole camera filming a checkerboard (its target.yaml beside the recording)
CHECKERBOARD = dict(cameras=1, fisheye=0, duration=14.0, width=256, height=192, seed=21,
                    claps=1, target_kind="checkerboard")
#: noisy speech (5 dB SNR), 12 triggers in four voices, five of them in the voice "rms"
NOISY = dict(cameras=1, duration=40.0, width=160, height=120, seed=3, snr_db=5.0, claps=1)


@pytest.fixture(scope="session")
def tiny_synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 14 s, 3-camera synthetic session (folder, truth) made once per test run."""
    return _synth(tmp_path_factory, "tiny", TINY)


def _synth(factory: pytest.TempPathFactory, name: str, options: dict) -> tuple[Path, dict]:
    """A synthetic session made with ``options`` in a fresh folder: (folder, truth)."""
    from speechcal_core.synth.options import SynthOptions
    from speechcal_core.synth.session import generate_session

    out = factory.mktemp(name) / "session"
    generate_session(out, SynthOptions(**options))
    return out, json.loads((out / "truth.json").read_text())


@pytest.fixture(scope="session")
def processed_tiny(tiny_synth: tuple[Path, dict], tmp_path_factory: pytest.TempPathFactory
                   ) -> Callable[[str | None], Path]:
    """Factory ``where -> folder``: a folder holding ``rec/`` (the tiny session's recording
    and audio) and the session the review's ``load_for_review`` made of them at ``where``
    (a path relative to the folder; None: beside the recording, where the review keeps
    it), made once per test run for each ``where``. Read only: a test copies the folder
    (``shutil.copytree(folder, tmp_path, dirs_exist_ok=True)``) to open or change it."""
    from speechcal_core.review.loading import load_for_review

    made: dict[str | None, Path] = {}
    source, truth = tiny_synth

    def make(where: str | None = None) -> Path:
        if where not in made:
            folder = tmp_path_factory.mktemp("processed")
            shutil.copytree(source, folder / "rec")
            session_path = None if where is None else folder / where
            if session_path is not None:
                session_path.parent.mkdir(parents=True, exist_ok=True)
            load_for_review(recording=[str(folder / "rec" / truth["recording"])],
                            audio=str(folder / "rec" / truth["audio"]),
                            new_session_path=session_path).close()
            made[where] = folder
        return made[where]

    return make


@pytest.fixture
def truth_session_file(tiny_synth: tuple[Path, dict], tmp_path: Path) -> Path:
    """A session file whose sets come from the truth's triggers (for review tests)."""
    from truth_sessions import truth_session

    from speechcal_core.session.store import save_session

    folder, truth = tiny_synth
    session = truth_session(folder, truth)
    session.sync_evidence = {"claps": truth["claps"]}
    path = tmp_path / "review.json"
    save_session(session, path)
    return path


@pytest.fixture(scope="session")
def _searched_session(tiny_synth: tuple[Path, dict]):
    """The tiny session as ``speechcal process`` makes it (true triggers and sync)."""
    from truth_sessions import searched_session

    return searched_session(*tiny_synth)


@pytest.fixture
def searched_session_file(_searched_session, tmp_path: Path) -> Path:
    """A session file with best still frames, their figures, details and references."""
    from speechcal_core.session.store import save_session

    path = tmp_path / "searched.json"
    save_session(_searched_session, path)
    return path


@pytest.fixture(scope="session")
def snapshot_synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 14 s, 1-camera synthetic session whose operator says "snapshot" (folder, truth)."""
    return _synth(tmp_path_factory, "snapshot", SNAPSHOT)


@pytest.fixture(scope="session")
def _capture_session_of_snapshots(snapshot_synth: tuple[Path, dict]):
    """The "snapshot" session processed as if its word were the default "capture"."""
    from speechcal_core.pipeline import process_recording

    folder, truth = snapshot_synth
    return process_recording([str(folder / truth["recording"])], str(folder / truth["audio"]))


@pytest.fixture
def wrong_word_session_file(_capture_session_of_snapshots, tmp_path: Path) -> Path:
    """A session file over the "snapshot" session detected with "capture": no sets."""
    import copy

    from speechcal_core.session.store import save_session

    path = tmp_path / "wrong-word.json"
    save_session(copy.deepcopy(_capture_session_of_snapshots), path)
    return path


@pytest.fixture(scope="session")
def checkerboard_synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 14 s, 1-camera synthetic session filming a checkerboard (folder, truth)."""
    return _synth(tmp_path_factory, "checkerboard", CHECKERBOARD)


@pytest.fixture(scope="session")
def noisy_synth(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A 40 s, 1-camera synthetic session at 5 dB SNR (folder, truth), made once per run."""
    return _synth(tmp_path_factory, "noisy", NOISY)


@pytest.fixture
def missed_voice_file(noisy_synth: tuple[Path, dict], tmp_path: Path) -> tuple[Path, list]:
    """A session file over the noisy session with sets for every true trigger but those
    of its most frequent voice (as when the recogniser never recognised that voice),
    and those missed triggers (truth entries, in time order)."""
    from collections import Counter

    from truth_sessions import truth_session

    from speechcal_core.session.store import save_session

    folder, truth = noisy_synth
    voice = Counter(t["voice"] for t in truth["triggers"]).most_common(1)[0][0]
    heard = [t for t in truth["triggers"] if t["voice"] != voice]
    session = truth_session(folder, {**truth, "triggers": heard})
    path = tmp_path / "missed.json"
    save_session(session, path)
    return path, [t for t in truth["triggers"] if t["voice"] == voice]
