"""A batch on a Dask cluster: reach the scheduler (or start one here), run the files on it.

Design notes: docs/internals.md, ``camtool/jobs/batch_dask.py``.
"""

from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import queue
import signal
import time
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import CancelledError
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

    A ``KeyboardInterrupt`` (Ctrl-C, or SIGTERM in a batch) inside the block kills
    the local cluster's worker processes before it closes: closing it with its workers
    busy waits seconds for their tasks, and what they post is not wanted any more.

    Raises:
        UsageError: ``scheduler`` is malformed, or Dask is not installed.
        CamtoolError: the scheduler does not answer, or no worker joins it.
    """
    check_scheduler(scheduler)
    distributed = _distributed()
    if scheduler.startswith(LOCAL):
        dashboard = ":8787" if importlib.util.find_spec("bokeh") is not None else ":0"
        stopping = contextlib.ExitStack()  # held until the cluster has closed
        with (
            stopping,
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
            try:
                yield client
            except KeyboardInterrupt:  # Ctrl-C or SIGTERM: stop now, not when the tasks end
                # the client's own comms then fail as the workers go, and distributed logs
                # each with its traceback: not the user's business while the batch stops
                stopping.enter_context(_quiet("distributed"))
                _kill_workers(cluster)
                raise
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


@contextlib.contextmanager
def _quiet(name: str) -> Iterator[None]:
    """Logger ``name`` (and its children) says nothing inside; its level is restored after."""
    logger = logging.getLogger(name)
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


def _kill_workers(cluster: Any) -> None:
    """SIGKILL the worker processes of a local cluster's nannies (those still running)."""
    for nanny in list(cluster.workers.values()):
        pid = getattr(getattr(nanny, "process", None), "pid", None)
        if pid is not None:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)


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

    It does not trust Dask to bring every result back: when a worker dies, a result
    can be lost between the scheduler and the client and the client waits for ever
    (dask/distributed#6074, #7331; seen here with Dask 2026.8). So each finished
    task's result is fetched with a deadline (:data:`RESULT_TIMEOUT_S`), and when the
    cluster sits idle (no worker running a task) for :data:`STALL_S` while tasks are
    unfinished, those tasks are submitted again, each at most :data:`RESUBMITS` times
    before its file is an error row. Nothing is written twice: a task's result is
    taken once, from whichever of its runs returns first, and the others are
    cancelled or ignored.

    Args:
        client: a ``dask.distributed.Client``.
        work: a module-level function (workers import it by name).
        count: how many tasks.
        arguments: the arguments of task ``i`` (sent to the cluster; picklable); called
            again for a task submitted again.

    Yields:
        ``(i, result, None)`` as each task finishes, in finishing order, or
        ``(i, None, error)`` for a task that failed on the cluster (e.g.
        ``KilledWorker``: its workers kept dying; :class:`LostTask`: its result never
        came back). Each ``i`` once. Leaving the loop early cancels the tasks not yet
        finished.
    """
    threads = sum(client.nthreads().values())
    ahead = max(MIN_IN_FLIGHT, IN_FLIGHT_PER_THREAD * threads)
    pending: dict[Any, int] = {}  # the live run of each unfinished task
    again: deque[int] = deque()  # tasks to submit again, before new ones
    submits = [0] * count
    finished: queue.SimpleQueue[Any] = queue.SimpleQueue()  # filled by Dask's callback thread
    following = 0
    idle_since: float | None = None

    def fill() -> None:
        nonlocal following
        while len(pending) < ahead and (again or following < count):
            if again:
                index = again.popleft()
            else:
                index, following = following, following + 1
            future = client.submit(work, *arguments(index), retries=RETRIES, pure=False)
            submits[index] += 1
            pending[future] = index
            future.add_done_callback(finished.put)

    def lost(future: Any, why: str) -> tuple[int, Any, BaseException | None] | None:
        """Forget ``future``'s run; its task again, or its error once it was run too often."""
        index = pending.pop(future)
        future.cancel()
        if submits[index] <= RESUBMITS:
            again.append(index)
            return None
        return index, None, LostTask(f"{why}, {submits[index]} times; giving up on it")

    try:
        fill()
        while pending:
            try:
                future = finished.get(timeout=POLL_S)
            except queue.Empty:
                idle_since = _idle_since(client, idle_since)
                if idle_since is not None and time.monotonic() - idle_since >= STALL_S:
                    idle_since = None
                    why = f"the cluster sat idle for {STALL_S:g} s with the task unfinished"
                    for outcome in [lost(f, why) for f in list(pending)]:
                        if outcome is not None:
                            yield outcome
                    fill()
                continue
            idle_since = None
            if future not in pending:  # a run given up on (cancelled), or one already taken
                future.release()
                continue
            fetched = _outcome(future)
            if fetched is None:
                outcome = lost(
                    future, f"its result did not come back within {RESULT_TIMEOUT_S:g} s"
                )
            else:
                outcome = (pending.pop(future), *fetched)
            future.release()
            fill()
            if outcome is not None:
                yield outcome
    finally:
        if pending:
            client.cancel(list(pending))


class LostTask(CamtoolError):
    """A task of a batch on Dask whose result never came back, however often it was submitted."""


STALL_S = 30.0
"""How long the cluster may sit idle (no worker running a task) while tasks of the batch
are unfinished before those tasks are submitted again, s. A cluster waiting for a worker
to join or restart is idle too; that takes seconds, not this long."""
RESULT_TIMEOUT_S = 120.0
"""How long fetching a finished task's result may take before the task is submitted again, s."""
RESUBMITS = 2
"""Times a task is submitted again (after a stall or a lost result) before its file is an error."""
POLL_S = 1.0
"""How often the client looks at the cluster while no task finishes, s."""


def _outcome(future: Any) -> tuple[Any, BaseException | None] | None:
    """``(result, None)`` or ``(None, error)`` of a done future.

    ``None`` when its result did not come back within :data:`RESULT_TIMEOUT_S`.
    """
    if future.status == "error":
        return None, future.exception()
    if future.cancelled():
        return None, CancelledError(f"task {future.key} was cancelled on the cluster")
    try:
        return future.result(timeout=RESULT_TIMEOUT_S), None
    except TimeoutError:
        return None
    except Exception as exc:  # the task failed after all (its result could not be fetched)
        return None, exc


def _idle_since(client: Any, since: float | None) -> float | None:
    """When the cluster became idle (``since``, or now), or ``None`` while a worker runs a task."""
    try:
        running = any(client.processing().values())
    except (OSError, TimeoutError):  # the scheduler does not answer: not known to be idle
        return since
    if running:
        return None
    return since if since is not None else time.monotonic()
