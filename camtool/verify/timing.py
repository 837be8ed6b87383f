"""Generic machining-time library: per-block kinematics and the rest-to-rest trapezoid.

Design notes: docs/internals.md, ``camtool/verify/timing.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from typing import Any, ClassVar, Protocol

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError, UsageError
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
            given = getattr(self, name)
            fresh = arr is not given and arr.base is None and arr.flags.owndata  # a new array
            object.__setattr__(self, name, frozen(arr if fresh else arr.copy()))

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


# ----------------------------------------------------- rest-to-rest trapezoid

DEFAULT_MAX_RATE_MM_MIN = 500.0
"""Default maximum (and rapid) rate, mm/min: GRBL 1.1's ``$110``/``$111`` (``defaults.h``)."""
DEFAULT_ACCELERATION_MM_S2 = 10.0
"""Default acceleration, mm/s²: GRBL 1.1's generic ``$120``/``$121`` (``defaults.h``)."""


def trapezoid_time_s(
    length_mm: npt.ArrayLike,
    speed_mm_s: npt.ArrayLike,
    acceleration_mm_s2: float | npt.ArrayLike,
    *,
    entry_mm_s: float | npt.ArrayLike = 0.0,
    exit_mm_s: float | npt.ArrayLike = 0.0,
) -> FloatArray:
    """Duration of trapezoidal (or triangular) speed profiles, s (module docstring formula).

    Entry and exit speeds above the nominal speed are lowered to it.

    Args:
        length_mm: ``(B,)`` path lengths, mm, ``>= 0``.
        speed_mm_s: ``(B,)`` nominal (cruise) speeds, mm/s, ``> 0`` where the
            length is not 0.
        acceleration_mm_s2: Acceleration, mm/s², scalar or ``(B,)``, ``> 0``.
        entry_mm_s: Speed at the block start, mm/s, scalar or ``(B,)``.
        exit_mm_s: Speed at the block end, mm/s, scalar or ``(B,)``.

    Returns:
        ``(B,) float64`` seconds, read-only; 0 for a zero length.

    Raises:
        UsageError: If lengths differ, a value is negative, a moving block has
            no speed, or the exit speed cannot be reached from the entry speed
            within the length (``|v1² − v0²| > 2aL``).
    """
    length = floats("length_mm", length_mm)
    v = floats("speed_mm_s", speed_mm_s)
    b = same_length(length_mm=length, speed_mm_s=v)
    a = per_block("acceleration_mm_s2", acceleration_mm_s2, b, minimum=0.0)
    if np.any(a <= 0):
        raise UsageError("acceleration_mm_s2 must be > 0")
    moving = length > 0
    if np.any(moving & (v <= 0)):
        i = int(np.flatnonzero(moving & (v <= 0))[0])
        raise UsageError(f"block {i} moves {length[i]!r} mm at speed 0; give a feed > 0")
    v0 = np.minimum(per_block("entry_mm_s", entry_mm_s, b, minimum=0.0), v)
    v1 = np.minimum(per_block("exit_mm_s", exit_mm_s, b, minimum=0.0), v)
    unreachable = np.abs(v1**2 - v0**2) > 2.0 * a * length * (1 + 1e-12) + 1e-18
    if np.any(unreachable):
        i = int(np.flatnonzero(unreachable)[0])
        raise UsageError(
            f"block {i}: cannot go from {v0[i]!r} to {v1[i]!r} mm/s in {length[i]!r} mm"
        )
    d_acc = (v**2 - v0**2) / (2.0 * a)
    d_dec = (v**2 - v1**2) / (2.0 * a)
    cruise = length - d_acc - d_dec
    v_safe = np.where(v > 0, v, 1.0)
    t_trap = (2.0 * v - v0 - v1) / a + np.maximum(cruise, 0.0) / v_safe
    vp = np.sqrt(np.maximum((2.0 * a * length + v0**2 + v1**2) / 2.0, 0.0))
    t_tri = (2.0 * vp - v0 - v1) / a
    t = np.where(cruise >= 0, t_trap, t_tri)
    return seconds(np.where(moving, t, 0.0))


