"""The verifier's generic interpolators, in integer motor steps, named by algorithm.

Design notes: docs/internals.md, ``camtool/verify/interpolators.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError, UsageError
from camtool.model.program import ArcMove
from camtool.model.shapes import chord_count, distance
from camtool.verify import dda
from camtool.verify.steparray import StepArray, concatenate, empty_steps, freeze


def freeze_view(rows: npt.NDArray[np.int8]) -> StepArray:
    """``rows`` (an ``(N, 2) int8`` view) marked read-only, not copied."""
    rows.flags.writeable = False
    return rows


# --------------------------------------------------------------------------- DDA, UNAM-GMM


# ----------------------------------------------------------- accumulator DDA, Munoz-22


def accumulator_dda_line(dx: int, dy: int) -> StepArray:
    """Line of the ValCNC PIC18F4550 firmware (Munoz-22 §4.1, Table 8), vectorised.

    One iteration per major-axis step (the major axis steps every iteration; X is
    major on a tie); the accumulator starts at 0 and the comparison is ``>=``, so
    the minor axis lags and the staircase lies on one side of the ideal line.
    Each iteration costs one 166.667 µs delay (Munoz-22 §4.3).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array ``(max(|dx|, |dy|), 2) int8``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    major, minor, x_major = dda._major_minor(dx, dy)
    n = np.arange(1, major + 1, dtype=np.int64)
    mnr = (n * minor) // major if major else n
    kx, ky = (n, mnr) if x_major else (mnr, n)
    return dda._rows(dda._sign(dx), dda._sign(dy), kx, ky)


