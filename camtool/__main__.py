"""``python -m camtool`` and the ``camtool`` console script."""

from __future__ import annotations

import atexit
import gc
import os
import sys
import threading
from contextlib import suppress
from typing import NoReturn

GC_THRESHOLD = (200_000, 30, 30)
"""The cyclic garbage collector's thresholds in a ``camtool`` process (``gc.set_threshold``).

A job builds hundreds of thousands of long-lived objects (segments, moves, blocks) and
frees few, so with Python's defaults (700, 10, 10) the collector rescans that growing
heap again and again: on the 213-icon SVG benchmark 2 941 + 267 + 11 collections, 1.7 s
of the main process; with these, 9 young ones and the SVG importer's one of its parse's
garbage, 0.75 s (``gc.callbacks``). The values are mypy's (``mypy/build.py``),
chosen for the same reason. Reference counting still frees every object not in a cycle at
once; cycles wait for the next collection. Only the command-line process is tuned: a
program that imports camtool keeps its own.
"""


def run() -> None:
    """Entry point: run the CLI and exit with its code."""
    gc.set_threshold(*GC_THRESHOLD)
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
    (:mod:`camtool.cli.common`), so no buffer is left. While another thread runs, the
    exit is Python's own (it waits for them). mypy leaves the same way, for the same
    reason (``mypy.util.hard_exit``).
    """
    if threading.active_count() > 1:
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with suppress(OSError, ValueError):  # a closed pipe: nothing is left to say
            stream.flush()
    os._exit(code)


if __name__ == "__main__":
    run()
