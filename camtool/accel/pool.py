"""Tasks on forked worker processes, results in order: the process pool of the accel layer.

A stage hands :func:`map_forked` a pure function and its tasks; the function must give the
same answer in a worker as in this process (what it returns is pickled back bit for bit).
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any, TypeVar

from camtool.accel import enabled
from camtool.accel.cores import in_worker

Task = TypeVar("Task")
Result = TypeVar("Result")


def map_forked(
    function: Callable[[Task], Result],
    tasks: Sequence[Task],
    workers: int,
    done: Callable[[Result], None] | None = None,
) -> list[Result] | None:
    """``[function(t) for t in tasks]`` on ``workers`` forked processes, in order.

    ``done`` is called here with each result as it comes back. ``None`` when no pool
    runs them: ``CAMTOOL_ACCEL=0``, fewer than 2 workers, this process is itself a worker
    (``camtool batch``, Dask), no ``fork`` on this platform, a pool that cannot start, or
    a worker that died; the caller then runs the tasks itself.
    """
    if workers < 2 or not enabled() or in_worker():
        return None
    try:
        context = multiprocessing.get_context("fork")
    except ValueError:  # pragma: no cover - no fork on this platform
        return None
    try:
        with ProcessPoolExecutor(workers, mp_context=context) as pool:
            results: list[Result] = []
            for result in pool.map(function, tasks):
                results.append(result)
                if done is not None:
                    done(result)
            return results
    except (OSError, RuntimeError, EOFError, AssertionError):  # cannot fork, a worker died
        return None


def each_threaded(function: Callable[[Task], object], tasks: Sequence[Task]) -> None:
    """``function(t)`` for every task, on a thread per core, for work that releases the GIL.

    In order, in this thread, with ``CAMTOOL_ACCEL=0`` or on one core; the first error
    raised by a task is raised here either way.
    """
    import os

    threads = min(len(tasks), os.cpu_count() or 1)
    if threads <= 1 or not enabled():
        for task in tasks:
            function(task)
        return
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=threads) as pool:
        list(pool.map(function, tasks))


def parts_threaded(fill: Callable[[slice], Any], size: int, part: int, dtype: Any = object) -> Any:
    """``fill(slice(0, size))``: a ``(size,)`` array, ``part`` rows at a time on every core.

    ``fill`` gives the rows of the slice it is given, each row a function of that row's
    input alone, in work that releases the GIL (a vectorised shapely function: GEOS's
    answer for one geometry is the same whichever thread computes it), so the array is
    the one a single call gives. In order, in this thread, with ``CAMTOOL_ACCEL=0``, on
    one core, or for one part (:func:`each_threaded`).
    """
    import numpy as np

    out = np.empty(size, dtype=dtype)

    def one(lo: int) -> None:
        at = slice(lo, min(size, lo + part))
        out[at] = fill(at)

    each_threaded(one, range(0, size, part))
    return out