def accumulator_dda_reference(dx: int, dy: int) -> StepArray:
    """Plain loop of the Munoz-22 §4.1 accumulator DDA; same result as the vectorised one.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array identical to ``accumulator_dda_line(dx, dy)``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    major, minor, x_major = dda._major_minor(dx, dy)
    sx, sy = dda._sign(dx), dda._sign(dy)
    cuenta = 0
    rows: list[tuple[int, int]] = []
    for _k in range(major):
        cuenta += minor
        step_minor = cuenta >= major
        if step_minor:
            cuenta -= major
        rows.append((sx, sy * step_minor) if x_major else (sx * step_minor, sy))
    return freeze(rows)


# ------------------------------------------------------------------------ Bresenham


def _bresenham_counts(
    m: int | npt.NDArray[np.int64],
    big: int | npt.NDArray[np.int64],
    n: npt.NDArray[np.int64],
    amass: bool,
) -> npt.NDArray[np.int64]:
    """Steps of an axis with ``m`` steps after ``n`` step events of a ``big``-event block.

    Integers or arrays of one length each (every line's own ``m`` and ``big``).
    """
    if amass:  # counter = big/2 exactly (block counts pre-scaled by 2^MAX_AMASS_LEVEL)
        return np.asarray((big + 2 * n * m - 1) // (2 * big), dtype=np.int64)
    return np.asarray((big // 2 + n * m - 1) // big, dtype=np.int64)


def bresenham_line(dx: int, dy: int, *, amass: bool = True) -> StepArray:
    """Line as GRBL 1.1's stepper executes it: Bresenham over the block's step events.

    One iteration (step event) per step of the major axis. Each axis counter
    starts at half the event count and gains the axis' step count per event; the
    axis pulses when its counter is strictly greater than the event count, which
    then is subtracted (grbl ``stepper.c``). GRBL 1.1 pre-scales block counts by
    ``2^MAX_AMASS_LEVEL`` when AMASS is compiled in (the default), which makes
    the initial counter exactly half the event count (``amass=True``); without
    AMASS it is ``event_count >> 1``. The minor axis then sits on the lattice
    point nearest the line (ties go to the lower count): it also models a step
    generator that follows the commanded position to the nearest step. AMASS's
    finer time slicing at low rates is not modelled (it changes timing, not the
    visited positions).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.
        amass: Model GRBL built with ``ADAPTIVE_MULTI_AXIS_STEP_SMOOTHING``.

    Returns:
        Step array ``(max(|dx|, |dy|), 2) int8``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    big = max(abs(dx), abs(dy))
    if big == 0:
        return empty_steps()
    jit = dda.compiled(big)
    if jit is not None:  # the same integers (camtool.accel.kernels)
        rows = np.empty((big, 2), dtype=np.int8)
        jit.bresenham_rows(np.array([dx]), np.array([dy]), amass, rows)
        return freeze(rows)
    n = np.arange(1, big + 1, dtype=np.int64)
    kx = _bresenham_counts(abs(dx), big, n, amass)
    ky = _bresenham_counts(abs(dy), big, n, amass)
    return dda._rows(dda._sign(dx), dda._sign(dy), kx, ky)


def bresenham_lines(
    dx: npt.NDArray[np.int64], dy: npt.NDArray[np.int64], *, amass: bool = True
) -> tuple[StepArray, npt.NDArray[np.int64]]:
    """:func:`bresenham_line` of many lines at once (the chords of an arc), the same rows.

    Args:
        dx: ``(L,)`` X moves, steps, signed.
        dy: ``(L,)`` Y moves, steps, signed.
        amass: As in :func:`bresenham_line`.

    Returns:
        The lines' rows one after the other, ``(sum of max(|dx|, |dy|), 2) int8``, and
        ``(L,)`` the first row of each line (a zero move has none: the next line's).
    """
    dx, dy = np.asarray(dx, dtype=np.int64), np.asarray(dy, dtype=np.int64)
    big = np.maximum(np.abs(dx), np.abs(dy))
    first = np.cumsum(big) - big
    total = int(first[-1] + big[-1]) if len(big) else 0
    jit = dda.compiled(total)
    if jit is not None:  # the same integers, line by line (camtool.accel.kernels)
        rows = np.empty((total, 2), dtype=np.int8)
        jit.bresenham_rows(dx, dy, amass, rows)
        return rows, first
    line = np.repeat(np.arange(len(big)), big)
    n = np.arange(len(line), dtype=np.int64) - first[line] + 1  # the step event, from 1
    events = big[line]
    out = np.empty((len(line), 2), dtype=np.int8)
    for col, d in ((0, dx), (1, dy)):
        k = _bresenham_counts(np.abs(d)[line], events, n, amass)
        before = np.empty_like(k)
        before[1:] = k[:-1]
        before[n == 1] = 0  # each line's counter starts anew
        np.multiply(k - before, np.sign(d)[line], out=out[:, col], casting="unsafe")
    return out, first


def bresenham_line_rows(dx: int, dy: int) -> int:
    """How many rows :func:`bresenham_line` ``(dx, dy)`` gives, without making them.

    One row per step event, ``max(|dx|, |dy|)``, every pulse the way of ``d``; with
    AMASS (GRBL's default build) each axis pulses ``|d|`` times.
    ``tests/verify/test_count_rows.py`` checks both against the rows.
    """
    return max(abs(dx), abs(dy))


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
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    scale = 2 if amass else 1  # AMASS: counts doubled so that the half is exact
    big = max(abs(dx), abs(dy)) * scale
    mx, my, sx, sy = abs(dx) * scale, abs(dy) * scale, dda._sign(dx), dda._sign(dy)
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
    points: npt.ArrayLike, line: Callable[[int, int], StepArray] = dda.dda_line
) -> StepArray:
    """Execute a polyline of step-lattice points with a line interpolator.

    How chord arcs (Yanez-07 §4.4, Munoz-22 §4.2, the ``chords`` arc) reach the motors: each
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


# --------------------------------------------------------------- corte recto, Intf8751


def corte_recto_line(dx: int, dy: int) -> StepArray:
    """Line by "corte recto" of the 8751 interface (Intf8751 §4.1–4.2, RESTA/RUT2/GIRA1).

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
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    out = np.zeros((max(abs(dx), abs(dy)), 2), dtype=np.int8)
    out[: abs(dx), 0] = dda._sign(dx)
    out[: abs(dy), 1] = dda._sign(dy)
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
    dx, dy = dda._as_int("dx", dx), dda._as_int("dy", dy)
    sx, sy = dda._sign(dx), dda._sign(dy)
    m = min(abs(dx), abs(dy))
    diff = abs(abs(dx) - abs(dy))
    rows = [(sx, sy)] * m
    rows += [(sx, 0) if abs(dx) > abs(dy) else (0, sy)] * diff
    return freeze(rows)


