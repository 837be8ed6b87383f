"""The collector set for camtool's many long-lived objects; the C heap's free pages returned.

A job builds hundreds of thousands of objects (segments, moves, blocks) and frees few, so
with Python's default thresholds the collector rescans that growing heap again and again.
Reference counting still frees every object not in a cycle at once. Switched off
(``CAMTOOL_ACCEL=0``) the collector keeps Python's defaults. Measured effects:
docs/performance.md.
"""

from __future__ import annotations

import functools
import gc
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from camtool.accel import enabled

THRESHOLD = (200_000, 30, 30)
"""``gc.set_threshold`` of a ``camtool`` command (mypy's values, for the same reason)."""


def tune_for_command() -> None:
    """Set :data:`THRESHOLD`, for the ``camtool`` command only (an importer keeps its own)."""
    if enabled():
        gc.set_threshold(*THRESHOLD)


@contextmanager
def paused() -> Iterator[None]:
    """No cyclic collection inside (reading a drawing allocates and frees almost nothing).

    The collector is re-enabled on the way out if it was enabled.
    """
    if not enabled():
        yield
        return
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


def collect_young() -> None:
    """Collect the young generations now, where a parser left its garbage in cycles.

    With :data:`THRESHOLD` the collector runs rarely, so such garbage would wait.
    """
    if enabled():
        gc.collect(1)


def release_free() -> None:
    """Give the freed pages of the C heap back to the system (glibc's ``malloc_trim``).

    A streamed verification frees a chunk's arrays as the next comes; glibc keeps the freed
    pages, scattered between live ones, so the process's resident size grows with the
    program though what it holds does not. Called when such a stage ends. Nothing on
    another C library, or switched off.
    """
    if not enabled():
        return
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@functools.cache
def _malloc_trim() -> Any:
    """Glibc's ``malloc_trim``, or ``None`` where the C library has none."""
    import ctypes
    import ctypes.util

    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        return libc.malloc_trim
    except (OSError, AttributeError):
        return None
