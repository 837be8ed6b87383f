"""``python -m camtool`` and the ``camtool`` console script."""

from __future__ import annotations

import atexit
import os
import sys
import threading
from contextlib import suppress
from typing import NoReturn


def run() -> None:
    """Entry point: run the CLI and exit with its code."""
    from camtool.accel.collector import tune_for_command

    tune_for_command()
    from camtool.cli.main import main

    leave(main())


def leave(code: int) -> NoReturn:
    """Exit with ``code``, without the interpreter's teardown of every object and module.

    After a big job that teardown is long for nothing: 0.15 s after ``camtool verify`` of
    the 66 M-step benchmark program (numba's compiled code, numpy's and scipy's modules,
    the last arrays), ~6 % of the command. What an exit must do is still done:
    the exit functions run (``atexit``: multiprocessing's children, tempfile's
    finalizers, a coverage run's data), then stdout and stderr are flushed; camtool
    writes its files in ``with`` blocks and flushes its stdout itself
    (:mod:`camtool.cli.common`), so no buffer is left. While another thread that is not a
    daemon runs, the exit is Python's own (it waits for them); a daemon thread (the
    progress line's timer, :mod:`camtool.cli.progress`) is left as Python's own exit
    leaves it. mypy leaves the same way, for the same reason (``mypy.util.hard_exit``).
    """
    main = threading.main_thread()
    if any(t is not main and not t.daemon for t in threading.enumerate()):
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with suppress(OSError, ValueError):  # a closed pipe: nothing is left to say
            stream.flush()
    os._exit(code)


if __name__ == "__main__":
    run()