def corte_recto_max_deviation(dx: int, dy: int) -> float:
    """Largest distance of the corte-recto path from the ideal segment, in steps.

    ``e = b·(a − b)/√(a² + b²)`` with ``a ≥ b`` the step magnitudes, reached at
    the corner ``(b, b)`` (Intf8751 §4.2, derived there); 0 for axis-parallel and
    45° moves. Golden: (100, 50) → 22.36 steps (Intf8751 §9 R10).

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Deviation in steps (multiply by mm/step for mm), ``>= 0``.

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    a, b, _ = dda._major_minor(dda._as_int("dx", dx), dda._as_int("dy", dy))
    return 0.0 if a == 0 else b * (a - b) / math.hypot(a, b)


# ----------------------------------------------------------------- arcs, UNAM-GMM

# Move codes of the inner loops, in magnitudes: X step, Y step, both, none.
_X, _Y, _XY, _NONE = 0, 1, 2, 3

Quadrant = tuple[int, int]
"""Quadrant as the signs ``(su, sv)`` of x − cx and y − cy inside it."""


def _depart(u: int, v: int, cw: bool) -> Quadrant:
    """Quadrant the motion enters from offset ``(u, v)`` (UNAM-GMM §4.6 order)."""
    if u and v:
        return (dda._sign(u), dda._sign(v))
    if u == 0:  # on the Y axis: CW goes towards +x above the centre
        s = 1 if v > 0 else -1
        return (s, s) if cw else (-s, s)
    s = 1 if u > 0 else -1  # on the X axis: CW goes towards -y right of the centre
    return (s, -s) if cw else (s, s)


def _next(q: Quadrant, cw: bool) -> Quadrant:
    """Next quadrant along the motion: CW is Q1 → Q4 → Q3 → Q2."""
    return (q[1], -q[0]) if cw else (-q[1], q[0])


def _plan(u0: int, v0: int, u1: int, v1: int, cw: bool) -> list[Quadrant]:
    """Quadrants visited from offset ``(u0, v0)`` to ``(u1, v1)``, in order."""
    q, end = _depart(u0, v0, cw), _depart(u1, v1, not cw)
    cross = u0 * v1 - v0 * u1
    ahead = cross < 0 if cw else cross > 0
    plan = [q]
    while plan[-1] != end or (len(plan) == 1 and not ahead):
        plan.append(_next(plan[-1], cw))
    return plan


def _grows_x(q: Quadrant, cw: bool) -> bool:
    """True where |x| grows along the motion (odd CUADRANTE of G02, A.6 ``CUAD1``)."""
    return (q[0] * q[1] > 0) == cw


def _stops(gx: int, x: int, y: int, x1: int, y1: int, last: bool) -> tuple[int, int]:
    """Stop magnitudes ``(stop_x, stop_y)``; -1 never matches (see module docstring)."""
    if not last:
        return (-1, 0) if gx > 0 else (0, -1)
    if x1 <= y1:  # x driven
        reached = x1 <= x if gx > 0 else x1 >= x
        return (x if reached else x1, 0 if gx > 0 else -1)
    reached = y1 >= y if gx > 0 else y1 <= y
    return (-1 if gx > 0 else 0, y if reached else y1)


def _closing(du: int, dv: int) -> npt.NDArray[np.int8]:
    """Corte-recto rows from a position to one ``(du, dv)`` away."""
    out = np.zeros((max(abs(du), abs(dv)), 2), dtype=np.int8)
    out[: abs(du), 0] = dda._sign(du)
    out[: abs(dv), 1] = dda._sign(dv)
    return out


def _code_rows(codes: bytearray, ux: int, uy: int) -> npt.NDArray[np.int8]:
    """Rows ``(N, 2) int8`` of move codes with the quadrant's step signs ``ux``, ``uy``."""
    table = np.array([[ux, 0], [0, uy], [ux, uy], [0, 0]], dtype=np.int8)
    return table[np.frombuffer(bytes(codes), dtype=np.uint8)]


