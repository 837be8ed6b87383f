"""A batch on a Dask cluster: reach the scheduler (or start one here), run the files on it.

Dask distributed (``pip install 'camtool[cluster]'``) runs a batch's files on the
workers of a cluster — on other hosts (``dask scheduler`` on one, ``dask worker
tcp://HOST:8786`` on each, see docs/batch.md "On a cluster") or on this machine
(``local:N``: a ``LocalCluster`` of N worker processes, one thread each: posting is
CPU-bound Python). This module knows Dask and nothing of posting:
:func:`camtool.jobs.batch.run_batch` gives it the work function and its arguments.

What it relies on from Dask (https://distributed.dask.org):

- a task whose worker dies is run again on another worker by the scheduler, up
  to its ``distributed.scheduler.allowed-failures`` (3 by default) worker deaths;
  then its future raises ``KilledWorker``. A task that raises is also retried
  :data:`RETRIES` times (``Client.submit(retries=...)``);
- a future's result reaches the client once, however often its task ran.

Dask is imported only here and only when a batch runs on it, so camtool works
without it; ``--scheduler`` without it is refused before any work starts
(:func:`require_dask`).
"""

from __future__ import annotations

import contextlib
import importlib.util
import logging
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

from camtool.model.errors import CamtoolError, UsageError

if TYPE_CHECKING:
    from distributed import Client

INSTALL_HINT = "pip install 'camtool[cluster]'"
"""How to get Dask distributed, for messages."""
LOCAL = "local:"
"""``--scheduler local:N``: a cluster of N worker processes on this machine."""
RETRIES = 2
"""Extra runs of a task that raised on its worker (``Client.submit(retries=...)``)."""
CONNECT_TIMEOUT_S = 30.0
"""How long to wait for a scheduler's answer, s."""
WORKER_WAIT_S = 60.0
"""How long to wait for a first worker at a scheduler that has none, s."""
IN_FLIGHT_PER_THREAD = 2
"""Tasks submitted ahead per worker thread, so that inputs are read as the cluster needs them."""
MIN_IN_FLIGHT = 8
"""Tasks submitted ahead at least (a cluster may grow while the batch runs)."""


def check_scheduler(text: str) -> str:
    """``text`` when it is a ``--scheduler``: a scheduler address or ``local:N`` (N ≥ 1).

    An address is what ``dask scheduler`` prints, ``tcp://HOST:PORT`` (or another of
    Dask's protocols: ``tls://``, ``ucx://``...).

    Raises:
        UsageError: anything else, naming the two forms.
    """
    if text.startswith(LOCAL):
        count = text.removeprefix(LOCAL)
        if count.isdigit() and int(count) >= 1:
            return text
    elif "://" in text and text.split("://", 1)[1]:
        return text
    raise UsageError(
        f"--scheduler {text!r}: give a Dask scheduler's address (tcp://HOST:8786, as "
        "`dask scheduler` prints it) or local:N to start N workers on this machine"
    )


def require_dask() -> None:
    """Refuse a batch on Dask when Dask distributed is not installed (checked without importing it).

    Raises:
        UsageError: ``distributed`` is not importable; the message says how to install it.
    """
    if importlib.util.find_spec("distributed") is None:
        raise UsageError(
            f"--scheduler runs the batch on Dask, which is not installed: {INSTALL_HINT} "
            "(or leave --scheduler out to use this machine's processes)"
        )


def _distributed() -> Any:
    """The ``distributed`` module.

    Raises:
        UsageError: it is not installed (see :func:`require_dask`).
    """
    require_dask()
    import distributed

    return distributed


