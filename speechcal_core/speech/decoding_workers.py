"""The worker processes that decode speech spans in parallel.

pocketsphinx holds Python's global interpreter lock while it decodes, so threads do not
help; processes do. The pool is kept between calls: each worker builds its decoder (about
a second with its grammars) once and reuses it for later chunks and recordings.

Spawned workers import the main module of the program, as Python's multiprocessing does:
a script calling the detector needs the ``if __name__ == "__main__":`` guard. Without it
the workers fail to start, and the detector decodes in the calling process instead (the
same result, slower; workers are not tried again in that process).
"""

from __future__ import annotations

import multiprocessing
import threading
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from contextlib import contextmanager

from speechcal_core.processes import exit_with_parent

#: workers idle this long are stopped (each holds about 200 MB)
IDLE_S = 120.0

_lock = threading.Lock()
_pool: ProcessPoolExecutor | None = None
_size = 0
_users = 0  # calls using the pool now
_idle_timer: threading.Timer | None = None
_served = False  # whether the pool's workers have returned a result
_unusable = False  # a pool broke before its workers returned anything: no more pools


def workers_usable() -> bool:
    """False once workers failed to start in this process (an unguarded script)."""
    return not _unusable


def pool_running(workers: int) -> bool:
    """Whether a pool of ``workers`` processes is up (its workers cost nothing to start)."""
    return _pool is not None and _size == workers


def note_served() -> None:
    """The pool's workers returned a result: they start, so a later breakdown (a worker
    killed) is no reason to stop using them."""
    global _served
    _served = True


@contextmanager
def decoding_pool(workers: int) -> Iterator[ProcessPoolExecutor]:
    """The shared pool of ``workers`` spawned processes while in the ``with`` block:
    started on first use (again for another size, unless another call uses it), stopped
    once idle for IDLE_S."""
    global _pool, _size, _users, _idle_timer
    with _lock:
        if _idle_timer is not None:
            _idle_timer.cancel()
            _idle_timer = None
        if _pool is None or (_size != workers and _users == 0):
            _shut_down()
            _pool = ProcessPoolExecutor(max_workers=workers,
                                        mp_context=multiprocessing.get_context("spawn"),
                                        initializer=exit_with_parent)
            _size = workers
        pool = _pool
        _users += 1
    try:
        yield pool
    finally:
        with _lock:
            _users -= 1
            if _users == 0 and _pool is pool:
                _idle_timer = threading.Timer(IDLE_S, _stop_if_idle, args=(pool,))
                _idle_timer.daemon = True
                _idle_timer.start()


def _stop_if_idle(pool: ProcessPoolExecutor) -> None:
    with _lock:
        if _pool is pool and _users == 0:
            _shut_down()


def discard_decoding_pool() -> None:
    """Stop the workers after one died (the pool is broken then; calls using it fail
    over to decoding in their own process). A pool whose workers never returned anything
    is not started again."""
    global _unusable
    with _lock:
        if _pool is not None and not _served:
            _unusable = True
        _shut_down()


def _shut_down() -> None:
    global _pool, _size, _served
    if _pool is not None:
        _pool.shutdown(wait=False, cancel_futures=True)
    _pool, _size, _served = None, 0, False