def _dsm_run(
    x: int, y: int, d: int, gx: int, gy: int, sx: int, sy: int, out: bytearray
) -> tuple[int, int, int]:
    """DSM of annex A.6 in one quadrant, on magnitudes; appends move codes to ``out``.

    Candidates |D+ΔX|, |D+ΔY|, |D+ΔX+ΔY|; if D1 > D2 the diagonal wins only when
    D2 > D3, else Y; otherwise the diagonal wins only when D1 > D3, else X (so
    ties go to single-axis moves and D1 = D2 goes to X). Δ += 2 after a step.
    """
    dx, dy = 2 * x * gx + 1, 2 * y * gy + 1
    app = out.append
    while x != sx and y != sy:
        d1 = d + dx
        d2 = d + dy
        d3 = d1 + dy
        a1 = d1 if d1 >= 0 else -d1
        a2 = d2 if d2 >= 0 else -d2
        a3 = d3 if d3 >= 0 else -d3
        if (a2 > a3) if a1 > a2 else (a1 > a3):
            d, dx, dy, x, y = d3, dx + 2, dy + 2, x + gx, y + gy
            app(2)
        elif a1 > a2:
            d, dy, y = d2, dy + 2, y + gy
            app(1)
        else:
            d, dx, x = d1, dx + 2, x + gx
            app(0)
    return x, y, d


def _staircase_run(
    x: int, y: int, d: int, gx: int, gy: int, sx: int, sy: int, out: bytearray
) -> tuple[int, int, int]:
    """Staircase of annex A.5 in one quadrant: D ≤ 0 (inside) moves the growing axis.

    D = x² + y² − R² is kept incrementally (A.5 recomputes it from squares; same value).
    """
    app = out.append
    while x != sx and y != sy:
        if d <= 0:  # grow the growing magnitude (outwards)
            if gx > 0:
                d, x = d + 2 * x + 1, x + 1
                app(0)
            else:
                d, y = d + 2 * y + 1, y + 1
                app(1)
        elif gx > 0:  # shrink the shrinking magnitude (inwards)
            d, y = d - 2 * y + 1, y - 1
            app(1)
        else:
            d, x = d - 2 * x + 1, x - 1
            app(0)
    return x, y, d


_Runner = Callable[[int, int, int, int, int, int, int, bytearray], tuple[int, int, int]]


def _arc_checked(
    x0: int, y0: int, x1: int, y1: int, cx: int, cy: int
) -> tuple[int, int, int, int, int]:
    """Validate integer inputs; return start and end offsets and R²."""
    names = ("x0", "y0", "x1", "y1", "cx", "cy")
    vals = [dda._as_int(n, v) for n, v in zip(names, (x0, y0, x1, y1, cx, cy), strict=True)]
    u0, v0 = vals[0] - vals[4], vals[1] - vals[5]
    u1, v1 = vals[2] - vals[4], vals[3] - vals[5]
    r2 = u0 * u0 + v0 * v0
    if r2 == 0:
        raise InputError(f"arc start ({x0}, {y0}) is its centre: radius 0")
    return u0, v0, u1, v1, r2


def _compiled_runner(run: _Runner, magnitude: int) -> Callable[..., Any] | None:
    """The compiled twin of ``run`` (same moves, rows written directly), or ``None``.

    ``None`` without numba, for a runner without a twin, or when a magnitude is
    large enough that int64 could overflow (the Python loop is exact at any size).
    """
    jit = dda.compiled(8 * magnitude)  # a full circle: up to 8R rows
    if jit is None or magnitude >= jit.SAFE_MAGNITUDE:
        return None
    if run is _dsm_run:
        return jit.dsm_quadrant
    if run is _staircase_run:
        return jit.staircase_quadrant
    return None


def _search_arc(args: tuple[int, ...], clockwise: bool, run: _Runner) -> StepArray:
    """Drive a decision-variable runner (DSM or staircase) over the planned quadrants."""
    u0, v0, u1, v1, _r2 = _arc_checked(*args)
    cw = bool(clockwise)
    plan = _plan(u0, v0, u1, v1, cw)
    u, v, d = u0, v0, 0  # D0 = 0: R² is taken from the start point
    magnitude = max(abs(u0), abs(v0), abs(u1), abs(v1))
    kernel = _compiled_runner(run, magnitude)
    parts = []
    buffer, at = np.empty((0, 2), dtype=np.int8), 0
    if kernel is not None:  # one buffer for every quadrant (a full circle: < 8R rows)
        buffer = np.empty((8 * magnitude + 64, 2), dtype=np.int8)
    for i, q in enumerate(plan):
        gx = 1 if _grows_x(q, cw) else -1
        x, y = abs(u), abs(v)
        sx, sy = _stops(gx, x, y, abs(u1), abs(v1), i == len(plan) - 1)
        if kernel is not None:
            x, y, d, buffer, at = kernel(
                x, y, d, gx, -gx, sx, sy, q[0] * gx, -q[1] * gx, buffer, at
            )
        else:
            codes = bytearray()
            x, y, d = run(x, y, d, gx, -gx, sx, sy, codes)
            parts.append(_code_rows(codes, q[0] * gx, -q[1] * gx))
        u, v = q[0] * x, q[1] * y
    closing = _closing(u1 - u, v1 - v)
    if kernel is not None and len(closing) == 0:
        return freeze_view(buffer[:at])
    if kernel is not None:
        parts.append(buffer[:at])
    parts.append(closing)
    return concatenate(parts)