@contextlib.contextmanager
def connect(scheduler: str, *, most_workers: int | None = None) -> Iterator[Client]:
    """A client of the cluster ``scheduler`` names, closed (with a local cluster) at the end.

    ``local:N`` starts a ``LocalCluster`` of N worker processes (no more than
    ``most_workers``, e.g. the batch's file count, as ``--jobs`` does) with one thread each
    (its dashboard at http://localhost:8787/status when Bokeh is installed — Dask
    takes another port, and says so, when 8787 is taken —; without Bokeh its web
    server takes a free port, so that two batches never clash on 8787). An address
    connects to a running scheduler and waits up to :data:`WORKER_WAIT_S` for a
    first worker.

    Raises:
        UsageError: ``scheduler`` is malformed, or Dask is not installed.
        CamtoolError: the scheduler does not answer, or no worker joins it.
    """
    check_scheduler(scheduler)
    distributed = _distributed()
    if scheduler.startswith(LOCAL):
        dashboard = ":8787" if importlib.util.find_spec("bokeh") is not None else ":0"
        with (
            distributed.LocalCluster(
                n_workers=min(int(scheduler.removeprefix(LOCAL)), max(1, most_workers or 1 << 30)),
                threads_per_worker=1,
                processes=True,
                dashboard_address=dashboard,
                # a local cluster's own shutdown chatter (closed comms, heartbeats to a
                # scheduler already gone) is not the user's business; camtool reports
                # every task that failed itself
                silence_logs=logging.CRITICAL,
            ) as cluster,
            distributed.Client(cluster) as client,
        ):
            yield client
        return
    try:
        client = distributed.Client(scheduler, timeout=CONNECT_TIMEOUT_S)
    except (OSError, TimeoutError, ValueError) as exc:
        raise CamtoolError(
            f"--scheduler {scheduler}: no Dask scheduler answers there ({exc}); start one "
            f"with `dask scheduler` and workers with `dask worker {scheduler}`"
        ) from exc
    with client:
        try:
            client.wait_for_workers(1, timeout=WORKER_WAIT_S)
        except TimeoutError as exc:
            raise CamtoolError(
                f"--scheduler {scheduler}: no worker joined the scheduler within "
                f"{WORKER_WAIT_S:g} s; start one with `dask worker {scheduler}`"
            ) from exc
        yield client


def map_unordered(
    client: Client,
    work: Callable[..., Any],
    count: int,
    arguments: Callable[[int], tuple[Any, ...]],
) -> Iterator[tuple[int, Any, BaseException | None]]:
    """Run ``work(*arguments(i))`` for ``i`` in ``range(count)`` on ``client``'s cluster.

    Tasks are submitted a few ahead of the cluster (:data:`IN_FLIGHT_PER_THREAD` per
    worker thread, at least :data:`MIN_IN_FLIGHT`), so ``arguments(i)`` is called
    (an input read) only shortly before task ``i`` can run, and the client never
    holds the whole batch's inputs. Each task may be retried (:data:`RETRIES`, and
    the scheduler's own re-runs of a task whose worker died).

    Args:
        client: a ``dask.distributed.Client``.
        work: a module-level function (workers import it by name).
        count: how many tasks.
        arguments: the arguments of task ``i`` (sent to the cluster; picklable).

    Yields:
        ``(i, result, None)`` as each task finishes, in finishing order, or
        ``(i, None, error)`` for a task that failed on the cluster (e.g.
        ``KilledWorker``: its workers kept dying). Leaving the loop early cancels
        the tasks not yet finished.
    """
    distributed = _distributed()
    threads = sum(client.nthreads().values())
    ahead = max(MIN_IN_FLIGHT, IN_FLIGHT_PER_THREAD * threads)
    pending: dict[Any, int] = {}
    done = distributed.as_completed(with_results=True, raise_errors=False)  # fetched as they end
    submitted = 0

    def submit() -> None:
        nonlocal submitted
        future = client.submit(work, *arguments(submitted), retries=RETRIES, pure=False)
        pending[future] = submitted
        done.add(future)
        submitted += 1

    try:
        while submitted < min(ahead, count):
            submit()
        for future, result in done:
            index = pending.pop(future)
            failed = isinstance(result, BaseException)  # failed or cancelled on the cluster
            outcome = (index, None, result) if failed else (index, result, None)
            future.release()
            if submitted < count:
                submit()
            yield outcome
    finally:
        if pending:
            client.cancel(list(pending))
