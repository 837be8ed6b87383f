"""Line interpolators of the verifier, in integer motor steps, plus mm → steps rounding.

Every interpolator is a pure function returning a *step array* (see
:mod:`camtool.verify.steparray`): a read-only ``(N, 2) int8`` array, one row per
interpolator iteration, rows in ``{-1, 0, +1}²``. Positive ``dx``/``dy`` give
``+1`` steps, negative give ``-1``.

Line interpolators here (one per machine family in DESIGN.md):

- :func:`dda_line` — seed-000 §4.2, annex A.3 (``pic-mmh``), vectorised with a
  closed form; :func:`dda_line_reference` is the literal register loop.
- :func:`accumulator_dda_line` — seed-004 §4.1, Table 8 (``valcnc``).
- :func:`corte_recto_line` — seed-003 §4.1–4.2 (``i8751``).
- :func:`bresenham_line` — GRBL's stepper Bresenham (``grbl``, ``linuxcnc``).

mm → steps rounding is :func:`~camtool.verify.quantize.steps_from_mm`.
Arc interpolators live in :mod:`camtool.verify.interpolators_arc` (DSM,
staircase, circular DDA on the step lattice) and chord generators in
:mod:`camtool.verify.interpolators_chord`; both are re-exported here.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.verify.interpolators_arc import circular_dda_arc, dsm_arc, staircase_arc
from camtool.verify.interpolators_chord import (
    chord_sagitta,
    flashcut_arc_points,
    grbl_arc_points,
    grbl_arc_segments,
    valcnc_arc_points,
)
from camtool.verify.quantize import steps_from_mm
from camtool.verify.steparray import StepArray, concatenate, empty_steps, freeze

__all__ = [
    "accumulator_dda_line",
    "accumulator_dda_reference",
    "accumulator_dda_table",
    "bresenham_line",
    "bresenham_reference",
    "chord_sagitta",
    "circular_dda_arc",
    "corte_recto_line",
    "corte_recto_max_deviation",
    "corte_recto_reference",
    "dda_iterations",
    "dda_line",
    "dda_line_reference",
    "dsm_arc",
    "flashcut_arc_points",
    "grbl_arc_points",
    "grbl_arc_segments",
    "polyline_steps",
    "staircase_arc",
    "steps_from_mm",
    "valcnc_arc_points",
]

_TIE_WINDOW = 1e-7
"""Half-width of the window around an integer in which the float estimate of the
DDA overflow count is re-checked with exact integer arithmetic."""


def _as_int(name: str, value: int) -> int:
    """Return ``value`` as a Python int (numpy integers accepted).

    Raises:
        UsageError: If ``value`` is not an integer (e.g. a float).
    """
    try:
        return operator.index(value)
    except TypeError:
        raise UsageError(f"{name} must be an integer number of steps, got {value!r}") from None


def _rows(sx: int, sy: int, kx: npt.NDArray[np.int64], ky: npt.NDArray[np.int64]) -> StepArray:
    """Step array from cumulative per-axis step counts ``(N,) int64`` and signs ±1/0."""
    out = np.empty((len(kx), 2), dtype=np.int8)
    for col, k, s in ((0, kx, sx), (1, ky, sy)):
        if len(k):
            out[0, col] = k[0] * s
            a, b = (k[1:], k[:-1]) if s >= 0 else (k[:-1], k[1:])  # sign by operand order
            np.subtract(a, b, out=out[1:, col], casting="unsafe")
    return freeze(out)


def _sign(v: int) -> int:
    return (v > 0) - (v < 0)


# --------------------------------------------------------------------------- DDA, seed-000


def dda_iterations(dx: int, dy: int) -> int:
    """Number of iterations of the seed-000 A.3 line DDA: ``floor(HIPO) + 1``.

    Every axis with a non-zero projection P overflows for the last time in the
    first iteration n with ``n·P > P·HIPO``, i.e. ``n = floor(HIPO) + 1``; a
    zero move has no iterations. Source: seed-000 §4.2 (Eq. 3.3, code A.3).

    Args:
        dx: X move, steps (sign ignored).
        dy: Y move, steps (sign ignored).

    Returns:
        Iteration count, ``0`` for ``(0, 0)``.
    """
    s = _as_int("dx", dx) ** 2 + _as_int("dy", dy) ** 2
    return 0 if s == 0 else math.isqrt(s) + 1


def _dda_counts(p: int, s: int, n: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """Overflow count of one DDA axis after iterations ``n`` (``(N,) int64``, 1-based).

    With register Q starting at 0, ``Q += P`` per iteration and one subtraction of
    HIPO = √s whenever ``Q > HIPO`` (strict), the invariant ``0 < Q ≤ HIPO``
    holds, so the count is ``k(n) = ceil(n·P/HIPO) − 1``: the largest k with
    ``k²·s < n²·P²``. Exact integer maths decides every tie.
    """
    if p == 0:
        return np.zeros(len(n), dtype=np.int64)
    h = math.isqrt(s)
    if h * h == s:  # HIPO is an integer: ties n·P = k·HIPO are real, stay in integers
        return (n * p - 1) // h
    # HIPO irrational: n·P/HIPO is never an integer; re-check near-ties exactly
    t = n * (p / math.sqrt(s))
    k = t.astype(np.int64)  # floor, t > 0
    for i in np.flatnonzero(np.abs((t - k) - 0.5) > 0.5 - _TIE_WINDOW):
        nn = int(n[i])
        k[i] = math.isqrt((nn * nn * p * p - 1) // s)
    # no cap needed: k(N) = P exactly at N = floor(HIPO) + 1, so ContadorX never passes PX
    return k


def dda_line(dx: int, dy: int) -> StepArray:
    """Linear DDA of the GMM PIC controller, vectorised (seed-000 §4.2, annex A.3).

    Projection registers ``PX = |dx|``, ``PY = |dy|``; each iteration adds them
    to accumulators QX, QY (starting at 0, no half preload); an accumulator that
    is strictly greater than ``HIPO = √(PX² + PY²)`` (Eq. 3.3) loses HIPO and
    pulses its axis, unless its counter already reached its projection. Both
    axes may pulse in the same iteration. Iterations without a pulse are rows
    ``(0, 0)``. HIPO is taken as the exact real square root (the thesis does not
    say how the PIC stores it); the closed form of :func:`_dda_counts` and the
    loop of :func:`dda_line_reference` agree exactly.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array ``(floor(HIPO) + 1, 2) int8``; ``(0, 2)`` for a zero move.
        Golden: (3, 4) → ``- XY Y XY - XY`` (seed-000 §4.2).

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    px, py = abs(dx), abs(dy)
    s = px * px + py * py
    if s == 0:
        return empty_steps()
    n = np.arange(1, math.isqrt(s) + 2, dtype=np.int64)
    return _rows(_sign(dx), _sign(dy), _dda_counts(px, s, n), _dda_counts(py, s, n))