def dsm_arc(x0: int, y0: int, x1: int, y1: int, cx: int, cy: int, clockwise: bool) -> StepArray:
    """Arc by the Direct Search Method of the GMM PIC (UNAM-GMM §4.5, annex A.6).

    Each iteration takes, among the moves "growing axis", "shrinking axis" and
    both, the one with the least |D| (D = x² + y² − R², Eqs. 3.4–3.14), ties to
    single-axis moves exactly as the annex code. Conventions (R from the start,
    quadrants, end rule, closing steps): see the module docstring.
    Golden (UNAM-GMM §4.7, Tabla 7): full circle R = 30 → 168 iterations, radial
    error ≤ ½ step.

    Args:
        x0: Start x, steps (absolute).
        y0: Start y, steps.
        x1: End x, steps.
        y1: End y, steps.
        cx: Centre x, steps.
        cy: Centre y, steps.
        clockwise: True for G02, False for G03.

    Returns:
        Step array ``(N, 2) int8``, ending exactly at ``(x1, y1)``.

    Raises:
        InputError: If the start point is the centre (radius 0).
        UsageError: If a coordinate is not an integer.
    """
    return _search_arc((x0, y0, x1, y1, cx, cy), clockwise, _dsm_run)


def staircase_arc(
    x0: int, y0: int, x1: int, y1: int, cx: int, cy: int, clockwise: bool
) -> StepArray:
    """Arc by the incremental "escalones" method (UNAM-GMM §4.4, annex A.5).

    One axis per iteration: inside or on the circle (D ≤ 0, as the annex puts
    D = 0) the magnitude that grows in this quadrant steps, outside the one that
    shrinks. Conventions: see the module docstring. Golden (UNAM-GMM §4.7,
    Tabla 7): full circle R = 30 → 240 iterations (8R).

    Args:
        x0: Start x, steps (absolute).
        y0: Start y, steps.
        x1: End x, steps.
        y1: End y, steps.
        cx: Centre x, steps.
        cy: Centre y, steps.
        clockwise: True for G02, False for G03.

    Returns:
        Step array ``(N, 2) int8`` with no diagonal rows except closing steps,
        ending exactly at ``(x1, y1)``.

    Raises:
        InputError: If the start point is the centre (radius 0).
        UsageError: If a coordinate is not an integer.
    """
    return _search_arc((x0, y0, x1, y1, cx, cy), clockwise, _staircase_run)


def _dda_run(
    pa: int, pb: int, na: int, nb: int, radius: int, code: bytes, out: bytearray
) -> tuple[int, int]:
    """Circular DDA of annex A.4 in one quadrant; returns the steps done (growing, shrinking).

    The growing axis is processed first (INTERCIRCULAR1X resp. 4Y). Its register
    ``pa`` holds the shrinking magnitude and ``pb`` the growing one ("X en Py y Y
    en Px"); a growing step increments ``pb``, a shrinking step decrements ``pa``.
    Accumulators start at 0 and overflow strictly above RADIO; counters are
    capped at ``na``/``nb``. ``code`` maps (a-step + 2·b-step) to a move code.
    """
    qa = qb = ca = cb = 0
    app = out.append
    while ca < na or cb < nb:
        if (ca >= na or pa <= 0) and (cb >= nb or pb <= 0):
            break  # stall: nothing can pulse any more (inconsistent end point)
        c = 0
        qa += pa
        if ca < na and qa > radius:
            qa -= radius
            ca += 1
            pb += 1
            c = 1
        qb += pb
        if cb < nb and qb > radius:
            qb -= radius
            cb += 1
            pa -= 1
            c += 2
        app(code[c])
    return ca, cb


