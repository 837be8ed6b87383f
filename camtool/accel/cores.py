"""Independent pieces of one job on the machine's cores: forked workers, answers in order.

Behind the switch (:func:`camtool.accel.enabled`): switched off, :class:`ForkedWork` and
:func:`ahead` run every item here, in order, and :func:`meanwhile` runs nothing. The fork
primitives at the end (:func:`fork_with_pipes` and the records) also serve the offsets'
child, which isolates OpenCASCADE's crashes whether or not the switch is on.

Design notes: docs/internals.md, ``camtool/accel/cores.py``.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import select
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager, suppress
from contextvars import ContextVar
from typing import Any, Generic, TypeVar

from camtool.accel import enabled

__all__ = [
    "FORK",
    "Beside",
    "ForkedWork",
    "ahead",
    "beside",
    "default_jobs",
    "end_process",
    "fork_process",
    "fork_with_pipes",
    "how_ended",
    "in_worker",
    "meanwhile",
    "patience",
    "quiet_crashes",
    "read_exactly",
    "read_record",
    "wait_readable",
    "wait_until",
    "write_all",
    "write_record",
]

T = TypeVar("T")
R = TypeVar("R")

FORK = sys.platform.startswith("linux") and hasattr(os, "fork")
"""Whether workers can be forked here (Linux)."""


def default_jobs() -> int:
    """The CPUs this process may run on (``os.sched_getaffinity``; else ``os.cpu_count()``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def in_worker() -> bool:
    """Whether this process is itself a worker (``camtool batch``'s pool, a Dask worker).

    A batch already keeps the cores busy with one file per worker, and a daemonic process
    (Dask's) may not start children: there the work runs in the worker, one item after the
    other.
    """
    current = multiprocessing.current_process()
    return bool(current.daemon) or multiprocessing.parent_process() is not None


_MEANWHILE: ContextVar[list[Callable[[], object]] | None] = ContextVar(
    "camtool_meanwhile", default=None
)
"""The tasks :func:`meanwhile` gave that no wait has run yet, in order (this context's)."""


@contextmanager
def meanwhile(tasks: Sequence[Callable[[], object]]) -> Iterator[None]:
    """Within it, this process runs ``tasks`` while it waits for another (:func:`wait_readable`).

    For work the job will need later and that depends on nothing the other process
    makes, such as loading the modules and compiled kernels a verification uses:
    ``post --preview`` of a part with offsets waits ~0.4 s for the offsets' child to load
    OpenCASCADE (:func:`camtool.toolpath.offset.offset_all`), and loads numba's kernels
    there instead of afterwards; it waits for the error budget's workers
    (:meth:`ForkedWork.answers`) and loads matplotlib for the picture. Each
    task runs at most once; those no wait ran are dropped on leaving. A task only saves
    time: what it does must be what the job would do anyway, with the same results.
    """
    pending = _MEANWHILE.get()
    if pending is None:
        pending = []
        token = _MEANWHILE.set(pending)
    else:
        token = None
    if enabled():
        pending.extend(tasks)
    try:
        yield
    finally:
        for task in tasks:
            with suppress(ValueError):  # already run
                pending.remove(task)
        if token is not None:
            _MEANWHILE.reset(token)


def wait_readable(fd: int) -> None:
    """Run the tasks :func:`meanwhile` gave, one at a time, until ``fd`` can be read."""
    wait_until(lambda: bool(select.select([fd], [], [], 0)[0]))


def wait_until(ready: Callable[[], bool]) -> None:
    """Run the tasks :func:`meanwhile` gave, one at a time, until ``ready()``.

    A task is not interrupted: the wait may end up to one task later than the other
    process's answer. A task that raises is dropped (it only saved time; the job does
    the same work, and meets the same error, when it needs it); ``KeyboardInterrupt``
    and ``SystemExit`` are not caught.
    """
    pending = _MEANWHILE.get()
    while pending and not ready():
        task = pending.pop(0)
        with suppress(Exception):
            task()


def ahead(items: Iterable[T]) -> Iterator[T]:
    """``items`` in order, the next one made in a thread while the caller works on this one.

    For a producer and a consumer that both spend their time where Python lets go of the
    GIL (numba's ``nogil`` kernels, numpy on large arrays), the two run on two cores. One
    item is made ahead, never more, so at most two are held beyond the caller's (memory).
    An exception raised while making an item is raised here, at that item's place, after
    the items before it. Leaving the loop early (``break``, an error, Ctrl-C) stops the
    thread once it has made its current item, and it is joined before this returns: no
    thread outlives the loop (forking stays safe). With one core, or in a worker process
    (:func:`in_worker`), the items are made here, one after the other.
    """
    if default_jobs() < 2 or in_worker() or not enabled():
        yield from items
        return
    made: queue.Queue[tuple[bool, Any]] = queue.Queue(maxsize=1)
    stop = threading.Event()

    def hand(done: bool, value: Any) -> bool:
        while not stop.is_set():
            try:
                made.put((done, value), timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def make() -> None:
        try:
            for item in items:
                if not hand(False, item):
                    return
            hand(True, None)
        except BaseException as exc:  # raised in the caller's thread, at its place
            hand(True, exc)

    thread = threading.Thread(target=make, name="camtool-ahead", daemon=True)
    thread.start()
    try:
        while True:
            done, value = made.get()
            if done:
                if value is not None:
                    raise value
                return
            yield value
    finally:
        stop.set()
        thread.join()
        close = getattr(items, "close", None)
        if close is not None:  # a generator left early: its own clean-up, here
            close()


class Beside(Generic[T]):
    """``fn()``, made in a thread from now on, taken later (:func:`beside`)."""

    def __init__(self, fn: Callable[[], T], threaded: bool) -> None:
        self._fn = fn
        self._answer: tuple[bool, Any] | None = None
        self._thread: threading.Thread | None = None
        if threaded:
            self._thread = threading.Thread(target=self._make, name="camtool-beside", daemon=True)
            self._thread.start()

    def _make(self) -> None:
        try:
            self._answer = (True, self._fn())
        except BaseException as exc:  # raised where the answer is taken
            self._answer = (False, exc)

    def join(self) -> None:
        """Wait for the thread, if one runs (the answer stays, to be taken or not)."""
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def result(self) -> T:
        """``fn()``'s answer (made here if no thread made it); what it raised is raised here."""
        self.join()
        if self._answer is None:
            self._make()
        assert self._answer is not None
        ok, value = self._answer
        if not ok:
            raise value
        return value


def beside(fn: Callable[[], T]) -> Beside[T]:
    """``fn()`` started in a thread now, for an answer the caller may take later.

    For work that releases the GIL (scipy's k-d tree build, numba's ``nogil`` kernels)
    and that the caller is likely to need while the other core has nothing to do: the
    caller goes on meanwhile. :meth:`Beside.result` waits for the answer; the caller
    must call :meth:`Beside.join` (or ``result``) before it forks or returns from the
    step, so that no thread outlives it. With one core, in a worker process
    (:func:`in_worker`) or with the switch off, no thread starts: ``result`` makes the
    answer then, and an answer never asked for is never made.
    """
    return Beside(fn, default_jobs() >= 2 and not in_worker() and enabled())


class ForkedWork(Generic[T, R]):
    """``[fn(item) for item in items]``, started now in forked workers, gathered later.

    The workers are forked when it is made, so they see this process's state as it is
    then, and this process works meanwhile; :meth:`answers` gathers what they made (and
    makes here what they could not). Use it as a context manager: leaving it stops the
    workers (the items not yet started are dropped, those running are waited for), so an
    error raised here meanwhile leaves no process behind.

    Args:
        fn: any callable, a closure included (it is inherited by the workers, not pickled);
            its answers must pickle. It must not depend on side effects of other items:
            each runs in its own process, whose changes to its state are not seen here.
        items: the work, a few coarse pieces (each worker takes the next item as it ends
            one, so the longest item bounds the wall time).
        jobs: worker processes at most; ``None``: :func:`default_jobs`. With 1, one item,
            no ``fork`` or in a worker process, every item runs here (in :meth:`answers`).
    """

    def __init__(self, fn: Callable[[T], R], items: Sequence[T], *, jobs: int | None = None):
        self.fn, self.items = fn, items
        self._got: dict[int, R] = {}
        self._pool: ProcessPoolExecutor | None = None
        self._futures: dict[Any, int] = {}
        workers = min(default_jobs() if jobs is None else max(1, jobs), len(items))
        if workers > 1 and FORK and not in_worker() and enabled():
            self._start(workers)

    def __enter__(self) -> ForkedWork[T, R]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Stop the workers (idempotent)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def answers(self, done: Callable[[int], None] | None = None) -> list[R]:
        """``fn``'s answers, in the order of the items; the workers are stopped after.

        ``done``: called here with the number of items answered so far, as each answer
        comes in (for a progress report; it changes no answer).

        Raises:
            Whatever ``fn`` raises for the first item it fails on, raised here: an item
            whose worker raised, died or sent no answer is run again in this process, in
            order.
        """
        try:  # what this process needs next is loaded while the workers work
            wait_until(lambda: all(future.done() for future in self._futures))
            for future in as_completed(self._futures):
                try:
                    ok, value = future.result()
                except Exception:  # the worker died or its answer did not come back whole
                    continue
                if ok:
                    self._got[self._futures[future]] = value
                    if done is not None:
                        done(len(self._got))
        finally:
            self.close()
        out: list[R] = []
        for i, item in enumerate(self.items):
            if i not in self._got:
                self._got[i] = self.fn(item)
                if done is not None:
                    done(len(self._got))
            out.append(self._got[i])
        return out

    def _start(self, workers: int) -> None:
        """Fork the workers and hand them every item (nothing if they cannot start)."""
        try:
            context = multiprocessing.get_context("fork")
            self._pool = ProcessPoolExecutor(
                workers,
                mp_context=context,
                initializer=_start_worker,
                initargs=(self.fn, self.items),
            )
            self._futures = {self._pool.submit(_run_item, i): i for i in range(len(self.items))}
        except (OSError, ValueError, RuntimeError):  # cannot fork: every item runs here
            self._futures = {}
            self.close()


_WORK: list[tuple[Callable[[Any], Any], Sequence[Any]]] = []
"""In a worker process only: the ``(fn, items)`` it was forked with (set by its initializer)."""


def _start_worker(fn: Callable[[Any], Any], items: Sequence[Any]) -> None:
    """A worker's initializer: keep its work; Ctrl-C is the parent's to handle."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORK.append((fn, items))


def _run_item(index: int) -> tuple[bool, Any]:
    """In a worker: ``(True, fn(items[index]))``, or ``(False, None)`` when ``fn`` raised.

    The parent runs a failed item again itself, so the error is raised there, in order.
    """
    fn, items = _WORK[-1]
    try:
        return True, fn(items[index])
    except Exception:  # answered in the parent, which raises it where it belongs
        return False, None


def fork_process(run: Callable[[], None], *, closing: Sequence[int]) -> int:
    """Fork a process that closes ``closing`` (fds it must not hold), runs ``run`` and leaves.

    It leaves with ``os._exit``: 0 after ``run``, 70 when ``run`` raised (whoever reads
    its answers sees which it did not give), never through this process's own code.
    Returns its pid, in this process. For the helpers a job starts ahead of the work they
    will do (:mod:`camtool.toolpath.offset`'s child, :mod:`camtool.accel.ahead`).
    """
    pid = os.fork()
    if pid == 0:
        code = 0
        try:
            for fd in closing:
                os.close(fd)
            run()
        except BaseException:
            code = 70
        finally:
            os._exit(code)
    return pid


def fork_with_pipes(
    run: Callable[[int, int], None], *, closing: Sequence[int] = ()
) -> tuple[int, int, int]:
    """Fork a helper joined to this process by two pipes: ``(pid, to_child, from_child)``.

    The child runs ``run(inbox, outbox)`` on its ends of the pipes, with this process's
    ends and ``closing`` closed in it, and leaves as :func:`fork_process` says; this
    process keeps ``to_child`` and ``from_child``. The one way the offsets' child, its
    workers and the picture's child are started.

    Raises:
        OSError: no pipe or no fork (a process limit, no memory). Nothing is left open:
            the caller does the work itself, as where ``fork`` is missing.
    """
    made: list[int] = []
    try:
        made += os.pipe()
        made += os.pipe()
        inbox, to_child, from_child, outbox = made
        pid = fork_process(lambda: run(inbox, outbox), closing=(*closing, to_child, from_child))
    except OSError:
        for fd in made:
            os.close(fd)
        raise
    os.close(inbox)
    os.close(outbox)
    return pid, to_child, from_child


def end_process(pid: int, *, kill: bool = False) -> int:
    """Wait for the child ``pid`` (``kill``: SIGKILL it first); its ``waitpid`` status.

    For the helpers :func:`fork_process` started (:func:`how_ended` reads the status).

    Raises:
        ChildProcessError: ``pid`` is no child of this process (already waited for).
    """
    if kill:
        with suppress(OSError):  # it has ended already
            os.kill(pid, signal.SIGKILL)
    return os.waitpid(pid, 0)[1]


def quiet_crashes() -> None:
    """In a helper process: a crash leaves no core file and no Python fault report.

    The process that started it says what happened (a helper that dies is answered for,
    or its work is done again, by the job's own process).
    """
    import faulthandler
    import resource

    faulthandler.disable()
    with suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def how_ended(status: int) -> str:
    """How a process ended, from its ``waitpid`` status: ``"SIGSEGV, signal 11"``, an exit code."""
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        try:
            name = signal.Signals(number).name
        except ValueError:
            name = "a signal"
        return f"{name}, signal {number}"
    return f"exit code {os.waitstatus_to_exitcode(status)}"


HELPER_PATIENCE = 4.0
"""How many times as long as this process has worked since it forked a helper it then waits
for the helper's answer (:func:`patience`): the helper's share of the work is about the size
of this process's, so a helper that takes four times as long has hung (a lock it inherited
held, the machine out of memory), and this process does that share itself."""
HELPER_PATIENCE_MIN_S = 10.0
"""The least time this process waits for a helper's answer, s (a short job on a busy machine)."""


def patience(started: float) -> float:
    """The ``time.monotonic()`` until which to wait for a helper forked at ``started``.

    :data:`HELPER_PATIENCE` times the time since, and at least :data:`HELPER_PATIENCE_MIN_S`.
    A helper's answer not there by then is taken as none (:func:`read_record`): the caller
    ends the helper and does its work itself, as for a helper that died.
    """
    now = time.monotonic()
    return now + max(HELPER_PATIENCE_MIN_S, HELPER_PATIENCE * (now - started))


def _readable_by(fd: int, deadline: float) -> bool:
    """Whether ``fd`` can be read before ``time.monotonic()`` reaches ``deadline``."""
    while True:
        left = deadline - time.monotonic()
        if select.select([fd], [], [], max(0.0, left))[0]:
            return True
        if left <= 0.0:
            return False


def read_exactly(fd: int, size: int, deadline: float | None = None) -> bytes | None:
    """``size`` bytes from ``fd``; ``None`` when it ends first (its writer left or died).

    ``deadline``: a ``time.monotonic()`` (:func:`patience`) after which waiting for more
    bytes gives ``None`` too; ``None``: wait as long as it takes.
    """
    parts = []
    while size:
        if deadline is not None and not _readable_by(fd, deadline):
            return None
        part = os.read(fd, min(size, 1 << 20))
        if not part:
            return None
        parts.append(part)
        size -= len(part)
    return b"".join(parts)


def write_all(fd: int, data: bytes) -> None:
    """Write every byte of ``data`` to ``fd``, ``os.write`` after ``os.write``.

    A write to a pipe may take only part of its bytes; the next one then reports a reader
    that has gone.

    Raises:
        OSError: the write failed (``BrokenPipeError``: the reader has gone).
    """
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def write_record(fd: int, data: bytes) -> None:
    """Write ``data`` to ``fd`` framed by its length (8 bytes, little-endian), whole.

    Raises:
        OSError: the reader has gone (``BrokenPipeError``).
    """
    write_all(fd, len(data).to_bytes(8, "little") + data)


def read_record(fd: int, deadline: float | None = None) -> bytes | None:
    """The next record :func:`write_record` wrote to ``fd``; ``None`` when it ends first.

    ``deadline``: as for :func:`read_exactly` (``None`` too when it passes first).
    """
    head = read_exactly(fd, 8, deadline)
    if head is None:
        return None
    return read_exactly(fd, int.from_bytes(head, "little"), deadline)
