"""Decoding in worker processes: the same words as decoding here, whatever the number of
workers; stoppable; and a worker that dies costs time, not the result."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from speech_scenes import Scene

from speechcal_core.audio import load_audio
from speechcal_core.speech import TriggerSpec, decoding_workers, span_decoding
from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend

SPEC = TriggerSpec(("capture",))


@pytest.fixture(autouse=True)
def small_chunks(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ~12 s scene in several chunks, decoded by workers although it is short."""
    monkeypatch.setattr(span_decoding, "CHUNK_S", 2.0)
    monkeypatch.setattr(span_decoding, "MIN_PARALLEL_S", 0.0)


def test_workers_find_the_same_words_as_decoding_here(capture_scene: Scene) -> None:
    audio = load_audio(capture_scene.path)
    here = PocketsphinxBackend(workers=1)
    alone = here.words(audio, SPEC)
    assert here.last_worker_cpu_s == 0.0
    assert sum(w.word == "capture" for w in alone) == 4
    for workers in (2, 3):
        parallel = PocketsphinxBackend(workers=workers)
        assert parallel.words(audio, SPEC) == alone
        assert parallel.last_worker_cpu_s > 0.0


def test_stopping_while_workers_decode_stops_the_call(capture_scene: Scene) -> None:
    class Stop(Exception):
        pass

    reports: list[float] = []

    def stop_after_two(share: float) -> None:
        reports.append(share)
        if len(reports) == 2:
            raise Stop

    audio = load_audio(capture_scene.path)
    with pytest.raises(Stop):
        PocketsphinxBackend(workers=2, progress=stop_after_two).words(audio, SPEC)
    # the workers are still there for the next call
    assert sum(w.word == "capture"
               for w in PocketsphinxBackend(workers=2).words(audio, SPEC)) == 4


def test_a_worker_that_died_is_replaced_by_decoding_here(capture_scene: Scene) -> None:
    audio = load_audio(capture_scene.path)
    expected = PocketsphinxBackend(workers=1).words(audio, SPEC)
    PocketsphinxBackend(workers=2).words(audio, SPEC)  # the workers are up
    assert decoding_workers._pool is not None
    for pid in list(decoding_workers._pool._processes):  # as the out-of-memory killer would
        os.kill(pid, signal.SIGKILL)
    survivor = PocketsphinxBackend(workers=2)
    assert survivor.words(audio, SPEC) == expected
    assert survivor.last_worker_cpu_s == 0.0  # decoded here
    # and the next call starts new workers
    parallel = PocketsphinxBackend(workers=2)
    assert parallel.words(audio, SPEC) == expected
    assert parallel.last_worker_cpu_s > 0.0


def test_idle_workers_are_stopped(capture_scene: Scene, monkeypatch: pytest.MonkeyPatch
                                  ) -> None:
    monkeypatch.setattr(decoding_workers, "IDLE_S", 0.5)
    backend = PocketsphinxBackend(workers=2)
    backend.words(load_audio(capture_scene.path), SPEC)
    # workers decoded (their pool may already be gone: the idle time starts when the
    # decoding ends, and on a loaded machine the search after it can outlast 0.5 s)
    assert backend.last_worker_cpu_s > 0
    deadline = time.monotonic() + 30.0  # idle 0.5 s, then stopped (a busy machine: later)
    while decoding_workers._pool is not None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert decoding_workers._pool is None  # their memory is freed


UNGUARDED_SCRIPT = """
from speechcal_core.audio import load_audio
from speechcal_core.speech import TriggerSpec, span_decoding
from speechcal_core.speech.pocketsphinx_backend import PocketsphinxBackend

span_decoding.CHUNK_S, span_decoding.MIN_PARALLEL_S = 2.0, 0.0
backend = PocketsphinxBackend(workers=2)
for _ in range(2):
    words = backend.words(load_audio({path!r}), TriggerSpec(("capture",)))
    print(sum(w.word == "capture" for w in words), backend.last_worker_cpu_s)
"""


def test_a_script_without_the_main_guard_still_gets_its_words(
        capture_scene: Scene, tmp_path: Path) -> None:
    """Spawned workers import the script again; unguarded, they cannot start. It decodes in
    its own process instead, and does not try workers again."""
    script = tmp_path / "unguarded.py"
    script.write_text(UNGUARDED_SCRIPT.format(path=str(capture_scene.path)))
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         cwd=tmp_path, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["4", "0.0", "4", "0.0"]
    assert run.stderr.count("bootstrapping phase") <= 2  # one pool's workers, not two
