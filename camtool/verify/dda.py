"""The DDA line interpolator, its rows counted, and the loader of the compiled kernels."""

from __future__ import annotations

import math
import operator
from types import ModuleType

import numpy as np
import numpy.typing as npt

from camtool.accel.loader import KernelsOnDemand
from camtool.model.errors import UsageError
from camtool.verify.steparray import StepArray, empty_steps, freeze

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


def dda_iterations(dx: int, dy: int) -> int:
    """Number of iterations of the UNAM-GMM A.3 line DDA: ``floor(HIPO) + 1``.

    Every axis with a non-zero projection P overflows for the last time in the
    first iteration n with ``n·P > P·HIPO``, i.e. ``n = floor(HIPO) + 1``; a
    zero move has no iterations. Source: UNAM-GMM §4.2 (Eq. 3.3, code A.3).

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
    """Linear DDA of the GMM PIC controller, vectorised (UNAM-GMM §4.2, annex A.3).

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
        Golden: (3, 4) → ``- XY Y XY - XY`` (UNAM-GMM §4.2).

    Raises:
        UsageError: If ``dx`` or ``dy`` is not an integer.
    """
    dx, dy = _as_int("dx", dx), _as_int("dy", dy)
    px, py = abs(dx), abs(dy)
    s = px * px + py * py
    if s == 0:
        return empty_steps()
    jit = compiled(math.isqrt(s) + 1)
    if jit is not None and s < jit.SAFE_SQUARE:
        return _dda_line_compiled(jit, px, py, _sign(dx), _sign(dy), s)
    return dda_line_numpy(dx, dy)


def dda_line_rows(dx: int, dy: int) -> int:
    """How many rows :func:`dda_line` ``(dx, dy)`` gives, without making them.

    ``floor(HIPO) + 1`` (0 for no move; HIPO as in :func:`dda_line`). Each axis pulses
    ``|d|`` times (its counter stops at its projection, and ``k(N) = P`` at the last
    row), every pulse the way of ``d``: a line reverses an axis at most once, at its
    first pulse. ``tests/verify/test_count_rows.py`` checks both against the rows.
    """
    s = dx * dx + dy * dy
    return math.isqrt(s) + 1 if s else 0


def dda_line_numpy(dx: int, dy: int) -> StepArray:
    """:func:`dda_line` by the numpy closed form (no numba); same rows.

    Args:
        dx: X move, steps, signed.
        dy: Y move, steps, signed.

    Returns:
        Step array identical to ``dda_line(dx, dy)``.

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


def _dda_count_at(p: int, s: int, n: int) -> int:
    """One value of :func:`_dda_counts` (``n`` ≥ 0; ``k(0) = 0``), exact."""
    if p == 0 or n == 0:
        return 0
    return int(_dda_counts(p, s, np.asarray([n], dtype=np.int64))[0])


def _dda_line_compiled(jit: ModuleType, px: int, py: int, sx: int, sy: int, s: int) -> StepArray:
    """:func:`dda_line` by the compiled kernels; near-ties re-checked in exact integers.

    HIPO an integer: the integer register loop (exact). Else the kernel computes
    ``k(n)`` with the same float product as :func:`_dda_counts` and counts the ``n``
    whose estimate lies within :data:`_TIE_WINDOW` of an integer; those rows (and
    the next, which depends on the same count) are recomputed here exactly, so
    the rows equal :func:`dda_line_numpy`'s. Rows come packed one ``uint16`` each
    (X in the low byte: little-endian only, see :func:`compiled`).
    """
    h = math.isqrt(s)
    lo, hi = sx & 0xFF, (sy & 0xFF) << 8
    if h * h == s:
        packed = jit.dda_exact(px, py, h, lo, hi, h + 1)
        ties: list[int] = []
    else:
        root = math.sqrt(s)
        cx, cy = (px / root if px else 0.0), (py / root if py else 0.0)
        packed, count = jit.dda_float(cx, cy, lo, hi, h + 1, _TIE_WINDOW)
        ties = jit.dda_ties(cx, cy, h + 1, _TIE_WINDOW).tolist() if count else []
    out = packed.view(np.int8).reshape(-1, 2)
    for i in ties:
        for row in (i, i + 1):
            if row <= h:
                for col, p, sign in ((0, px, sx), (1, py, sy)):
                    k = _dda_count_at(p, s, row + 1) - _dda_count_at(p, s, row)
                    out[row, col] = sign * k
    out.flags.writeable = False
    return out


COMPILE_FROM = 20_000_000
"""Rows the plain (numpy / Python) paths have worked through in this process — each
interpolator call, reversal scan and carriage counts its rows, so a simulated row counts
about three times — from which the compiled kernels are loaded. Loading numba and its
cache costs about 1 s once (measured under load), more than the plain paths take for a
4 M-row trace (whose carriage, the costliest part, then runs in numpy: ~0.2 s per M
rows); from about 6 M simulated rows the kernels win. A small program (the logo: 0.3 M
rows, simulated about 4 times with the error budget) never pays it."""


def compiled(work: int = COMPILE_FROM) -> ModuleType | None:
    """The numba kernels (:mod:`camtool.accel.kernels`), once the work warrants them.

    ``work`` is the rows the caller is about to produce; the kernels are loaded when
    the rows asked for so far in this process reach :data:`COMPILE_FROM` (the default
    asks for them at once) and then used by every later call. ``None`` before that,
    with ``CAMTOOL_ACCEL=0``, when numba is not installed, or on a big-endian machine
    (the packed rows assume little-endian); the numpy / Python paths then give the same
    rows.

    Args:
        work: Rows the caller is about to compute, ``>= 0``.

    Returns:
        The kernels module, or ``None`` (use the plain path).
    """
    return KERNELS.get(work)


KERNELS = KernelsOnDemand("camtool.accel.kernels", COMPILE_FROM, little_endian=True)
"""The step kernels of this process, loaded from :data:`COMPILE_FROM` rows on."""


def dda_line_reference(dx: int, dy: int) -> StepArray:
    """Literal register loop of the UNAM-GMM A.3 DDA; same result as :func:`dda_line`.

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


def _major_minor(dx: int, dy: int) -> tuple[int, int, bool]:
    """``(major, minor, x_is_major)`` magnitudes; X is the major axis on a tie."""
    ax, ay = abs(dx), abs(dy)
    return (ax, ay, True) if ax >= ay else (ay, ax, False)


def accumulator_dda_table(dx: int, dy: int) -> npt.NDArray[np.int64]:
    """Iteration table of the ValCNC accumulator DDA, as Table 8 of Munoz-22 §4.1.

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