def dda_line_reference(dx: int, dy: int) -> StepArray:
    """Literal register loop of the seed-000 A.3 DDA; same result as :func:`dda_line`.

    Plain Python, one pass per iteration, kept as the executable reading of
    annex A.3 and as the speed baseline of the benchmark. The register
    ``QX = ax − CX·HIPO`` is held as the integer ``ax`` (the sum of PX so far)
    so that ``QX > HIPO ⟺ ax² > (CX + 1)²·(PX² + PY²)`` is decided exactly.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array, identical to ``dda_line(dx, dy)``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    px, py, sx, sy = abs(dx), abs(dy), _sign(dx), _sign(dy)
    s = px * px + py * py
    ax = ay = cx = cy = 0
    rows: list[tuple[int, int]] = []
    while cx < px or cy < py:
        ox = oy = 0
        ax += px  # QX = QX + PX
        if cx < px and ax * ax > (cx + 1) * (cx + 1) * s:  # QX > HIPO
            cx += 1
            ox = sx
        ay += py  # QY = QY + PY
        if cy < py and ay * ay > (cy + 1) * (cy + 1) * s:  # QY > HIPO
            cy += 1
            oy = sy
        rows.append((ox, oy))
    return freeze(rows)


# ----------------------------------------------------------- accumulator DDA, seed-004


def _major_minor(dx: int, dy: int) -> tuple[int, int, bool]:
    """``(major, minor, x_is_major)`` magnitudes; X is the major axis on a tie."""
    ax, ay = abs(dx), abs(dy)
    return (ax, ay, True) if ax >= ay else (ay, ax, False)


def accumulator_dda_table(dx: int, dy: int) -> npt.NDArray[np.int64]:
    """Iteration table of the ValCNC accumulator DDA, as Table 8 of seed-004 §4.1.

    K counts the major-axis steps; CUENTA accumulates the minor move each
    iteration and, when ``CUENTA >= major``, the minor axis steps and CUENTA
    loses ``major``. Closed form: after iteration n the minor axis travelled
    ``floor(n·minor/major)`` and ``CUENTA = n·minor mod major``.

    Args:
        dx: X move, steps, signed (the table shows magnitudes).
        dy: Y move, steps, signed.

    Returns:
        Read-only ``(max(|dx|, |dy|), 4) int64`` array with columns
        (iteration, |X| travelled, |Y| travelled, CUENTA), steps.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    major, minor, x_major = _major_minor(dx, dy)
    n = np.arange(1, major + 1, dtype=np.int64)
    mnr = (n * minor) // major if major else n
    table = np.empty((major, 4), dtype=np.int64)
    table[:, 0] = n
    table[:, 1] = n if x_major else mnr
    table[:, 2] = mnr if x_major else n
    table[:, 3] = (n * minor) % major if major else n
    table.flags.writeable = False
    return table