def trapezoid_block_time_s(
    length_mm: npt.ArrayLike,
    feed_mm_min: npt.ArrayLike,
    is_rapid: npt.ArrayLike,
    *,
    acceleration_mm_s2: float | npt.ArrayLike = DEFAULT_ACCELERATION_MM_S2,
    max_rate_mm_min: float | npt.ArrayLike = DEFAULT_MAX_RATE_MM_MIN,
) -> FloatArray:
    """Conservative block time: rest-to-rest trapezoid at min(F, max rate), s.

    Rapids run at ``max_rate_mm_min``; feed moves at the programmed feed capped
    by it. No junction look-ahead, so the sum over blocks is an upper bound of
    a blending planner's real time (module docstring).

    Args:
        length_mm: ``(B,)`` path lengths, mm (arc length for arcs).
        feed_mm_min: ``(B,)`` programmed feeds, mm/min (ignored for rapids).
        is_rapid: ``(B,)`` True for G00.
        acceleration_mm_s2: Acceleration along the path, mm/s², scalar or ``(B,)``.
        max_rate_mm_min: Maximum rate, mm/min, scalar or ``(B,)``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: If lengths differ, a value is negative or not finite, a
            feed move of non-zero length has feed 0, or a limit is not positive.
    """
    length = floats("length_mm", length_mm)
    feed = floats("feed_mm_min", feed_mm_min)
    rapid = flags("is_rapid", is_rapid)
    b = same_length(length_mm=length, feed_mm_min=feed, is_rapid=rapid)
    cap = per_block("max_rate_mm_min", max_rate_mm_min, b, minimum=0.0)
    if np.any(cap <= 0):
        raise UsageError("max_rate_mm_min must be > 0")
    speed = np.where(rapid, cap, np.minimum(feed, cap)) / 60.0
    return trapezoid_time_s(length, speed, acceleration_mm_s2)


@dataclass(frozen=True, kw_only=True)
class TrapezoidTiming:
    """Parameters of the rest-to-rest trapezoid time model (:func:`trapezoid_block_time_s`).

    Attributes:
        acceleration_mm_s2: Acceleration along the path, mm/s² (GRBL ``$120``).
        max_rate_mm_min: Maximum rate, also the rapid rate, mm/min (GRBL ``$110``).

    Raises:
        UsageError: If a value is not a finite number > 0.
    """

    model: ClassVar[str] = "trapezoid"
    assumes: ClassVar[str] = "every block from rest to rest: an upper bound"
    """What the times assume, said with the estimate: a controller that blends its blocks
    (GRBL's planner, LinuxCNC's G64) is faster."""
    acceleration_mm_s2: float = DEFAULT_ACCELERATION_MM_S2
    max_rate_mm_min: float = DEFAULT_MAX_RATE_MM_MIN

    def __post_init__(self) -> None:
        positive("acceleration_mm_s2", self.acceleration_mm_s2)
        positive("max_rate_mm_min", self.max_rate_mm_min)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        return trapezoid_block_time_s(
            blocks.length_mm,
            blocks.feed_mm_min,
            blocks.is_rapid,
            acceleration_mm_s2=self.acceleration_mm_s2,
            max_rate_mm_min=self.max_rate_mm_min,
        )

    def capped_blocks(self, blocks: BlockKinematics) -> list[tuple[IntArray, str]]:
        """Feed moves whose feed is over the maximum rate, timed at the rate instead."""
        over = ~blocks.is_rapid & (blocks.feed_mm_min > self.max_rate_mm_min)
        return [
            (
                group,
                f"feed {feed:g} mm/min is over the maximum rate "
                f"{self.max_rate_mm_min:g} mm/min of the {self.model} timing model "
                "([machine.timing] max_rate_mm_min): timed at the maximum rate",
            )
            for group, feed in blocks_by_value(over, blocks.feed_mm_min)
        ]


def blocks_by_value(chosen: BoolArray, values: FloatArray) -> list[tuple[IntArray, float]]:
    """The ``chosen`` blocks grouped by their value: ``(indices, value)`` per distinct value.

    Each group's indices ``(n,) int64`` rise; the groups come in the order of their first
    block. A program of half a million capped moves makes a few groups, not a message each.
    """
    index = np.flatnonzero(chosen)
    if not len(index):
        return []
    group_of = np.unique(values[index], return_inverse=True)[1]
    order = np.argsort(group_of, kind="stable")
    bounds = np.flatnonzero(np.diff(group_of[order])) + 1
    groups = np.split(index[order], bounds)
    groups.sort(key=lambda g: int(g[0]))
    return [(g, float(values[g[0]])) for g in groups]


