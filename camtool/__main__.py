"""``python -m camtool`` and the ``camtool`` console script."""

from __future__ import annotations

import gc
import sys

GC_THRESHOLD = (200_000, 30, 30)
"""The cyclic garbage collector's thresholds in a ``camtool`` process (``gc.set_threshold``).

A job builds hundreds of thousands of long-lived objects (segments, moves, blocks) and
frees few, so with Python's defaults (700, 10, 10) the collector rescans that growing
heap again and again: on the 213-icon SVG benchmark 2 941 + 267 + 11 collections, 1.7 s
of the main process; with these, 9 young ones and the SVG importer's one of its parse's
garbage, 0.75 s (``gc.callbacks``; issue 17). The values are mypy's (``mypy/build.py``),
chosen for the same reason. Reference counting still frees every object not in a cycle at
once; cycles wait for the next collection. Only the command-line process is tuned: a
program that imports camtool keeps its own.
"""


def run() -> None:
    """Entry point: run the CLI and exit with its code."""
    gc.set_threshold(*GC_THRESHOLD)
    from camtool.cli.main import main

    sys.exit(main())


if __name__ == "__main__":
    run()
