"""The point-list arrays of the Angel-11 wood router's Matlab GUI.

The GUI (Angel-11 §3, verbatim code in Appendix A.1, thesis L4400–L4515) turns
the clicked vertices into three integer arrays that the master PIC replays one
segment at a time:

Design notes: docs/internals.md, ``postprocessors/matlab_router/arrays.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeAlias, overload

from camtool.model.errors import DialectError, UsageError

if TYPE_CHECKING:  # numpy is imported where it is used: `camtool targets` loads this module
    import numpy as np
    import numpy.typing as npt

    IntArray: TypeAlias = npt.NDArray[np.int64]

DEFAULT_SPEED = 480
"""Major-axis speed of a segment, encoder counts per 5 ms (Angel-11 §2.3, R7, L4458)."""


@overload
def matlab_round(x: float) -> int: ...


@overload
def matlab_round(x: npt.NDArray[np.floating] | npt.NDArray[np.integer]) -> IntArray: ...


def matlab_round(x: float | npt.NDArray[np.floating] | npt.NDArray[np.integer]) -> int | IntArray:
    """Round half away from zero, as Matlab's ``round`` (Angel-11 §3, R1).

    ``matlab_round(2.5) == 3`` and ``matlab_round(-2.5) == -3`` (Python's
    ``round`` and ``numpy.round`` give 2 and -2). Exact for every double: the
    fractional part ``a - floor(a)`` is computed without rounding error, so
    ``0.49999999999999994`` rounds to 0.

    Args:
        x: A number, or an array of numbers (any shape).

    Returns:
        An ``int`` for a scalar, else a new ``int64`` array of the same shape.

    Raises:
        UsageError: If a value is not finite.
    """
    import numpy as np

    arr = np.asarray(x, dtype=np.float64)
    if not np.all(np.isfinite(arr)):
        raise UsageError(f"cannot round non-finite value(s): {x!r}")
    mag = np.abs(arr)
    floor = np.floor(mag)
    rounded = np.copysign(floor + (mag - floor >= 0.5), arr).astype(np.int64)
    if np.ndim(x) == 0:
        return int(rounded)
    return rounded


def points_01mm(xy_mm: npt.ArrayLike) -> IntArray:
    """Convert vertices in mm to whole 0.1 mm units, as the GUI's ``round(xy*100)`` in cm (R1).

    Args:
        xy_mm: ``(N, 2)`` vertices, mm.

    Returns:
        Read-only ``(N, 2) int64`` array, 0.1 mm.

    Raises:
        DialectError: If the array is not ``(N, 2)``.
        UsageError: If a coordinate is not finite.
    """
    import numpy as np

    arr = np.asarray(xy_mm, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise DialectError(f"router vertices must be an (N, 2) array of mm, got shape {arr.shape}")
    out = matlab_round(arr * 10.0)
    out.flags.writeable = False
    return out


@dataclass(frozen=True)
class RouterArrays:
    """The arrays the Matlab GUI sends for one stroke (Angel-11 §3, R2).

    Attributes:
        xy: ``(2, N) int64``, read-only: absolute vertices, 0.1 mm; row 0 is x.
        lxy: ``(2, n) int64``, read-only: ``|Δx|``, ``|Δy|`` per segment, 0.1 mm.
        velxy: ``(2, n) int64``, read-only: signed speeds per segment, encoder
            counts per 5 ms (positive = towards larger coordinates).
        speed: The major-axis speed used, counts per 5 ms.
    """

    xy: IntArray
    lxy: IntArray
    velxy: IntArray
    speed: int

    @property
    def n(self) -> int:
        """Number of segments (``size_of_array`` in the GUI), ``N − 1``."""
        return int(self.lxy.shape[1])

    @property
    def first_point(self) -> tuple[int, int]:
        """First vertex ``(x, y)``, 0.1 mm (``first_pointx``, ``first_pointy``)."""
        return int(self.xy[0, 0]), int(self.xy[1, 0])

    @property
    def increments(self) -> IntArray:
        """Signed increments ``(Δx, Δy)`` per segment: ``(2, n) int64``, 0.1 mm, read-only."""
        import numpy as np

        out = np.diff(self.xy, axis=1)
        out.flags.writeable = False
        return out


def _vertices(xy_01mm: npt.ArrayLike) -> IntArray:
    """Validate ``(N, 2)`` whole-number vertices and return them as ``(2, N) int64``."""
    import numpy as np

    arr = np.asarray(xy_01mm)
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 2:
        raise DialectError(
            f"router vertices must be an (N, 2) array with N >= 2 points, got shape {arr.shape}"
        )
    if not np.issubdtype(arr.dtype, np.integer):
        as_float = arr.astype(np.float64)
        if not (np.all(np.isfinite(as_float)) and np.all(as_float == np.round(as_float))):
            raise DialectError(
                "router vertices must be whole 0.1 mm units; convert mm with points_01mm()"
            )
    return np.ascontiguousarray(arr.astype(np.int64).T)


def router_arrays(xy_01mm: npt.ArrayLike, *, speed: int = DEFAULT_SPEED) -> RouterArrays:
    """Build ``xy``, ``lxy`` and ``velxy`` exactly as the GUI's ``axes5_CreateFcn`` does.

    Angel-11 §3 (verbatim Matlab, L4444–L4515) and R2. For the 11-point star of
    L3196 this gives the ``lxy`` and ``velxy`` printed at L3212–L3228.

    Args:
        xy_01mm: ``(N, 2)`` vertices in whole 0.1 mm units, ``N >= 2`` (one row
            per point, x then y).
        speed: Major-axis speed, encoder counts per 5 ms (R7), ``> 0``.

    Returns:
        The arrays, each read-only ``int64``.

    Raises:
        DialectError: If the vertices are not ``(N, 2)`` with ``N >= 2`` or not
            whole numbers.
        UsageError: If ``speed`` is not a positive integer.
    """
    import numpy as np

    if isinstance(speed, bool) or not isinstance(speed, int | np.integer) or speed <= 0:
        raise UsageError(
            f"router speed must be a positive integer (counts per 5 ms), got {speed!r}"
        )
    xy = _vertices(xy_01mm)
    d = np.diff(xy, axis=1)
    ax, ay = np.abs(d[0]).astype(np.float64), np.abs(d[1]).astype(np.float64)
    vel = np.full((2, d.shape[1]), float(speed))
    x_major, y_major = ax > ay, ay > ax
    with np.errstate(divide="ignore"):  # |minor| = 0: factor = Inf, speed/Inf = 0 as in Matlab
        vel[1, x_major] = float(speed) / (ax[x_major] / ay[x_major])
        vel[0, y_major] = float(speed) / (ay[y_major] / ax[y_major])
    vel = np.where(d < 0, -vel, vel)
    velxy = matlab_round(vel)
    lxy = np.abs(d)
    for arr in (xy, lxy, velxy):
        arr.flags.writeable = False
    return RouterArrays(xy=xy, lxy=lxy, velxy=velxy, speed=int(speed))