class TimingModel(Protocol):
    """A timing model: parameters (a frozen dataclass) and the seconds each block takes.

    ``model`` names it as a ``[machine.timing]`` table does; ``block_time_s`` returns
    ``(B,) float64`` seconds, read-only, for the ``B`` blocks of ``blocks``. An optional
    ``assumes`` class attribute says what a reader of the estimate should know
    (:func:`camtool.verify.clock.time_assumption`; :class:`TrapezoidTiming`'s upper bound).
    """

    model: ClassVar[str]

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        ...


CappedBlocks = Callable[[BlockKinematics], list[tuple[IntArray, str]]]
"""Optional method ``capped_blocks(blocks)`` of a timing model: every block the model
times slower than programmed because of a limit it applies (a step-rate cap, a
maximum rate), as ``(block indices (n,) int64 rising, what was capped)``, one pair
per reason (:func:`blocks_by_value`); the verifier warns about
each (:func:`camtool.verify.clock.timing_warnings`), so no cap is silent."""


TIMING_RANGES: dict[str, tuple[float, float, str]] = {
    "_mm_min": (1e-3, 1e7, "mm/min"),
    "_mm_s2": (1e-3, 1e8, "mm/s²"),
}
"""The physical range of a timing number by its unit (its name's ending; 0 means "none"
where a model allows it): a rate of ``1e-300`` mm/min would time a program at 10³⁰⁰ s."""

MAX_TIMING_NUMBER = 1e9
"""Largest magnitude of any other timing number (µs, ms, s, baud, periods)."""


def _in_range(key: str, number: float, where: str) -> float:
    """``number`` if finite and within its unit's range (:data:`TIMING_RANGES`), else refused.

    Raises:
        InputError: naming ``where``, the key, the range and the unit.
    """
    low, high, unit = next(
        (span for end, span in TIMING_RANGES.items() if key.endswith(end)),
        (0.0, MAX_TIMING_NUMBER, ""),
    )
    if not math.isfinite(number) or (number != 0 and not low <= abs(number) <= high):
        raise InputError(
            f"{where}: {key} must be between {low:g} and {high:g}{' ' + unit if unit else ''} "
            f"(a physical machine), got {number!r}"
        )
    return number


def timing_from_table(cls: type[Any], table: Mapping[str, Any], *, where: str) -> Any:
    """Build the parameter dataclass ``cls`` from a TOML ``[timing]`` table.

    The table holds ``model`` (ignored here: the caller resolved it to ``cls``) and
    any of ``cls``'s dataclass fields: numbers, or names where the field's default
    is a string (i8751's ``cruise``), passed as written for the model to check
    (e.g. ``model = "trapezoid"`` and ``acceleration_mm_s2 = 500``).

    Args:
        cls: A frozen parameter dataclass (every field a number or a name).
        table: The parsed table.
        where: What to name in messages, e.g. ``"machine.toml [timing]"``.

    Returns:
        ``cls(**parameters)``.

    Raises:
        InputError: An unknown key, or a value of the wrong type or out of range,
            naming ``where`` and the known keys.
    """
    name = table.get("model")
    by_name = {f.name: f for f in fields(cls)}
    unknown = sorted(set(table) - set(by_name) - {"model"})
    if unknown:
        raise InputError(
            f"{where}: unknown {name} timing key(s) {unknown}; known: {sorted(by_name)}"
        )
    kwargs: dict[str, Any] = {}
    for key, value in table.items():
        if key == "model":
            continue
        if isinstance(by_name[key].default, str):  # a choice by name, checked by the model
            if not isinstance(value, str):
                raise InputError(f"{where}: {key} must be a name, got {value!r}")
            kwargs[key] = value
        elif isinstance(value, bool) or not isinstance(value, int | float):
            raise InputError(f"{where}: {key} must be a number, got {value!r}")
        else:
            kwargs[key] = _in_range(key, float(value), where)
    try:
        return cls(**kwargs)
    except UsageError as exc:
        raise InputError(f"{where}: {exc}") from exc
