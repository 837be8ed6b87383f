"""Step arrays: the common output of every step interpolator.

Design notes: docs/internals.md, ``camtool/verify/steparray.py``.
"""

from __future__ import annotations

from typing import TypeVar

import numpy as np
import numpy.typing as npt

STEP_DTYPE = np.int8
"""dtype of a step array."""

StepArray = npt.NDArray[np.int8]
"""Type alias of a step array: ``(N, 2) int8``, read-only."""


_Array = TypeVar("_Array", bound=np.ndarray)


def read_only(array: _Array) -> _Array:
    """Mark ``array`` read-only and return it (the array itself, not a copy)."""
    array.flags.writeable = False
    return array


def freeze(rows: npt.ArrayLike) -> StepArray:
    """Return ``rows`` as a read-only ``(N, 2) int8`` step array.

    Args:
        rows: Anything numpy turns into an ``(N, 2)`` array of integers in
            ``{-1, 0, +1}``; an empty sequence gives shape ``(0, 2)``.

    Returns:
        A new read-only ``(N, 2) int8`` array.
    """
    arr = np.array(rows, dtype=STEP_DTYPE).reshape(-1, 2)
    arr.flags.writeable = False
    return arr


def empty_steps() -> StepArray:
    """Return a read-only step array with no iterations, shape ``(0, 2)``."""
    return freeze(np.zeros((0, 2), dtype=STEP_DTYPE))


def positions(steps: StepArray, start: tuple[int, int] = (0, 0)) -> npt.NDArray[np.int64]:
    """Positions after each iteration of a step array.

    Args:
        steps: ``(N, 2) int8`` step array.
        start: Start position ``(x, y)`` in steps.

    Returns:
        Read-only ``(N, 2) int64`` array, steps: the position *after* each
        iteration (the start point itself is not included).
    """
    pos = np.cumsum(steps, axis=0, dtype=np.int64)
    pos += np.asarray(start, dtype=np.int64)
    pos.flags.writeable = False
    return pos


def concatenate(parts: list[StepArray]) -> StepArray:
    """Join step arrays end to end (iterations in order).

    Args:
        parts: Step arrays, each ``(N_i, 2) int8``.

    Returns:
        Read-only ``(sum N_i, 2) int8`` step array.
    """
    if not parts:
        return empty_steps()
    return freeze(np.concatenate(parts, axis=0))
