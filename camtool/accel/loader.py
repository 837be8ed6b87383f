"""Compiled kernels loaded on demand: once a process has asked for enough work to pay for them.

Loading numba and its cached kernels costs start-up time and memory once a process, so a
small job is faster on the plain numpy paths (figures: docs/performance.md). A
:class:`KernelsOnDemand` counts the work its callers announce and imports its kernel
module when the count reaches its threshold; from then on every caller gets the module.
Nothing but the speed depends on it: every kernel gives what the plain path gives.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType

from camtool.accel import enabled


class KernelsOnDemand:
    """One kernel module of the accel layer, imported once the work asked for reaches ``threshold``.

    Args:
        module: the module's name (``"camtool.accel.kernels"``).
        threshold: work (rows, samples: the callers' unit) from which it is loaded.
        little_endian: load it only on a little-endian machine (kernels whose packed
            rows assume it).
    """

    def __init__(self, module: str, threshold: int, *, little_endian: bool = False) -> None:
        self.module = module
        self.threshold = threshold
        self.little_endian = little_endian
        self._work = 0
        self._loaded: tuple[ModuleType | None] | None = None  # (module or None,) once tried

    def get(self, work: int) -> ModuleType | None:
        """The module once the work so far, ``work`` included, reaches :attr:`threshold`.

        ``None`` (the plain path) before that, with ``CAMTOOL_ACCEL=0``, without numba,
        or on a machine the module does not run on.

        Args:
            work: what the caller is about to compute, ``>= 0``, in the threshold's unit.
        """
        if not enabled():
            return None
        if self._loaded is not None:
            return self._loaded[0]
        self._work += work
        if self._work < self.threshold:
            return None
        found: ModuleType | None = None
        if not self.little_endian or sys.byteorder == "little":
            try:
                found = importlib.import_module(self.module)
            except ImportError:  # numba not installed: the plain paths answer
                found = None
        self._loaded = (found,)
        return found

    @contextmanager
    def off(self) -> Iterator[None]:
        """Inside, :meth:`get` answers ``None`` (the plain paths), as if numba were missing."""
        saved = self._loaded
        self._loaded = (None,)
        try:
            yield
        finally:
            self._loaded = saved

    def loaded(self) -> ModuleType | None:
        """The module if it was loaded, else ``None`` (nothing is loaded by asking)."""
        return None if self._loaded is None else self._loaded[0]

    def forget(self) -> None:
        """Back to the state of a new process: nothing counted, nothing loaded (for tests)."""
        self._work = 0
        self._loaded = None
