"""Arc interpolators of the GMM PIC controller on the step lattice (seed-000 §4.3–4.7).

Three algorithms of seed-000, all quadrant by quadrant on magnitudes:

- :func:`dsm_arc` — Direct Search Method, annex A.6 (the selected one, ``pic-mmh``);
  :func:`dsm_arc_reference` is a literal, unoptimised transcription.
- :func:`staircase_arc` — "escalones", annex A.5 (one axis per iteration).
- :func:`circular_dda_arc` — circular DDA, annex A.4.

Common conventions (all coordinates absolute, integer steps; Y up):

- ``clockwise=True`` is G02, ``False`` G03 (seed-000 §4.6).
- Radius: R² = (x0 − cx)² + (y0 − cy)² from the start point, so D₀ = 0 at the
  start (the thesis' "rutina de cálculos" that derives it is not shown). The
  circular DDA needs an integer RADIO register: R rounded to the nearest step.
- ``start == end`` is a full circle; otherwise the arc runs in the given sense
  to the end point, through as many quadrants as needed (a start and end on the
  same ray from the centre is also a full circle, as in GRBL).
- Quadrants: a point on an axis belongs, at the start, to the quadrant the motion
  enters and, at the end, to the quadrant it leaves. In a quadrant where |x|
  grows ("odd" CUADRANTE of G02, the ``CUAD1`` initialisation) ΔX = 2|x| + 1,
  ΔY = −2|y| + 1; where |x| shrinks the roles swap (``CUAD2``); G03 swaps them.
  A quadrant that is not the last ends on the axis (|y| = 0 resp. |x| = 0).
- End of the last quadrant (DSM, staircase): the *driven* coordinate is x when
  |x₁| ≤ |y₁| (end point nearer the Y axis, where x changes fastest) and y
  otherwise; the interpolator stops when the driven magnitude reaches the end
  point's (or the quadrant's axis is reached). The circular DDA stops when its
  two step counters reach the end point's offsets (A.4 caps the counters).
- Closing steps: if the interpolator stopped off the end point (lattice path not
  through it, or an end point off the circle), the remaining difference is
  issued corte-recto style (diagonal, then one axis), one step per iteration. When
  start and end lie on the same circle this is rare and short (sampled: at most
  1 step for the DSM, 2 for the staircase) and stays within the radial error
  bounds; it keeps the absolute position exact for the next block. Quadrant switches are
  not iterations (Tabla 7 counts: staircase 240 = 8R at R = 30).

Termination: in each quadrant one magnitude is monotone towards its stop value
and the other cannot move forever without the decision variable forcing the
first one (|D| grows by ≥ 1 per such move), so every loop ends. The circular DDA
leaves a quadrant early if a register that still must pulse is 0 ("stall",
only possible for inconsistent end points); closing steps then finish.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError, UsageError
from camtool.verify.steparray import StepArray, concatenate, empty_steps, freeze

# Move codes of the inner loops, in magnitudes: X step, Y step, both, none.
_X, _Y, _XY, _NONE = 0, 1, 2, 3

Quadrant = tuple[int, int]
"""Quadrant as the signs ``(su, sv)`` of x − cx and y − cy inside it."""


def _as_int(name: str, value: int) -> int:
    try:
        return operator.index(value)
    except TypeError:
        raise UsageError(f"{name} must be an integer number of steps, got {value!r}") from None


def _sgn(v: int) -> int:
    return (v > 0) - (v < 0)


def _depart(u: int, v: int, cw: bool) -> Quadrant:
    """Quadrant the motion enters from offset ``(u, v)`` (seed-000 §4.6 order)."""
    if u and v:
        return (_sgn(u), _sgn(v))
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
    out[: abs(du), 0] = _sgn(du)
    out[: abs(dv), 1] = _sgn(dv)
    return out


def _rows(codes: bytearray, ux: int, uy: int) -> npt.NDArray[np.int8]:
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
    vals = [_as_int(n, v) for n, v in zip(names, (x0, y0, x1, y1, cx, cy), strict=True)]
    u0, v0 = vals[0] - vals[4], vals[1] - vals[5]
    u1, v1 = vals[2] - vals[4], vals[3] - vals[5]
    r2 = u0 * u0 + v0 * v0
    if r2 == 0:
        raise InputError(f"arc start ({x0}, {y0}) is its centre: radius 0")
    return u0, v0, u1, v1, r2


def _search_arc(args: tuple[int, ...], clockwise: bool, run: _Runner) -> StepArray:
    """Drive a decision-variable runner (DSM or staircase) over the planned quadrants."""
    u0, v0, u1, v1, _r2 = _arc_checked(*args)
    cw = bool(clockwise)
    plan = _plan(u0, v0, u1, v1, cw)
    u, v, d = u0, v0, 0  # D0 = 0: R² is taken from the start point
    parts = []
    for i, q in enumerate(plan):
        gx = 1 if _grows_x(q, cw) else -1
        x, y = abs(u), abs(v)
        sx, sy = _stops(gx, x, y, abs(u1), abs(v1), i == len(plan) - 1)
        codes = bytearray()
        x, y, d = run(x, y, d, gx, -gx, sx, sy, codes)
        parts.append(_rows(codes, q[0] * gx, -q[1] * gx))
        u, v = q[0] * x, q[1] * y
    parts.append(_closing(u1 - u, v1 - v))
    return concatenate(parts)


def dsm_arc(x0: int, y0: int, x1: int, y1: int, cx: int, cy: int, clockwise: bool) -> StepArray:
    """Arc by the Direct Search Method of the GMM PIC (seed-000 §4.5, annex A.6).

    Each iteration takes, among the moves "growing axis", "shrinking axis" and
    both, the one with the least |D| (D = x² + y² − R², Eqs. 3.4–3.14), ties to
    single-axis moves exactly as the annex code. Conventions (R from the start,
    quadrants, end rule, closing steps): see the module docstring.
    Golden (seed-000 §4.7, Tabla 7): full circle R = 30 → 168 iterations, radial
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
    """Arc by the incremental "escalones" method (seed-000 §4.4, annex A.5).

    One axis per iteration: inside or on the circle (D ≤ 0, as the annex puts
    D = 0) the magnitude that grows in this quadrant steps, outside the one that
    shrinks. Conventions: see the module docstring. Golden (seed-000 §4.7,
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
    """Arc by the circular DDA of the GMM PIC (seed-000 §4.3, annex A.4).

    The overflow threshold is the radius (RADIO, R rounded to a whole step); the
    projections are stored crosswise and updated as the tool moves; each axis
    counter stops at the steps left to the quadrant's axis point ((R, 0) or
    (0, R) in magnitudes) or, in the last quadrant, to the end point. Iterations
    without a pulse are rows ``(0, 0)``. Conventions: see the module docstring.
    Golden (seed-000 §4.7, Tabla 7): full circle R = 30 → 188 iterations.

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
        rows = _rows(codes, q[0] * gx, -q[1] * gx)
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
