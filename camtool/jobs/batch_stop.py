"""Stopping a command on SIGTERM as on Ctrl-C; a batch stopped cleanly, its pool's workers killed.

The first signal stops the batch at once (:class:`Interrupts`); the pool's workers are
killed and reaped (:func:`kill_pool`) and die with the batch if it dies first
(:func:`worker_init`), so no worker outlives it and only the batch process writes files.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from typing import Any


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised as Ctrl-C is, so that a batch stops the same way (:class:`Interrupts`)."""


class TerminateAsInterrupt:
    """A SIGTERM handler that raises :class:`Terminated` in the process that installs it.

    A command stopped by SIGTERM (``timeout``, a CI runner, ``kill``) then unwinds as
    after Ctrl-C: a file being written loses its temporary file, the output is left as it
    was, and the exit code is 143. A process forked while it is installed (a helper, a
    pool's worker) gets SIGTERM's default back at once (``os.register_at_fork``: a signal
    that came before Python's handlers ran there would be lost), so SIGTERM ends it as
    before; should the handler run there all the same, it does the same.

    Use it as a context manager in the main thread: the handler is installed only over
    Python's default (not over ``nohup``'s ignore, nor a caller's own handler), and the
    one before is put back at the end. :class:`Interrupts` takes it for a default.
    """

    def __init__(self) -> None:
        self.owner = os.getpid()
        self._previous: Any = None

    def __enter__(self) -> TerminateAsInterrupt:
        main = threading.current_thread() is threading.main_thread()
        if main and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
            self._previous = signal.signal(signal.SIGTERM, self)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGTERM, self._previous)
            self._previous = None

    def __call__(self, signum: int, frame: object) -> None:
        """The handler: raise :class:`Terminated` here; in a forked process, end by SIGTERM."""
        if os.getpid() != self.owner:  # a forked helper: end as before
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise Terminated()


def _default_in_child() -> None:
    """After a fork, in the child: SIGTERM's default again where the handler was in place."""
    with contextlib.suppress(ValueError):  # not the main thread: nothing to put back
        if isinstance(signal.getsignal(signal.SIGTERM), TerminateAsInterrupt):
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


os.register_at_fork(after_in_child=_default_in_child)


class Interrupts:
    """Ctrl-C (SIGINT) and SIGTERM while a batch runs: the first one stops it, cleanly.

    Inside the block (in the main thread) the first of these signals raises
    ``KeyboardInterrupt`` (:class:`Terminated` for SIGTERM) — at once, or, inside
    :meth:`held`, at its end, so that a file being written is written whole and
    recorded. Signals that follow are ignored: the batch is already stopping
    (killing its workers, releasing its output folder), and a second Ctrl-C must not
    cut that short. Only a signal whose handler is Python's default is taken over
    (SIGINT raising ``KeyboardInterrupt``, SIGTERM ending the process or
    :class:`TerminateAsInterrupt`'s): one ignored
    (``nohup``) or handled by the caller is left alone. The handlers are restored at
    the end; outside the main thread nothing changes.
    """

    def __init__(self) -> None:
        self.signum: int | None = None
        self._holding = False
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> Interrupts:
        if threading.current_thread() is threading.main_thread():
            defaults = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: signal.SIG_DFL}
            for signum, default in defaults.items():
                now = signal.getsignal(signum)
                if now == default or isinstance(now, TerminateAsInterrupt):
                    self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
        self._previous = {}

    def _handle(self, signum: int, frame: object) -> None:
        if self.signum is not None:  # stopping already
            return
        self.signum = signum
        if not self._holding:
            raise self.exception()

    def exception(self) -> KeyboardInterrupt:
        """The exception the signal received stands for."""
        return Terminated() if self.signum == signal.SIGTERM else KeyboardInterrupt()

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """A signal arriving inside the block is raised at its end (no later)."""
        self._holding = True
        try:
            yield
        finally:
            self._holding = False
        if self.signum is not None:
            raise self.exception()


def kill_pool(pool: Any) -> None:
    """Kill ``pool``'s workers now (SIGKILL), reap them, and drop the work not started.

    The pool's processes are its private ``_processes`` (CPython's since 3.2; the
    public ``kill_workers`` comes only with Python 3.14). With its workers gone the
    pool's own thread sees them die and ends, so nothing waits for a file in flight;
    it is waited for (its private ``_executor_manager_thread``, taken before ``shutdown``,
    which forgets it): ending the interpreter while it closes its wake-up pipe let
    CPython's exit hook write to the closed pipe and print a traceback (``OSError: [Errno
    9] Bad file descriptor``).
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())
    manager = getattr(pool, "_executor_manager_thread", None)
    for process in processes:
        with contextlib.suppress(OSError, ValueError):
            process.kill()
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            process.join(KILL_WAIT_S)
    pool.shutdown(wait=False, cancel_futures=True)
    if manager is not None:
        manager.join(KILL_WAIT_S)


KILL_WAIT_S = 5.0
"""Longest wait for a killed worker to be reaped, s (SIGKILL ends it at once)."""
PARENT_POLL_S = 0.5
"""How often a worker checks that the batch that started it is still alive, s."""


def worker_init(parent_pid: int) -> None:
    """Make a pool worker die with the batch process ``parent_pid``.

    On Linux the kernel sends the worker SIGKILL when its parent dies
    (``prctl(PR_SET_PDEATHSIG)``, prctl(2)); everywhere a daemon thread also polls
    the parent pid every :data:`PARENT_POLL_S` and exits the worker when the worker
    has been re-parented. A parent already gone ends the worker at once.

    The worker's k-d tree queries run on one thread (``KD_WORKERS``): the pool already
    runs one worker per job, and the distances do not depend on it. It ignores SIGINT:
    Ctrl-C at a terminal reaches the whole process group, and the batch alone decides
    what stops (it kills its workers, :func:`kill_pool`).
    """
    import sys

    from camtool.verify import nearest_exact

    nearest_exact.KD_WORKERS = 1
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    if sys.platform.startswith("linux"):
        import ctypes

        pr_set_pdeathsig = 1  # <linux/prctl.h>
        ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:
        os._exit(1)

    def watch() -> None:
        import time

        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="camtool-parent-watch", daemon=True).start()
