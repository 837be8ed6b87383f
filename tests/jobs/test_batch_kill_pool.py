"""``kill_pool``: a batch's pool stopped at once leaves no thread of its own running.

CPython's ``ProcessPoolExecutor.shutdown`` forgets its manager thread (``shutdown`` sets
``_executor_manager_thread`` to ``None``, Lib/concurrent/futures/process.py), so that
thread must be taken before it: a manager still closing the pool's wake-up pipe when the
interpreter exits lets CPython's exit hook write to the closed pipe and print a traceback
(what a batch stopped by Ctrl-C under load printed).
"""

from __future__ import annotations

import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor

import pytest

from camtool.jobs import batch_stop
from camtool.jobs.batch_stop import kill_pool


def test_the_pools_own_thread_has_ended_when_kill_pool_returns(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(batch_stop, "KILL_WAIT_S", 600.0)  # as long as it takes, under load
    pool = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork"))
    futures = [pool.submit(time.sleep, 30) for _ in range(4)]
    while not all(f.running() for f in futures[:2]):
        time.sleep(0.01)
    manager = pool._executor_manager_thread
    assert manager is not None and manager.is_alive()
    kill_pool(pool)
    assert not manager.is_alive()
    assert all(f.done() for f in futures)