def accumulator_dda_line(dx: int, dy: int) -> StepArray:
    """Line of the ValCNC PIC18F4550 firmware (seed-004 §4.1, Table 8), vectorised.

    One iteration per major-axis step (the major axis steps every iteration; X is
    major on a tie); the accumulator starts at 0 and the comparison is ``>=``, so
    the minor axis lags and the staircase lies on one side of the ideal line.
    Each iteration costs one 166.667 µs delay (seed-004 §4.3).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array ``(max(|dx|, |dy|), 2) int8``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    major, minor, x_major = _major_minor(dx, dy)
    n = np.arange(1, major + 1, dtype=np.int64)
    mnr = (n * minor) // major if major else n
    kx, ky = (n, mnr) if x_major else (mnr, n)
    return _rows(_sign(dx), _sign(dy), kx, ky)


def accumulator_dda_reference(dx: int, dy: int) -> StepArray:
    """Plain loop of the seed-004 §4.1 accumulator DDA; same result as the vectorised one.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array identical to ``accumulator_dda_line(dx, dy)``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    major, minor, x_major = _major_minor(dx, dy)
    sx, sy = _sign(dx), _sign(dy)
    cuenta = 0
    rows: list[tuple[int, int]] = []
    for _k in range(major):
        cuenta += minor
        step_minor = cuenta >= major
        if step_minor:
            cuenta -= major
        rows.append((sx, sy * step_minor) if x_major else (sx * step_minor, sy))
    return freeze(rows)


# ------------------------------------------------------------------ Bresenham (GRBL)