_DDA_CODES_GROW_X = bytes((_NONE, _X, _Y, _XY))
_DDA_CODES_GROW_Y = bytes((_NONE, _Y, _X, _XY))


def _round_radius(r2: int) -> int:
    """Nearest integer to √r2 (RADIO register of A.4), exact."""
    r = math.isqrt(r2)
    return r + 1 if r2 - r * r > r else r


def circular_dda_arc(
    x0: int, y0: int, x1: int, y1: int, cx: int, cy: int, clockwise: bool
) -> StepArray:
    """Arc by the circular DDA of the GMM PIC (UNAM-GMM §4.3, annex A.4).

    The overflow threshold is the radius (RADIO, R rounded to a whole step); the
    projections are stored crosswise and updated as the tool moves; each axis
    counter stops at the steps left to the quadrant's axis point ((R, 0) or
    (0, R) in magnitudes) or, in the last quadrant, to the end point. Iterations
    without a pulse are rows ``(0, 0)``. Conventions: see the module docstring.
    Golden (UNAM-GMM §4.7, Tabla 7): full circle R = 30 → 188 iterations.

    Args:
        x0: Start x, steps (absolute).
        y0: Start y, steps.
        x1: End x, steps.
        y1: End y, steps.
        cx: Centre x, steps.
        cy: Centre y, steps.
        clockwise: True for G02, False for G03.

    Returns:
        Step array ``(N, 2) int8``, ending exactly at ``(x1, y1)``.

    Raises:
        InputError: If the start point is the centre (radius 0).
        UsageError: If a coordinate is not an integer.
    """
    u0, v0, u1, v1, r2 = _arc_checked(x0, y0, x1, y1, cx, cy)
    cw = bool(clockwise)
    radius = _round_radius(r2)
    plan = _plan(u0, v0, u1, v1, cw)
    u, v = u0, v0
    parts = []
    for i, q in enumerate(plan):
        gx = 1 if _grows_x(q, cw) else -1
        x, y = abs(u), abs(v)
        if i == len(plan) - 1:
            tx, ty = abs(u1), abs(v1)
        else:
            tx, ty = (radius, 0) if gx > 0 else (0, radius)
        codes = bytearray()
        if gx > 0:  # grow x: PX = |y| drives x, PY = |x| drives y
            _dda_run(y, x, max(0, tx - x), max(0, y - ty), radius, _DDA_CODES_GROW_X, codes)
        else:  # grow y: PY = |x| drives y, PX = |y| drives x
            _dda_run(x, y, max(0, ty - y), max(0, x - tx), radius, _DDA_CODES_GROW_Y, codes)
        rows = _code_rows(codes, q[0] * gx, -q[1] * gx)
        u, v = u + int(rows[:, 0].sum()), v + int(rows[:, 1].sum())
        tu, tv = q[0] * tx, q[1] * ty
        parts += [rows, _closing(tu - u, tv - v)]
        u, v = tu, tv
    return concatenate(parts)


