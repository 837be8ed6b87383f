"""Compiled inner loops of the verifier's interpolators (numba).

Design notes: docs/internals.md, ``camtool/accel/kernels.py``.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

SAFE_MAGNITUDE = 1 << 40
"""Largest coordinate magnitude (steps) the compiled arc loops accept: D, Δ and the
squared terms stay far inside int64 (|D| ≤ ~2R, Δ ≤ 2R + 1)."""
SAFE_SQUARE = 1 << 60
"""Largest ``dx² + dy²`` (steps²) of a line the compiled DDA accepts (``n·P`` fits int64)."""


@numba.njit(cache=True, nogil=True)
def dda_exact(p: int, q: int, h: int, lo: int, hi: int, n_rows: int) -> Any:
    """Rows of the A.3 DDA when HIPO is the integer ``h``, packed one ``uint16`` per row.

    The literal register loop of annex A.3 on integers (``Q += P``; ``Q > HIPO`` pulses
    and loses HIPO), which is exact here; it equals ``k(n) = (n·P − 1) // h`` of
    ``_dda_counts``. A pulse adds ``lo`` (X: the low byte of the row) resp. ``hi``
    (Y: the high byte), the step's int8 value already shifted into place.
    """
    out = np.empty(n_rows, dtype=np.uint16)
    qx = 0
    qy = 0
    for i in range(n_rows):
        v = 0
        qx += p
        if qx > h:
            qx -= h
            v += lo
        qy += q
        if qy > h:
            qy -= h
            v += hi
        out[i] = v
    return out


@numba.njit(cache=True, nogil=True)
def dda_float(cx: float, cy: float, lo: int, hi: int, n_rows: int, window: float) -> Any:
    """Rows of the A.3 DDA by the closed form ``k(n) = floor(n·c)``, ``c = P/√s``, packed.

    The same float product and truncation as the numpy ``_dda_counts``; returns the rows
    (one ``uint16`` each, as :func:`dda_exact`) and how many estimates lie within
    ``window`` of an integer (the caller re-checks those rows exactly, :func:`dda_ties`).
    """
    out = np.empty(n_rows, dtype=np.uint16)
    ties = 0
    kx_prev = 0
    ky_prev = 0
    edge = 0.5 - window
    for i in range(n_rows):
        n = i + 1
        tx = n * cx
        ty = n * cy
        kx = int(tx)
        ky = int(ty)
        ties += abs((tx - kx) - 0.5) > edge
        ties += abs((ty - ky) - 0.5) > edge
        out[i] = (kx - kx_prev) * lo + (ky - ky_prev) * hi
        kx_prev = kx
        ky_prev = ky
    return out, ties


@numba.njit(cache=True, nogil=True)
def dda_ties(cx: float, cy: float, n_rows: int, window: float) -> Any:
    """Row indices (0-based) whose closed-form estimate :func:`dda_float` flags as near-ties."""
    found = np.empty(n_rows, dtype=np.int64)
    nt = 0
    edge = 0.5 - window
    for i in range(n_rows):
        n = i + 1
        tx = n * cx
        ty = n * cy
        if abs((tx - int(tx)) - 0.5) > edge or abs((ty - int(ty)) - 0.5) > edge:
            found[nt] = i
            nt += 1
    return found[:nt]


@numba.njit(cache=True, nogil=True)
def bresenham_rows(dx: Any, dy: Any, amass: bool, out: Any) -> None:
    """The rows of GRBL's Bresenham lines ``(dx[j], dy[j])`` steps, one after the other.

    ``out``: ``(sum of max(|dx|, |dy|), 2) int8``, filled. Step event ``n`` of a line of
    ``big`` events leaves an axis of ``m`` steps at ``(big + 2·n·m − 1) // (2·big)``
    pulses with AMASS, ``(big // 2 + n·m − 1) // big`` without: the integers of
    :func:`camtool.verify.interpolators._bresenham_counts`, a row the pulses since the
    event before, signed as the move.
    """
    i = 0
    for j in range(len(dx)):
        ax = abs(dx[j])
        ay = abs(dy[j])
        sx = 1 if dx[j] > 0 else (-1 if dx[j] < 0 else 0)
        sy = 1 if dy[j] > 0 else (-1 if dy[j] < 0 else 0)
        big = max(ax, ay)
        kx0 = 0
        ky0 = 0
        for n in range(1, big + 1):
            if amass:
                kx = (big + 2 * n * ax - 1) // (2 * big)
                ky = (big + 2 * n * ay - 1) // (2 * big)
            else:
                kx = (big // 2 + n * ax - 1) // big
                ky = (big // 2 + n * ay - 1) // big
            out[i, 0] = (kx - kx0) * sx
            out[i, 1] = (ky - ky0) * sy
            kx0 = kx
            ky0 = ky
            i += 1


@numba.njit(cache=True, nogil=True)
def _grow(out: Any, i: int) -> Any:
    grown = np.empty((2 * out.shape[0] + 64, 2), dtype=np.int8)
    grown[:i] = out[:i]
    return grown


@numba.njit(cache=True, nogil=True)
def dsm_quadrant(
    x: int, y: int, d: int, gx: int, gy: int, sx: int, sy: int, ux: int, uy: int, out: Any, at: int
) -> tuple[int, int, int, Any, int]:
    """``_dsm_run`` of annex A.6 writing rows ``(ux, 0)``, ``(0, uy)``, ``(ux, uy)``.

    Rows go to ``out`` from row ``at`` on (``out`` is grown when full); returns the end
    state, the buffer and the next free row. The loop itself is :func:`_dsm_fill`, which
    never replaces the buffer: a buffer replaced inside the loop is reloaded by numba at
    every iteration, several times slower (docs/performance.md).
    """
    i = at
    while True:
        x, y, d, i = _dsm_fill(x, y, d, gx, gy, sx, sy, ux, uy, out, i)
        if x == sx or y == sy:
            return x, y, d, out, i
        out = _grow(out, i)


@numba.njit(inline="always")
def _dsm_fill(
    x: int, y: int, d: int, gx: int, gy: int, sx: int, sy: int, ux: int, uy: int, out: Any, at: int
) -> tuple[int, int, int, int]:  # pragma: no cover - compiled
    """:func:`dsm_quadrant`'s loop, until its end or ``out`` is full: ``(x, y, d, next row)``.

    ``dx``, ``dy`` (the change of D for a step on each axis) are ``2·x·gx + 1`` and
    ``2·y·gy + 1`` wherever the loop is (each step adds 2 to its own), so they are made
    again from ``x`` and ``y`` when it resumes.
    """
    i = at
    n = out.shape[0]
    dx = 2 * x * gx + 1
    dy = 2 * y * gy + 1
    while x != sx and y != sy and i < n:
        d1 = d + dx
        d2 = d + dy
        d3 = d1 + dy
        a1 = d1 if d1 >= 0 else -d1
        a2 = d2 if d2 >= 0 else -d2
        a3 = d3 if d3 >= 0 else -d3
        if (a2 > a3) if a1 > a2 else (a1 > a3):
            d = d3
            dx += 2
            dy += 2
            x += gx
            y += gy
            out[i, 0] = ux
            out[i, 1] = uy
        elif a1 > a2:
            d = d2
            dy += 2
            y += gy
            out[i, 0] = 0
            out[i, 1] = uy
        else:
            d = d1
            dx += 2
            x += gx
            out[i, 0] = ux
            out[i, 1] = 0
        i += 1
    return x, y, d, i


@numba.njit(cache=True, nogil=True)
def staircase_quadrant(
    x: int, y: int, d: int, gx: int, gy: int, sx: int, sy: int, ux: int, uy: int, out: Any, at: int
) -> tuple[int, int, int, Any, int]:
    """``_staircase_run`` of annex A.5 writing rows ``(ux, 0)`` / ``(0, uy)`` (as dsm_quadrant)."""
    i = at
    while True:
        x, y, d, i = _staircase_fill(x, y, d, gx, sx, sy, ux, uy, out, i)
        if x == sx or y == sy:
            return x, y, d, out, i
        out = _grow(out, i)


@numba.njit(inline="always")
def _staircase_fill(
    x: int, y: int, d: int, gx: int, sx: int, sy: int, ux: int, uy: int, out: Any, at: int
) -> tuple[int, int, int, int]:  # pragma: no cover - compiled
    """:func:`staircase_quadrant`'s loop, until its end or a full ``out`` (:func:`_dsm_fill`)."""
    i = at
    n = out.shape[0]
    while x != sx and y != sy and i < n:
        if d <= 0:
            if gx > 0:
                d = d + 2 * x + 1
                x += 1
                out[i, 0] = ux
                out[i, 1] = 0
            else:
                d = d + 2 * y + 1
                y += 1
                out[i, 0] = 0
                out[i, 1] = uy
        elif gx > 0:
            d = d - 2 * y + 1
            y -= 1
            out[i, 0] = 0
            out[i, 1] = uy
        else:
            d = d - 2 * x + 1
            x -= 1
            out[i, 0] = ux
            out[i, 1] = 0
        i += 1
    return x, y, d, i


@numba.njit(cache=True, nogil=True)
def _count_runs(rows: Any) -> tuple[int, int]:
    """Runs of equal non-zero step sign in each column of ``rows`` (one pass, both axes)."""
    count_x = 0
    count_y = 0
    last_x = 0
    last_y = 0
    for i in range(rows.shape[0]):
        sx = rows[i, 0]
        sy = rows[i, 1]
        if sx != 0 and sx != last_x:
            count_x += 1
            last_x = sx
        if sy != 0 and sy != last_y:
            count_y += 1
            last_y = sy
    return count_x, count_y


@numba.njit(cache=True, nogil=True)
def _fill_run(
    i: int, s: int, last: int, k: int, starts: Any, signs: Any, at: Any, mx: int, my: int
) -> tuple[int, int]:
    """Row ``i``'s step ``s`` on one axis: a new run there is filled. Returns ``(k, last)``."""
    if s != 0 and s != last:
        starts[k] = i
        signs[k] = s
        at[k, 0] = mx
        at[k, 1] = my
        return k + 1, s
    return k, last


@numba.njit(cache=True, nogil=True)
def _fill_runs(
    rows: Any,
    ox: int,
    oy: int,
    starts_x: Any,
    signs_x: Any,
    at_x: Any,
    starts_y: Any,
    signs_y: Any,
    at_y: Any,
) -> None:
    """Fill the run starts, signs and motor positions of both columns (see play_runs).

    The arrays are as long as :func:`_count_runs` counted; the pass stops once they are
    full (a line's runs start at its first pulses).
    """
    kx = 0
    ky = 0
    last_x = 0
    last_y = 0
    mx = ox
    my = oy
    need_x = starts_x.shape[0]
    need_y = starts_y.shape[0]
    for i in range(rows.shape[0]):
        if kx == need_x and ky == need_y:
            break  # every run counted is filled: the rows after start none
        sx = rows[i, 0]
        sy = rows[i, 1]
        mx += sx
        my += sy
        kx, last_x = _fill_run(i, sx, last_x, kx, starts_x, signs_x, at_x, mx, my)
        ky, last_y = _fill_run(i, sy, last_y, ky, starts_y, signs_y, at_y, mx, my)


def play_runs(rows: Any, ox: int, oy: int) -> tuple[Any, ...]:
    """Runs of equal step sign per axis, for the backlash play (``simulate.backlash_play``).

    A run starts at a row whose non-zero step on that axis differs in sign from the
    axis's previous non-zero step (or is its first). Returns, per axis, the run start
    rows ``(R,) int64``, their signs ``(R,) int8`` (+1/-1) and the motor positions
    ``(R, 2) int64`` after each start row (steps, absolute from ``(ox, oy)``): what the
    band of the run is looked up with. Two passes over the rows, both axes in each: one
    counts the runs, one fills them.
    """
    counts = _count_runs(rows)
    out: list[Any] = []
    for axis in (0, 1):
        count = counts[axis]
        out += [
            np.empty(count, dtype=np.int64),
            np.empty(count, dtype=np.int8),
            np.empty((count, 2), dtype=np.int64),
        ]
    _fill_runs(rows, ox, oy, *out)
    return tuple(out)


@numba.njit(cache=True, nogil=True)
def _scan_column(rows: Any, axis: int, direction: int) -> tuple[int, int, int]:
    """Reversals, direction after and pulses of column ``axis`` (one pass; see reversals)."""
    count = 0
    pulses = 0
    previous = direction
    for i in range(rows.shape[0]):
        s = rows[i, axis]
        if s != 0:
            pulses += abs(int(s))
            if previous != 0 and s != previous:
                count += 1
            previous = s
    return count, previous, pulses


@numba.njit(cache=True, nogil=True)
def _fill_reversals(rows: Any, axis: int, direction: int, at: Any, signs: Any) -> None:
    """Fill the rows and signs of the reversals :func:`_scan_column` counted (then stop)."""
    k = 0
    previous = direction
    for i in range(rows.shape[0]):
        if k == at.shape[0]:
            break
        s = rows[i, axis]
        if s != 0:
            if previous != 0 and s != previous:
                at[k] = i
                signs[k] = s
                k += 1
            previous = s


def reversals(rows: Any, axis: int, direction: int) -> tuple[Any, Any, int, int]:
    """Reversals of column ``axis`` of step rows, given the axis's direction before them.

    A reversal is a non-zero step whose sign differs from the previous non-zero one
    (``direction`` before the first row; 0: none yet, so no reversal). Returns the rows
    ``(K,) int64`` and signs ``(K,) int8`` of the reversals, the direction after the
    rows (``direction`` when the column has no step) and the column's pulses (the sum
    of ``|step|``), as ``simulate.StepController._compensate`` and ``block`` find them
    with numpy. One pass over the column; a second, to fill the reversals, only when
    there are any (a line has at most one, at its first pulse).
    """
    count, last, pulses = _scan_column(rows, axis, direction)
    at = np.empty(count, dtype=np.int64)
    signs = np.empty(count, dtype=np.int8)
    if count:
        _fill_reversals(rows, axis, direction, at, signs)
    return at, signs, int(last), int(pulses)


@numba.njit(cache=True, nogil=True)
def play_axis_from(
    rows: Any,
    axis: int,
    starts: Any,
    signs: Any,
    bands: Any,
    state: Any,
    motor0: int,
    start: float,
    true_spm: float,
    out: Any,
) -> int:
    """One axis of ``simulate._carriage``, the play operator, over a chunk of rows.

    The same float operations, in the same order, as the numpy ``_play`` and
    ``_carriage``: before the first run the carriage is at ``start``; in an up run it
    is ``max(c, M)``, in a down run ``min(c, M + band)`` with ``c`` the value at the end
    of the previous run and ``M`` the motor (integer steps); then ``(v − c0 + start) /
    true_spm`` into ``out``. ``bands[r]`` is the band of run ``r`` in steps (unused for
    up runs). The whole trace is one chunk from a zero ``state``
    (``simulate._carriage_compiled``); a streamed one resumes each chunk from the last
    (``chunked.ChunkedSimulation``), and the chunks' rows joined give the same values.

    ``state`` is ``float64[5]``: ``c0`` (the carriage before the first run, set at the
    first run: ``start`` going up, ``start + band`` going down), ``current``, ``value``,
    ``band``, and ``flags`` (bit 0: a run has started, bit 1: the current run goes up).
    ``starts``/``signs``/``bands`` are the runs that *start* in this chunk (a run going
    on from the chunk before is not one). Returns the motor position after the chunk.
    """
    n = rows.shape[0]
    motor = motor0
    c0 = state[0]
    current = state[1]
    value = state[2]
    band = state[3]
    flags = int(state[4])
    started = (flags & 1) != 0
    up = (flags & 2) != 0
    r = 0
    runs = len(starts)
    for i in range(n):
        motor += rows[i, axis]
        if r < runs and i == starts[r]:
            if not started:
                c0 = start if signs[r] > 0 else start + bands[r]
                value = c0
                started = True
            current = value
            up = signs[r] > 0
            band = bands[r]
            r += 1
        if started:
            m = float(motor)
            if up:
                value = current if current >= m else m
            else:
                mb = m + band
                value = current if current <= mb else mb
            out[i, axis] = (value - c0 + start) / true_spm
        else:
            out[i, axis] = start / true_spm
    state[0] = c0
    state[1] = current
    state[2] = value
    state[3] = band
    state[4] = float((1 if started else 0) | (2 if up else 0))
    return motor


EXACT_BINS = 2048 + 64
"""Bins of :func:`exact_sum_squares`: one per binary exponent of a double, and room for
the carries above the largest."""
EXACT_CARRY = 512
"""Additions after which :func:`exact_sum_squares` carries its bins: a carried bin is
below ``2^32 + 2^31``, and 512 mantissas below ``2^53`` keep it below ``2^63``."""


@numba.njit(cache=True, nogil=True)
def exact_sum_squares(values: Any, bins: Any) -> None:
    """Add ``values[i]²`` (each square rounded to float64, as numpy's ``d * d``) exactly.

    A finite double ``x >= 0`` is ``m · 2^(e − 1074)`` with an integer ``m < 2^53`` and
    ``e = max(exponent field − 1, 0)``; ``m`` is added to ``bins[e]`` (int64). After at
    most :data:`EXACT_CARRY` additions, and at the end of each call, every bin's bits
    from 32 up are carried into the bin 32 exponents higher (the same value), so the
    bins hold the exact sum at all times and stay below ``2^63``: :func:`exact_sum`
    turns them into the correctly rounded float. Only the bins from the lowest this
    call added to up to the highest any carry reached are carried: the others were
    carried before and have not changed since. A square that is not finite (inf, nan)
    sets ``bins[-1]`` to 1.
    """
    mask = (1 << 52) - 1
    pending = 0
    low = bins.shape[0]
    high = -1
    for k in range(values.shape[0]):
        x = values[k] * values[k]
        bits = np.float64(x).view(np.int64)
        exponent = (bits >> 52) & 2047
        if exponent == 2047:
            bins[bins.shape[0] - 1] = 1
            continue
        mantissa = bits & mask
        if exponent > 0:
            mantissa |= 1 << 52
            exponent -= 1
        bins[exponent] += mantissa
        if exponent < low:
            low = int(exponent)
        if exponent > high:
            high = int(exponent)
        pending += 1
        if pending == EXACT_CARRY:
            high = _carry(bins, low, high)
            pending = 0
    if pending:
        _carry(bins, low, high)


@numba.njit(cache=True, nogil=True)
def _carry(bins: Any, low: int, high: int) -> int:
    """Carry bins ``low`` up (bits from 32 up into the bin 32 exponents higher, exact).

    Every bin from ``low`` to ``high`` and every bin a carry reaches is carried in turn
    (a bin below ``bins.shape[0] - 33`` only: the top ones hold the carries). Returns
    the highest bin reached.
    """
    keep = (1 << 32) - 1
    last = bins.shape[0] - 34
    e = low
    while e <= high and e <= last:
        carried = bins[e] >> 32
        if carried:
            bins[e] &= keep
            bins[e + 32] += carried
            if e + 32 > high:
                high = e + 32
        e += 1
    return high


def exact_sum(bins: Any) -> float:
    """The correctly rounded float of the exact sum held in ``bins``, or nan (see above)."""
    from fractions import Fraction

    if bins[-1]:
        return float("nan")
    total = sum(int(v) << e for e, v in enumerate(bins[:-1].tolist()) if v)
    return float(Fraction(total, 1 << 1074))


@numba.njit(cache=True, nogil=True)
def extent(points: Any) -> tuple[float, float, float, float]:
    """``(x max, x min, y max, y min)`` of ``(N, 2)`` points, ``N >= 1``: numpy's ``max``/``min``.

    One pass over both columns. Exact (a comparison rounds nothing); a NaN in a column
    makes both of its figures NaN, as numpy's reductions give. (``0.0`` and ``-0.0``
    compare equal, so either may be given where both are the extreme, as with numpy; a
    carriage, made from whole steps, is never ``-0.0``.)
    """
    x_top = x_low = points[0, 0]
    y_top = y_low = points[0, 1]
    x_nan = y_nan = False
    for i in range(points.shape[0]):
        x = points[i, 0]
        y = points[i, 1]
        x_top = max(x_top, x)
        x_low = min(x_low, x)
        y_top = max(y_top, y)
        y_low = min(y_low, y)
        x_nan |= x != x
        y_nan |= y != y
    if x_nan:
        x_top = x_low = math.nan
    if y_nan:
        y_top = y_low = math.nan
    return x_top, x_low, y_top, y_low


@numba.njit(cache=True, nogil=True)
def to_line(points: Any, x0: float, y0: float, x1: float, y1: float, out: Any) -> None:
    """``deviations._to_line`` into ``out``: each point's distance to the segment, mm.

    The same float operations per point, in the same order (``t`` clipped to [0, 1],
    0 for a segment of no length; ``math.hypot`` is the C library's, as numpy's).
    """
    dx = x1 - x0
    dy = y1 - y0
    length2 = dx * dx + dy * dy
    for i in range(points.shape[0]):
        px = points[i, 0] - x0
        py = points[i, 1] - y0
        t = (px * dx + py * dy) / length2 if length2 > 0 else 0.0
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
        out[i] = math.hypot(px - t * dx, py - t * dy)


@numba.njit(cache=True, nogil=True)
def window_bounds(
    samples: Any, centre: Any, a: Any, b: Any, moved: Any, window: int, out: Any
) -> None:
    """``path_shortfall._window_bounds`` of one part into ``out``: each sample's bound, mm.

    Sample ``i`` against the polyline pieces ``k = clip(centre[i] + off, 0, m - 1)``,
    ``off`` from ``-window`` to ``window`` (``m = len(moved) - 1``), each the segment from
    ``a[moved[k]]`` to ``b[moved[k + 1] - 1]``: the same float operations per piece, in
    the same order, as ``path_shortfall._segment_formula`` (``t`` 0 for a piece of no
    length, clipped to [0, 1]; ``sqrt`` of the sum of squares, not ``hypot``), and the
    least of them as ``np.minimum`` keeps it (a NaN is kept).
    """
    m = moved.shape[0] - 1
    for n in range(samples.shape[0]):
        px = samples[n, 0]
        py = samples[n, 1]
        best = math.inf
        for off in range(-window, window + 1):
            k = centre[n] + off
            if k < 0:
                k = 0
            elif k > m - 1:
                k = m - 1
            i = moved[k]
            j = moved[k + 1] - 1
            ax = a[i, 0]
            ay = a[i, 1]
            apx = px - ax
            apy = py - ay
            abx = b[j, 0] - ax
            aby = b[j, 1] - ay
            length2 = abx * abx + aby * aby
            dot = apx * abx + apy * aby
            t = dot / length2 if length2 > 0 else 0.0
            if t < 0.0:
                t = 0.0
            elif t > 1.0:
                t = 1.0
            ox = apx - t * abx
            oy = apy - t * aby
            d = math.sqrt(ox * ox + oy * oy)
            if best == best and (d < best or d != d):
                best = d
        out[n] = best


@numba.njit(cache=True, nogil=True)
def ideal_motor(rows: Any, total: Any, origin: Any, motor: Any, signs: Any) -> None:
    """The ideal controller's motor after each fractional row, and each row's direction.

    ``motor[i] = (total + rows[0] + … + rows[i]) + origin`` per axis: the running sum in
    row order (numpy's ``cumsum``, resumed from ``total``), then the origin added, as
    ``chunked._FloatPlay`` and ``simulate.motor_positions`` take them; ``total`` becomes the
    running sum after the last row. ``signs[i]`` is ``sign(rows[i])`` (int8; 0 for a
    zero of either sign).
    """
    tx = total[0]
    ty = total[1]
    ox = origin[0]
    oy = origin[1]
    for i in range(rows.shape[0]):
        rx = rows[i, 0]
        ry = rows[i, 1]
        tx += rx
        ty += ry
        motor[i, 0] = tx + ox
        motor[i, 1] = ty + oy
        signs[i, 0] = 1 if rx > 0 else (-1 if rx < 0 else 0)
        signs[i, 1] = 1 if ry > 0 else (-1 if ry < 0 else 0)
    total[0] = tx
    total[1] = ty


@numba.njit(cache=True, nogil=True)
def _scan_runs(signs: Any, axis: int, sign0: int, starts: Any, run_signs: Any) -> int:
    """Count (and, given room, fill) the runs of column ``axis`` (see :func:`runs`)."""
    count = 0
    previous = sign0
    room = starts.shape[0]
    for i in range(signs.shape[0]):
        s = signs[i, axis]
        if s != 0 and s != previous:
            if count < room:
                starts[count] = i
                run_signs[count] = s
            count += 1
        if s != 0:
            previous = s
    return count


def runs(signs: Any, axis: int, sign0: int) -> tuple[Any, Any]:
    """The runs that start in column ``axis`` of direction rows ``signs`` ``(N, 2) int8``.

    A run starts at a non-zero direction that differs from the previous non-zero one
    (``sign0`` before the first row; 0: none yet, so the first non-zero starts one).
    Returns their rows ``(R,) int64`` and directions ``(R,) int8``.
    """
    none = np.empty(0, dtype=np.int64)
    count = _scan_runs(signs, axis, sign0, none, np.empty(0, dtype=np.int8))
    starts = np.empty(count, dtype=np.int64)
    run_signs = np.empty(count, dtype=np.int8)
    if count:
        _scan_runs(signs, axis, sign0, starts, run_signs)
    return starts, run_signs


@numba.njit(cache=True, nogil=True)
def ideal_play_axis(
    motor: Any,
    axis: int,
    starts: Any,
    signs: Any,
    bands: Any,
    state: Any,
    origin: float,
    true_spm: float,
    out: Any,
) -> None:
    """One axis of ``chunked._FloatPlay.chunk``, the play operator on fractional steps.

    The same float operations, in the same order, as the numpy form: before the first
    run the carriage is ``origin``; a run starting here takes ``current`` from the value
    at the end of the run before (the first run sets ``c0``: ``origin`` going up,
    ``origin + band`` going down); in an up run the carriage is ``max(current, M)``, in a
    down run ``min(current, M + band)`` (numpy's ``maximum``/``minimum``: the motor's
    where equal, as for ``0.0`` and ``-0.0``), ``M`` the motor; then
    ``((v − c0) + origin) / true_spm`` into ``out``.
    ``starts``/``signs``/``bands``: the runs that start in this chunk (:func:`runs`), the
    band in steps (unused going up). ``state`` is ``float64[5]``, carried from chunk to
    chunk: ``c0``, ``current``, ``value`` (after the last row), ``band``, ``sign`` (0: no
    run yet).
    """
    c0 = state[0]
    current = state[1]
    value = state[2]
    band = state[3]
    sign = int(state[4])
    r = 0
    count = starts.shape[0]
    for i in range(motor.shape[0]):
        if r < count and i == starts[r]:
            s = int(signs[r])
            b = bands[r] if s < 0 else 0.0
            if sign == 0:
                value = origin if s > 0 else origin + b
                c0 = value
            current = value
            band = b
            sign = s
            r += 1
        if sign == 0:
            out[i, axis] = (0.0 + origin) / true_spm
            continue
        m = motor[i, axis]
        if sign > 0:
            v = current if current > m else m
        else:
            mb = m + band
            v = current if current < mb else mb
        value = v
        out[i, axis] = ((v - c0) + origin) / true_spm
    state[0] = c0
    state[1] = current
    state[2] = value
    state[3] = band
    state[4] = float(sign)