def _bresenham_counts(
    m: int, big: int, n: npt.NDArray[np.int64], amass: bool
) -> npt.NDArray[np.int64]:
    """Steps of an axis with ``m`` steps after ``n`` step events of a ``big``-event block."""
    if amass:  # counter = big/2 exactly (block counts pre-scaled by 2^MAX_AMASS_LEVEL)
        return (big + 2 * n * m - 1) // (2 * big)
    return (big // 2 + n * m - 1) // big


def bresenham_line(dx: int, dy: int, *, amass: bool = True) -> StepArray:
    """Line as GRBL 1.1's stepper executes it: Bresenham over the block's step events.

    One iteration (step event) per step of the major axis. Each axis counter
    starts at half the event count and gains the axis' step count per event; the
    axis pulses when its counter is strictly greater than the event count, which
    then is subtracted (grbl ``stepper.c``). GRBL 1.1 pre-scales block counts by
    ``2^MAX_AMASS_LEVEL`` when AMASS is compiled in (the default), which makes
    the initial counter exactly half the event count (``amass=True``); without
    AMASS it is ``event_count >> 1``. The minor axis then sits on the lattice
    point nearest the line (ties go to the lower count). LinuxCNC's step
    generator also follows the commanded position to the nearest step, so this
    model serves ``linuxcnc`` too. AMASS's finer time slicing at low rates is
    not modelled (it changes timing, not the visited positions).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.
        amass: Model GRBL built with ``ADAPTIVE_MULTI_AXIS_STEP_SMOOTHING``.

    Returns:
        Step array ``(max(|dx|, |dy|), 2) int8``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    big = max(abs(dx), abs(dy))
    if big == 0:
        return empty_steps()
    n = np.arange(1, big + 1, dtype=np.int64)
    kx = _bresenham_counts(abs(dx), big, n, amass)
    ky = _bresenham_counts(abs(dy), big, n, amass)
    return _rows(_sign(dx), _sign(dy), kx, ky)


def bresenham_reference(dx: int, dy: int, *, amass: bool = True) -> StepArray:
    """Plain counter loop of :func:`bresenham_line` (GRBL ``stepper.c`` logic).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.
        amass: As in :func:`bresenham_line`.

    Returns:
        Step array identical to ``bresenham_line(dx, dy, amass=amass)``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    scale = 2 if amass else 1  # AMASS: counts doubled so that the half is exact
    big = max(abs(dx), abs(dy)) * scale
    mx, my, sx, sy = abs(dx) * scale, abs(dy) * scale, _sign(dx), _sign(dy)
    cx = cy = big >> 1
    rows: list[tuple[int, int]] = []
    for _event in range(big // scale):
        ox = oy = 0
        cx += mx
        if cx > big:
            cx -= big
            ox = sx
        cy += my
        if cy > big:
            cy -= big
            oy = sy
        rows.append((ox, oy))
    return freeze(rows)


# ----------------------------------------------------------------------- polylines


def polyline_steps(
    points: npt.ArrayLike, line: Callable[[int, int], StepArray] = dda_line
) -> StepArray:
    """Execute a polyline of step-lattice points with a line interpolator.

    How chord arcs (seed-001 §4.4, seed-004 §4.2, GRBL) reach the motors: each
    pair of consecutive points is one line move.

    Args:
        points: ``(N, 2)`` integers, steps, absolute; the first row is the start.
        line: Line interpolator, e.g. :func:`dda_line` or :func:`accumulator_dda_line`.

    Returns:
        Step array: the iterations of every line, in order.

    Raises:
        UsageError: If ``points`` is not an ``(N, 2)`` integer array.
    """
    pts = np.asarray(points)
    if pts.ndim != 2 or pts.shape[1] != 2 or not np.issubdtype(pts.dtype, np.integer):
        raise UsageError(f"points must be an (N, 2) integer array of steps, got {pts.dtype}")
    moves = np.diff(pts.astype(np.int64), axis=0)
    return concatenate([line(int(a), int(b)) for a, b in moves])


# --------------------------------------------------------------- corte recto, seed-003


def corte_recto_line(dx: int, dy: int) -> StepArray:
    """Line by "corte recto" of the 8751 interface (seed-003 §4.1–4.2, RESTA/RUT2/GIRA1).

    Both motors step together ``min(|dx|, |dy|)`` times, then the motor with
    more steps continues alone for the difference. The tool goes
    ``(0, 0) → (b, b) → (a, b)`` (signs by direction), not along the segment.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array ``(max(|dx|, |dy|), 2) int8``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    out = np.zeros((max(abs(dx), abs(dy)), 2), dtype=np.int8)
    out[: abs(dx), 0] = _sign(dx)
    out[: abs(dy), 1] = _sign(dy)
    return freeze(out)


def corte_recto_reference(dx: int, dy: int) -> StepArray:
    """Plain loop of the 8751 firmware's RUT2 (diagonal) then GIRA1 (rest) loops.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array identical to ``corte_recto_line(dx, dy)``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    sx, sy = _sign(dx), _sign(dy)
    m = min(abs(dx), abs(dy))
    diff = abs(abs(dx) - abs(dy))
    rows = [(sx, sy)] * m
    rows += [(sx, 0) if abs(dx) > abs(dy) else (0, sy)] * diff
    return freeze(rows)


def corte_recto_max_deviation(dx: int, dy: int) -> float:
    """Largest distance of the corte-recto path from the ideal segment, in steps.

    ``e = b·(a − b)/√(a² + b²)`` with ``a ≥ b`` the step magnitudes, reached at
    the corner ``(b, b)`` (seed-003 §4.2, derived there); 0 for axis-parallel and
    45° moves. Golden: (100, 50) → 22.36 steps (seed-003 §9 R10).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Deviation in steps (multiply by mm/step for mm), ``>= 0``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    a, b, _ = _major_minor(_as_int("dx", dx), _as_int("dy", dy))
    return 0.0 if a == 0 else b * (a - b) / math.hypot(a, b)