def dsm_arc_reference(
    x0: int, y0: int, x1: int, y1: int, cx: int, cy: int, clockwise: bool
) -> StepArray:
    """Unoptimised transcription of annex A.6; same result as :func:`dsm_arc`.

    Recomputes D1, D2, D3 with ``abs`` and follows the annex branch structure
    (``COMPARAD2COND3``, ``ACTUALIZACONTADORES``) on signed coordinates, one
    tuple per iteration. Kept as the readable reference and benchmark baseline.

    Args:
        x0: Start x, steps (absolute).
        y0: Start y, steps.
        x1: End x, steps.
        y1: End y, steps.
        cx: Centre x, steps.
        cy: Centre y, steps.
        clockwise: True for G02, False for G03.

    Returns:
        Step array identical to ``dsm_arc(...)``.

    Raises:
        InputError: If the start point is the centre (radius 0).
        UsageError: If a coordinate is not an integer.
    """
    u0, v0, u1, v1, _r2 = _arc_checked(x0, y0, x1, y1, cx, cy)
    cw = bool(clockwise)
    plan = _plan(u0, v0, u1, v1, cw)
    u, v, d = u0, v0, 0
    rows: list[tuple[int, int]] = []
    for i, q in enumerate(plan):
        cuad1 = _grows_x(q, cw)  # DSMCIRCULARCUAD1 pattern
        xo, yo = abs(u), abs(v)
        stop_x, stop_y = _stops(1 if cuad1 else -1, xo, yo, abs(u1), abs(v1), i == len(plan) - 1)
        delta_x = 2 * xo + 1 if cuad1 else -2 * xo + 1
        delta_y = -2 * yo + 1 if cuad1 else 2 * yo + 1
        while xo != stop_x and yo != stop_y:
            d1, d2, d3 = abs(d + delta_x), abs(d + delta_y), abs(d + delta_x + delta_y)
            if d1 > d2:  # COMPARAD2COND3
                step_x, step_y = (True, True) if d2 > d3 else (False, True)
            else:
                step_x, step_y = (True, True) if d1 > d3 else (True, False)
            if step_x:
                d, delta_x = d + delta_x, delta_x + 2
            if step_y:
                d, delta_y = d + delta_y, delta_y + 2
            # ACTUALIZACONTADORES: magnitudes per quadrant pattern
            gx = 1 if cuad1 else -1
            xo += gx * step_x
            yo -= gx * step_y
            rows.append((q[0] * gx * step_x, -q[1] * gx * step_y))
        u, v = q[0] * xo, q[1] * yo
    rows += [(int(a), int(b)) for a, b in _closing(u1 - u, v1 - v)]
    return freeze(rows) if rows else empty_steps()


# --------------------------------------------------------------------------- chords

Point = tuple[float, float]
"""A point ``(x, y)`` in mm."""


def freeze_points(points: list[Point] | npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Chord end points as a read-only ``(N, 2) float64`` array, mm."""
    arr = np.array(points, dtype=np.float64).reshape(-1, 2)
    arr.flags.writeable = False
    return arr


def arc_offsets(
    start: Point, end: Point, centre: Point
) -> tuple[float, float, float, float, float]:
    """Start and end offsets from the centre and the radius from the start.

    Raises:
        InputError: If the start point is the centre.
    """
    u0, v0 = start[0] - centre[0], start[1] - centre[1]
    u1, v1 = end[0] - centre[0], end[1] - centre[1]
    r = math.hypot(u0, v0)
    if r == 0.0:
        raise InputError(f"arc start {tuple(start)} is its centre: radius 0")
    return u0, v0, u1, v1, r


def chord_sagitta(radius_mm: float, angle_rad: float) -> float:
    """Largest distance between an arc of ``angle_rad`` and its chord: R(1 − cos(β/2)), mm.

    Args:
        radius_mm: Radius, mm.
        angle_rad: Angle subtended by the chord, rad (sign ignored).

    Returns:
        Sagitta, mm (Munoz-22 §4.2 "chord error per segment").
    """
    return radius_mm * (1.0 - math.cos(abs(angle_rad) / 2.0))


def sagitta_chord_points(start: Point, move: ArcMove, tolerance_mm: float) -> list[Point]:
    """End points of equal chords of an arc within ``tolerance_mm``: the ``sagitta`` chord rule.

    The fewest equal chords whose sagitta is at most ``tolerance_mm``
    (:func:`camtool.model.shapes.chord_count`), radius from the start point; the last point is
    the programmed end. A start equal to the end is a full circle.

    Args:
        start: Arc start, mm.
        move: The arc (end, centre, sense), mm.
        tolerance_mm: Largest chord error, mm, ``> 0``.

    Returns:
        Chord end points ``[(x, y), ...]``, mm, the start not included.
    """
    cx, cy = move.cx, move.cy
    radius = math.hypot(start[0] - cx, start[1] - cy)
    a0 = math.atan2(start[1] - cy, start[0] - cx)
    a1 = math.atan2(move.y - cy, move.x - cx)
    sweep = a1 - a0
    turn = -math.tau if move.clockwise else math.tau
    sweep = sweep % turn or turn
    if distance(start, (move.x, move.y)) > 1e-9 and abs(abs(sweep) - math.tau) < 1e-12:
        sweep = 0.0
    n = chord_count(radius, abs(sweep), tolerance_mm) if radius > 0 else 1
    points = [
        (cx + radius * math.cos(a0 + sweep * k / n), cy + radius * math.sin(a0 + sweep * k / n))
        for k in range(n + 1)
    ]
    points[-1] = (move.x, move.y)
    return points[1:]
