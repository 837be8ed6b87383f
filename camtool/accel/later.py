"""Work done in a forked helper while this process goes on: its bytes, taken later.

:func:`start` forks a helper that runs a function and sends back the bytes it returns;
:meth:`Later.take` waits for them. ``None`` everywhere the helper cannot help: switched off
(``CAMTOOL_ACCEL=0``), no ``fork``, one core, in a worker process, a failed fork, or a helper
that raised, died or hung; the caller then does the work itself. :func:`same` tells
whether a helper's answer started from this process's own state.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from contextlib import suppress

from camtool.accel import enabled


class Later:
    """A forked helper's answer, to :meth:`take` once (or :meth:`close` unread).

    Args:
        pid: the helper's process id.
        fd: the read end of the pipe its answer comes through.
    """

    def __init__(self, pid: int, fd: int) -> None:
        self.pid = pid
        self.fd: int | None = fd
        self.started = time.monotonic()

    def take(self) -> bytes | None:
        """The helper's bytes, waited for; ``None`` when it raised or died (or was taken).

        ``None`` too when they are not there by :func:`camtool.accel.cores.patience`'s
        deadline (a helper that hung): it is ended, and the caller does its work.
        """
        from camtool.accel.cores import patience, read_record

        if self.fd is None:
            return None
        try:
            return read_record(self.fd, patience(self.started))
        finally:
            self.close()

    def close(self) -> None:
        """End the helper, its answer unread."""
        from camtool.accel.cores import end_process

        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
            with suppress(ChildProcessError):
                end_process(self.pid, kill=True)


def start(work: Callable[[], bytes]) -> Later | None:
    """Fork a helper that runs ``work`` and answers its bytes; ``None`` when not.

    The helper is a copy of this process: ``work`` sees everything as it is now. Not when
    switched off, without ``fork``, on one core, in a worker process, or when no process
    can be forked.
    """
    if not enabled():
        return None
    from camtool.accel.cores import (
        FORK,
        default_jobs,
        fork_with_pipes,
        in_worker,
        quiet_crashes,
        write_record,
    )

    if not FORK or default_jobs() < 2 or in_worker():
        return None

    def serve(inbox: int, outbox: int) -> None:
        quiet_crashes()
        os.close(inbox)
        write_record(outbox, work())

    try:
        pid, to_child, from_child = fork_with_pipes(serve)
    except OSError:
        return None
    os.close(to_child)
    return Later(pid, from_child)


def same(a: object, b: object) -> bool:
    """Whether ``a`` and ``b`` are the same: floats bit for bit, the rest by type and value.

    ``-0.0`` is not ``0.0`` and a NaN is never the same; tuples, lists and dicts are
    compared item by item, anything else by its type and ``==``.
    """
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        assert isinstance(b, float)
        return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)
    if isinstance(a, tuple | list):
        assert isinstance(b, tuple | list)
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        assert isinstance(b, dict)
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b
