"""What the simulator knows about each block, as arrays, for the time models.

The time models of :mod:`camtool.verify.timing` are vectorised over the ``B``
blocks of a program: every per-block quantity is a ``(B,)`` array and every
model returns ``(B,)`` float64 seconds, read-only. :class:`BlockKinematics`
bundles those arrays so that the simulator can call any model the same way
(``model.block_time_s(blocks)``); the model functions themselves take plain
arrays. The helpers here validate and freeze arrays for the model modules.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.verify.steparray import read_only

FloatArray = npt.NDArray[np.float64]
"""``(B,) float64`` array."""
IntArray = npt.NDArray[np.int64]
"""``(B,) int64`` array."""
BoolArray = npt.NDArray[np.bool_]
"""``(B,) bool`` array."""


frozen = read_only
"""Mark an array read-only and return it (:func:`camtool.verify.steparray.read_only`)."""


def seconds(values: npt.ArrayLike) -> FloatArray:
    """Return ``values`` as a new read-only float64 array of seconds."""
    out = np.array(values, dtype=np.float64)
    out.flags.writeable = False
    return out


def _whole(name: str, arr: npt.NDArray[np.generic]) -> IntArray:
    """``arr`` as int64 after checking that it holds whole numbers.

    Raises:
        UsageError: If it holds non-finite or fractional values.
    """
    if arr.size and not np.issubdtype(arr.dtype, np.integer):
        f = arr.astype(np.float64)
        if not np.all(np.isfinite(f)) or np.any(f != np.round(f)):
            raise UsageError(f"{name} must hold whole numbers of steps, got {arr.dtype}")
    return arr.astype(np.int64)


def counts(name: str, values: npt.ArrayLike) -> IntArray:
    """Return ``values`` as a 1-D int64 array of non-negative counts.

    Raises:
        UsageError: If ``values`` is not 1-D, holds non-integers or negatives.
    """
    arr = np.asarray(values)
    if arr.ndim != 1:
        raise UsageError(f"{name} must be a (B,) array, got shape {arr.shape}")
    out = _whole(name, arr)
    if np.any(out < 0):
        i = int(np.flatnonzero(out < 0)[0])
        raise UsageError(f"{name} must be >= 0; block {i} has {int(out[i])}")
    return out


def floats(name: str, values: npt.ArrayLike, *, minimum: float = 0.0) -> FloatArray:
    """Return ``values`` as a 1-D float64 array of finite values ``>= minimum``.

    Raises:
        UsageError: If ``values`` is not 1-D, not finite or below ``minimum``.
    """
    arr = np.asarray(values, dtype=np.float64)
    if arr.ndim != 1:
        raise UsageError(f"{name} must be a (B,) array, got shape {arr.shape}")
    bad = ~np.isfinite(arr) | (arr < minimum)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise UsageError(f"{name} must be finite and >= {minimum}; block {i} has {arr[i]!r}")
    return arr


def flags(name: str, values: npt.ArrayLike) -> BoolArray:
    """Return ``values`` as a 1-D bool array.

    Raises:
        UsageError: If ``values`` is not 1-D.
    """
    arr = np.asarray(values, dtype=np.bool_)
    if arr.ndim != 1:
        raise UsageError(f"{name} must be a (B,) array, got shape {arr.shape}")
    return arr


def same_length(**arrays: npt.NDArray[np.generic]) -> int:
    """Common length ``B`` of 1-D arrays.

    Raises:
        UsageError: If the lengths differ (the message lists them).
    """
    sizes = {name: len(a) for name, a in arrays.items()}
    if len(set(sizes.values())) > 1:
        raise UsageError(f"per-block arrays differ in length: {sizes}")
    return next(iter(sizes.values()), 0)


def per_block(name: str, value: float | npt.ArrayLike, b: int, *, minimum: float) -> FloatArray:
    """Broadcast a scalar or ``(B,)`` parameter to ``(B,)`` float64, checked ``>= minimum``.

    Raises:
        UsageError: If it cannot be broadcast to ``(b,)`` or is out of range.
    """
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim > 1 or (arr.ndim == 1 and len(arr) != b):
        raise UsageError(f"{name} must be a number or a ({b},) array, got shape {arr.shape}")
    return floats(name, np.broadcast_to(arr, (b,)), minimum=minimum)


def positive(name: str, value: float) -> float:
    """Return ``value`` as a float after checking it is finite and ``> 0``.

    Raises:
        UsageError: If it is not.
    """
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise UsageError(f"{name} must be a finite number > 0, got {value!r}")
    return v


@dataclass(frozen=True, kw_only=True)
class BlockKinematics:
    """Per-block quantities the simulator hands to a time model; all arrays read-only.

    Construct with :meth:`build`, which fills the optional arrays; direct
    construction needs every array. The arrays are copied, checked and frozen.

    Attributes:
        dominant_steps: ``(B,) int64``, ``max(|x steps|, |y steps|)`` of the block.
        is_rapid: ``(B,) bool``, True for G00-style moves (feed ignored).
        feed_mm_min: ``(B,) float64``, programmed feed, mm/min (0 for a rapid).
        length_mm: ``(B,) float64``, path length of the block, mm (an arc's arc length).
        iterations: ``(B,) int64``, interpolator iterations (including iterations
            without a pulse).
        steps: ``(B, 3) int64``, signed steps per axis ``(x, y, z)``.
        compensation_steps: ``(B,) int64``, backlash compensation steps the
            controller inserted in the block.
        block_bytes: ``(B,) int64``, bytes the host sends for the block (for
            serial-time models).

    Raises:
        UsageError: If an array has the wrong shape, a count is negative or not
            whole, a feed or length is negative, or the lengths differ.
    """

    dominant_steps: IntArray
    is_rapid: BoolArray
    feed_mm_min: FloatArray
    length_mm: FloatArray
    iterations: IntArray
    steps: IntArray
    compensation_steps: IntArray
    block_bytes: IntArray

    def __post_init__(self) -> None:
        values = {
            "dominant_steps": counts("dominant_steps", self.dominant_steps),
            "is_rapid": flags("is_rapid", self.is_rapid),
            "feed_mm_min": floats("feed_mm_min", self.feed_mm_min),
            "length_mm": floats("length_mm", self.length_mm),
            "iterations": counts("iterations", self.iterations),
            "compensation_steps": counts("compensation_steps", self.compensation_steps),
            "block_bytes": counts("block_bytes", self.block_bytes),
        }
        b = same_length(**values)
        values["steps"] = _axis_steps(self.steps, b)
        for name, arr in values.items():
            object.__setattr__(self, name, frozen(arr.copy()))

    @classmethod
    def build(
        cls,
        *,
        dominant_steps: npt.ArrayLike,
        is_rapid: npt.ArrayLike,
        feed_mm_min: npt.ArrayLike,
        length_mm: npt.ArrayLike,
        iterations: npt.ArrayLike | None = None,
        steps: npt.ArrayLike | None = None,
        compensation_steps: npt.ArrayLike | None = None,
        block_bytes: npt.ArrayLike | None = None,
    ) -> BlockKinematics:
        """Build from array-likes, filling the optional arrays.

        ``iterations`` defaults to ``dominant_steps``; ``steps`` may be
        ``(B, 2)`` or ``(B, 3)`` and defaults to zeros, as do the other counts.

        Raises:
            UsageError: As the class does.
        """
        dom = counts("dominant_steps", dominant_steps)
        zeros = np.zeros(len(dom), dtype=np.int64)

        def arr(value: npt.ArrayLike | None, default: IntArray) -> IntArray:
            return default if value is None else np.asarray(value)

        return cls(
            dominant_steps=dom,
            is_rapid=np.asarray(is_rapid),
            feed_mm_min=np.asarray(feed_mm_min),
            length_mm=np.asarray(length_mm),
            iterations=arr(iterations, dom),
            steps=arr(steps, np.zeros((len(dom), 3), dtype=np.int64)),
            compensation_steps=arr(compensation_steps, zeros),
            block_bytes=arr(block_bytes, zeros),
        )

    def __len__(self) -> int:
        return len(self.dominant_steps)


def _axis_steps(steps: npt.ArrayLike, b: int) -> IntArray:
    """``(B, 3) int64`` signed axis steps from a ``(B, 2)`` or ``(B, 3)`` array."""
    arr = np.asarray(steps)
    if arr.ndim != 2 or arr.shape[0] != b or arr.shape[1] not in (2, 3):
        raise UsageError(f"steps must be a ({b}, 2) or ({b}, 3) array, got shape {arr.shape}")
    out = np.zeros((b, 3), dtype=np.int64)
    out[:, : arr.shape[1]] = _whole("steps", arr)
    return out
