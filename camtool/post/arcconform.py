"""Arcs conformed to a controller's check: the printed centre searched, or the arc split.

The rules are :mod:`camtool.post.arccheck`'s; this module finds, for an arc that the
rounding of its printed numbers would make the controller refuse, a printable centre
that passes (or splits the arc into pieces that do), within the arc's deviation bound.

Design notes: docs/internals.md, ``camtool/post/arccheck.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING

from camtool.model.errors import DialectError, UsageError
from camtool.model.shapes import Point
from camtool.post.numfmt import half_up

if TYPE_CHECKING:  # numpy is imported in the functions that use it: a re-post whose arcs
    # all pass the shortcut (plainly_passes) never loads it (~0.1 s of CPU)
    import numpy as np
    import numpy.typing as npt

from camtool.post.arccheck import (
    GRBL_ANGULAR_EPSILON,
    GRBL_CEILING_MM,
    GRBL_RELATIVE,
    GRBL_TOLERANCE_MM,
    LINUXCNC_CEILING_MM,
    LINUXCNC_MIN_RADIUS_MM,
    LINUXCNC_RELATIVE,
    LINUXCNC_TOLERANCE_MM,
    MARGIN_MM,
    RULE_TEXT,
    arc_error,
    check_rule,
    max_difference,
    rule_ok,
    travel,
)

DEVIATION_QUANTA = 1.5
"""Largest distance of a block's path from the exact arc, in quanta (the printed
end points alone may be √2/2 quantum off the exact ones)."""
SEARCH_QUANTA = 3.0
"""Centres tried first lie within this many quanta of the exact centre."""
BISECTOR_QUANTA = 40.0
"""Then centres along the chord's bisector, this many quanta (and at most one
radius) either side of the exact centre."""
MAX_SPLIT_DEPTH = 10
"""An arc is halved at most this many times (at most 1024 blocks)."""
SAMPLES = 65
"""Points per block at which the path is compared with the exact arc."""

Index = tuple[int, int]
if TYPE_CHECKING:
    IntArray = npt.NDArray[np.int64]
    FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Grid:
    """The points the writer can print: integer multiples of ``quantum`` mm."""

    quantum: Decimal

    @classmethod
    def of(cls, quantum_mm: float) -> Grid:
        """The grid of a resolution in mm (one shared instance per resolution).

        Raises:
            UsageError: ``quantum_mm`` is not a positive finite number.
        """
        if not (math.isfinite(quantum_mm) and quantum_mm > 0):
            raise UsageError(f"the arc quantum must be a positive number of mm, got {quantum_mm!r}")
        return _grid_of(float(quantum_mm))

    @cached_property
    def mm(self) -> float:
        """The quantum, mm."""
        return float(self.quantum)

    @cached_property
    def decimals(self) -> int | None:
        """``d`` when the quantum is exactly ``10**-d`` mm (``0 ≤ d ≤ 6``), else ``None``."""
        _, digits, exponent = self.quantum.as_tuple()
        if digits == (1,) and isinstance(exponent, int) and -6 <= exponent <= 0:
            return -exponent
        return None

    def index(self, value_mm: float) -> int:
        """Nearest grid index, halves away from zero (as ``NumberFormat`` rounds).

        The index is that of the float's shortest repr ``D`` (the decimal the writer
        prints from): :meth:`_index_slow` divides and quantizes it with ``Decimal``
        (kept for the tests). On a ``10**-d`` grid two faster ways give the same:

        - ``x = value·10**d`` in floats, rounded half up, whenever ``x`` is further
          from a half-integer than from ``D·10**d``. ``10**d`` is exact (d ≤ 6),
          ``|x − value·10**d| ≤ 2**-53·|x|`` and ``|D − value| ≤ ulp/2 ≤
          2**-53·|value|``, so ``|x − D·10**d| < 2**-51·|x|``; the test leaves
          :data:`_ROOM` (``2**-48``) of ``|x|``. Rounding half up changes value only
          at half-integers, so none lies between the two and they round alike.
        - else the digits of the repr, rounded directly
          (:func:`~camtool.post.numfmt.half_up`).
        """
        d = self.decimals
        if d is not None:
            x = value_mm * _TENS[d]
            a = abs(x)
            if a < _FAST_BELOW:  # also False for NaN and infinities
                whole = math.floor(a)
                f = a - whole  # exact: a < 2**50
                if abs(f - 0.5) > a * _ROOM:
                    k = whole + 1 if f > 0.5 else whole
                    return -k if x < 0 else k
            plain = half_up(float(value_mm), d)
            if plain is not None:
                k = int(plain[0].replace(".", ""))
                return -k if plain[1] else k
        return self._index_slow(value_mm)

    def _index_slow(self, value_mm: float) -> int:
        q = Decimal(repr(float(value_mm))) / self.quantum
        return int(q.quantize(Decimal(1), rounding=ROUND_HALF_UP))

    def indices(self, p: Point) -> Index:
        """The grid point nearest ``p`` (mm)."""
        return self.index(p[0]), self.index(p[1])

    def value(self, k: int) -> float:
        """Grid index ``k`` in mm: the float of the exact decimal, so it prints as itself.

        On a ``10**-d`` grid ``float("{k}e-{d}")``: the same decimal, and both
        conversions are correctly rounded (:meth:`_value_slow` is the ``Decimal`` one).
        """
        memo = self._values
        v = memo.get(k)
        if v is None:
            d = self.decimals
            v = float(f"{k}e-{d}") if d is not None and -(10**20) < k < 10**20 else None
            v = self._value_slow(k) if v is None else v
            if len(memo) >= _MEMO_SIZE:
                memo.clear()
            memo[k] = v
        return v

    @cached_property
    def _values(self) -> dict[int, float]:
        """:meth:`value` of the indices met lately (a pure function of ``k``: the same float)."""
        return {}

    def _value_slow(self, k: int) -> float:
        return float(Decimal(k) * self.quantum)

    def point(self, k: Index) -> Point:
        """Grid point ``k`` in mm."""
        return (self.value(k[0]), self.value(k[1]))

    def on_grid(self, p: Point, what: str) -> Index:
        """Indices of a point that must already be printable.

        Raises:
            ValueError: ``p`` is not on the grid (a caller bug).
        """
        k = self.indices(p)
        if max(abs(self.value(k[0]) - p[0]), abs(self.value(k[1]) - p[1])) > 1e-6 * self.mm:
            raise ValueError(f"the arc {what} {p} is not on the {self.quantum} mm grid")
        return k


_TENS = tuple(float(10**d) for d in range(7))
"""``10**d`` for the decimals :attr:`Grid.decimals` can take (exact floats)."""
_FAST_BELOW = 2.0**50
"""Grid indices below this are rounded in floats by :meth:`Grid.index` (an exact fraction)."""
_ROOM = 2.0**-48
"""Relative distance from a half-integer :meth:`Grid.index` needs to round in floats."""

_MEMO_SIZE = 1 << 16
"""Most indices :meth:`Grid.value` keeps (an arc's ends and centre recur in the next arcs)."""


@lru_cache(maxsize=64)
def _grid_of(quantum_mm: float) -> Grid:
    return Grid(Decimal(repr(quantum_mm)))


@dataclass(frozen=True)
class Reference:
    """The exact arc or a part of it: centre (mm), radius (mm), start angle and signed sweep.

    Angles in radians, counter-clockwise from +X; ``sweep < 0`` is clockwise.
    """

    centre: Point
    radius: float
    angle: float
    sweep: float

    def at(self, fraction: float) -> Point:
        """The point a ``fraction`` (0…1) of the way along, mm."""
        a = self.angle + fraction * self.sweep
        return (
            self.centre[0] + self.radius * math.cos(a),
            self.centre[1] + self.radius * math.sin(a),
        )

    def part(self, start: float, stop: float) -> Reference:
        """The part between two fractions of the sweep."""
        angle = self.angle + start * self.sweep
        return Reference(self.centre, self.radius, angle, (stop - start) * self.sweep)

    def distance(self, p: FloatArray) -> FloatArray:
        """Distance of points ``p`` (``(..., 2)`` mm) from this arc, mm (shape ``p[..., 0]``)."""
        import numpy as np  # imported where used (see the module's imports)

        dx, dy = p[..., 0] - self.centre[0], p[..., 1] - self.centre[1]
        turned = np.arctan2(dy, dx) - self.angle
        along = np.mod(turned if self.sweep >= 0 else -turned, 2 * math.pi)
        radial = np.abs(np.hypot(dx, dy) - self.radius)
        ends = [np.hypot(p[..., 0] - e[0], p[..., 1] - e[1]) for e in (self.at(0.0), self.at(1.0))]
        return np.where(along <= abs(self.sweep), radial, np.minimum(*ends))


class Unsolvable(Exception):
    """No printable centre for a part of the arc, and it cannot be halved further."""


@dataclass(frozen=True)
class Solver:
    """Finds the blocks of one arc for one rule, grid, direction and exact centre."""

    grid: Grid
    rule: str
    clockwise: bool
    exact_centre: Point
    shortcut: bool = True
    """Test the rounded centre with :func:`plainly_passes` before the search (False: the
    search alone, as before the shortcut; tests compare the two)."""

    @property
    def limit(self) -> float:
        """Largest deviation of a block's path from the exact arc, mm."""
        return DEVIATION_QUANTA * self.grid.mm

    def solve(
        self, s: Index, e: Index, ref: Reference, depth: int = 0
    ) -> list[tuple[Index, Index]]:
        """``(end, centre)`` grid points of the blocks from ``s`` to ``e`` along ``ref``.

        One block with a nearby centre; else the two halves of ``ref`` (the mid
        point rounded to the grid), each solved the same way; else one block
        with a centre along the chord's bisector.

        Raises:
            Unsolvable: a part fails and cannot be halved (its mid point rounds
                onto one of its ends, or :data:`MAX_SPLIT_DEPTH` is reached).
        """
        c = self.centre(s, e, ref, bisector=False)
        if c is not None:
            return [(e, c)]
        m = self.grid.indices(ref.at(0.5))
        why = "its mid point prints on one of its ends"
        if depth < MAX_SPLIT_DEPTH and m not in (s, e):
            try:
                first = self.solve(s, m, ref.part(0.0, 0.5), depth + 1)
                return first + self.solve(m, e, ref.part(0.5, 1.0), depth + 1)
            except Unsolvable as exc:
                why = str(exc)
        c = self.centre(s, e, ref, bisector=True)
        if c is not None:
            return [(e, c)]
        span = math.degrees(abs(ref.sweep))
        raise Unsolvable(f"a part of {span:.3g}° from {self.grid.point(s)} fails ({why})")

    def centre(self, s: Index, e: Index, ref: Reference, *, bisector: bool) -> Index | None:
        """The grid centre for a block ``s`` → ``e``, or ``None`` when none passes.

        Nearby (``bisector=False``): the rounded centre if it passes, else the
        grid points within :data:`SEARCH_QUANTA` of the exact centre, the one
        that best equalises the radii first, then the nearest. Along the
        bisector (``bisector=True``): the grid points near the bisector of ``s``
        and ``e`` where the radii agree within the rule, nearest the exact centre
        first (:data:`BISECTOR_QUANTA`).
        """
        if not bisector and self.shortcut:
            c0 = self.grid.indices(self.exact_centre)
            if plainly_passes(self, s, e, c0, ref) and self._accepted(s, e, c0):
                return c0  # what the search below returns first: see plainly_passes
        import numpy as np  # imported where used (see the module's imports)

        exact = np.array(self.exact_centre) / self.grid.mm
        rounded = np.array([self.grid.indices(self.exact_centre)], dtype=np.int64)
        tiers = (
            ((lambda: self._band(s, e, ref), False),)
            if bisector
            else ((lambda: rounded, False), (lambda: _disk(rounded, exact), True))
        )
        for make, by_delta in tiers:
            cands = make()
            if len(cands) == 0:
                continue
            delta, ok = self._passes(s, e, cands, ref)
            away = np.hypot(*(cands - exact).T)
            order = np.lexsort((away, np.round(delta, 9))) if by_delta else np.argsort(away)
            for k in order:
                c = (int(cands[k, 0]), int(cands[k, 1]))
                if ok[k] and self._accepted(s, e, c):
                    return c
        return None

    def _band(self, s: Index, e: Index, ref: Reference) -> IntArray:
        """Grid points ``(K, 2)`` near the bisector of ``s``–``e`` where the radii agree.

        Within the rule's radius difference of the bisector (at most
        :data:`SEARCH_QUANTA`) and :data:`BISECTOR_QUANTA` (at most one radius)
        of the exact centre's foot on it; empty when ``s == e`` (every centre
        equalises the radii).
        """
        import numpy as np  # imported where used (see the module's imports)

        q = self.grid.mm
        chord = np.subtract(e, s).astype(np.float64)
        d = float(np.hypot(*chord))
        if d == 0.0:
            return np.empty((0, 2), dtype=np.int64)
        u = chord / d
        n = np.array([-u[1], u[0]])
        mid = (np.array(s) + np.array(e)) / 2.0
        exact = np.array(self.exact_centre) / q
        foot = mid + float((exact - mid) @ n) * n
        w = min(SEARCH_QUANTA, max_difference(self.rule, ref.radius) * ref.radius / (d * q * q))
        reach = min(BISECTOR_QUANTA, max(SEARCH_QUANTA, ref.radius / q))
        span = reach + w + 1.0
        xs = np.arange(math.floor(foot[0] - span), math.ceil(foot[0] + span) + 1)
        ys = np.arange(math.floor(foot[1] - span), math.ceil(foot[1] + span) + 1)
        grid = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
        keep = (np.abs((grid - mid) @ u) <= w) & (np.abs((grid - foot) @ n) <= reach)
        return grid[keep].astype(np.int64)

    def _accepted(self, s: Index, e: Index, c: Index) -> bool:
        """The controller's own check (:func:`arc_error`) on the printed numbers."""
        g = self.grid
        return arc_error(g.point(s), g.point(e), g.point(c), rule=self.rule) is None

    def _passes(
        self, s: Index, e: Index, cands: IntArray, ref: Reference
    ) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
        """Radius difference (mm) of each candidate centre and whether it passes every test.

        The rule with a margin, a sweep within 90° of the exact part's, and a
        path within :attr:`limit` of it.
        """
        import numpy as np  # imported where used (see the module's imports)

        q = self.grid.mm
        u0 = ((np.array(s) - cands) * q).astype(np.float64)  # (K, 2) centre → start, mm
        u1 = ((np.array(e) - cands) * q).astype(np.float64)
        r0, r1 = np.hypot(*u0.T), np.hypot(*u1.T)
        ok = rule_ok(self.rule, r0, r1) & (r0 > 0) & (r1 > 0)
        sweep = travel(u0, u1, self.clockwise)
        ok &= np.abs(np.abs(sweep) - abs(ref.sweep)) <= math.pi / 2
        end = np.array(e, dtype=np.float64) * q
        path = _path(self.rule, (cands * q).astype(np.float64), u0, r0, r1, sweep, end)
        ok &= np.max(ref.distance(path), axis=1) <= self.limit
        return np.abs(r1 - r0), ok


# -- the shortcut: the rounded centre without the search ------------------------------

SLACK_MM = 1e-9
"""Room :func:`plainly_passes` leaves for the float rounding of the search's numpy (mm)."""
SLACK_RAD = 1e-9
"""The same for angles, rad."""
SHORTCUT_MAX_MM = 1e4
"""Radii beyond this (mm) always go to the search (float noise grows with the radius)."""


def plainly_passes(solver: Solver, s: Index, e: Index, c: Index, ref: Reference) -> bool:
    """Whether the search's tests of the rounded centre ``c`` surely pass (no numpy, ~µs).

    ``True`` only when :meth:`Solver._passes` is sure to pass ``c``: then
    :meth:`Solver.centre` (not along the bisector), whose first tier is the
    rounded centre alone, returns ``c`` as soon as :func:`arc_error` accepts it,
    and the caller returns the same. ``False`` means "not sure", never "fails":
    the caller then runs the whole search, which tries ``c`` again, so the
    result is always the search's. Each test of ``_passes`` is checked here with
    :data:`SLACK_MM` / :data:`SLACK_RAD` to spare (numpy's ``hypot``/``arctan2``
    may differ from ``math``'s by an ulp):

    - the rule with its margin (:func:`rule_ok`), both radii > 0;
    - the sweep (:func:`travel`; refused near its branch points ``±π`` and
      ``±``:data:`GRBL_ANGULAR_EPSILON`, where an ulp could flip it by 2π) within
      90° of the exact part's;
    - the deviation, by a bound on the continuous path (the search samples it):
      with ``d = c − C`` (``C`` the exact centre, ``δ = |d|``, ``R`` the exact
      radius) a path point is ``P = C + d + ρ·u(θ)``, ``ρ`` the start radius
      (GRBL) or linear from ``r0`` to ``r1`` (LinuxCNC), ``θ = θ0 + σt``. Then
      ``|P − C| = √(f² + w²)`` with ``f = ρ + d·u`` and ``|w| = |d × u| ≤ δ``, so
      ``f ≤ |P − C| ≤ f + δ²/(2f)`` and every point's radial distance is at
      most ``Brad = max(fmax + δ²/(2 fmin) − R, R − fmin)``; ``f(t) = r0 + bt +
      δ·cos(x0 + σt)`` takes its extremes at ``t = 0, 1`` or where
      ``sin(x0 + σt) = b/(δσ)``, all evaluated. Where the search measures a point
      against the arc's ends instead (its angle about ``C`` outside the arc), the
      distance is at most ``Brad + R·g``, ``g`` the angle between that point and
      the end: when ``ρ² − ρ·δ − |dρ/dθ|·δ > 0`` the path turns monotonically
      about ``C`` (``V × V' = ρ² + ρ d·u + ρ' d × u`` with ``V = P − C``), and
      when ``g0 + g1 + ||σ| − |Σ|| + 2·asin(δ/ρmin) < π`` (``g0``, ``g1`` the angles
      of the path's first and last points from the arc's ends, ``Σ`` the exact
      sweep) it does not wrap, so the points outside the arc lie within ``g0``
      of its start or ``g1`` of its end. The last point, the printed end, is
      within ``|e − A1|`` of the arc.

    Args:
        solver: the search it stands in for (grid, rule, direction, exact centre).
        s: the block's start, grid indices.
        e: its end, grid indices.
        c: the rounded exact centre, grid indices.
        ref: the exact arc (or part) the block follows.

    Returns:
        ``True`` when the search surely passes ``c`` (before :func:`arc_error`),
        ``False`` when that is not sure.
    """
    q = solver.grid.mm
    u0x, u0y = (s[0] - c[0]) * q, (s[1] - c[1]) * q
    u1x, u1y = (e[0] - c[0]) * q, (e[1] - c[1]) * q
    r0, r1 = math.hypot(u0x, u0y), math.hypot(u1x, u1y)
    big = max(r0, r1, ref.radius)
    if not (r0 > 0 and r1 > 0 and big < SHORTCUT_MAX_MM and _rule_room(solver.rule, r0, r1)):
        return False
    cross, dot = u0x * u1y - u0y * u1x, u0x * u1x + u0y * u1y
    raw = math.atan2(cross, dot)
    if cross == 0.0 and dot > 0.0:
        raw = 0.0  # both atan2 give ±0 exactly: a full turn either way
    elif abs(raw) <= 2 * GRBL_ANGULAR_EPSILON or abs(abs(raw) - math.pi) <= SLACK_RAD:
        return False
    if solver.clockwise:
        sweep = raw - 2 * math.pi if raw >= -GRBL_ANGULAR_EPSILON else raw
    else:
        sweep = raw + 2 * math.pi if raw <= GRBL_ANGULAR_EPSILON else raw
    turn_gap = abs(abs(sweep) - abs(ref.sweep))
    if turn_gap > math.pi / 2 - SLACK_RAD:
        return False
    rho0 = r0
    rho1 = r0 if solver.rule == "grbl" else r1
    cx, cy = c[0] * q, c[1] * q
    big_c = ref.centre
    dx, dy = cx - big_c[0], cy - big_c[1]
    delta = math.hypot(dx, dy)
    rho_min, rho_max = min(rho0, rho1), max(rho0, rho1)
    slope = abs(rho1 - rho0) / abs(sweep)  # |dρ/dθ|
    if rho_min * rho_min - rho_max * delta - slope * delta <= 1e-6 * rho_min * rho_min:
        return False  # the path may not turn monotonically about the exact centre
    if delta != 0.0 and delta * sweep == 0.0:
        return False  # δ·σ underflows (a centre a subnormal away): _radial_span divides by it
    f_min, f_max = _radial_span(rho0, rho1, u0x, u0y, dx, dy, delta, sweep)
    if f_min <= 0.0:
        return False
    radius = ref.radius
    brad = max(f_max + delta * delta / (2 * f_min) - radius, radius - f_min)
    a0, a1 = ref.at(0.0), ref.at(1.0)
    p1 = (cx + rho1 * u1x / r1, cy + rho1 * u1y / r1)
    g0 = _angle((s[0] * q - big_c[0], s[1] * q - big_c[1]), (a0[0] - big_c[0], a0[1] - big_c[1]))
    g1 = _angle((p1[0] - big_c[0], p1[1] - big_c[1]), (a1[0] - big_c[0], a1[1] - big_c[1]))
    eta = math.asin(min(1.0, delta / rho_min))
    if g0 + g1 + turn_gap + 2 * eta >= math.pi - SLACK_RAD:
        return False
    end_gap = math.hypot(e[0] * q - a1[0], e[1] * q - a1[1])
    if not math.isfinite(brad + g0 + g1 + eta + end_gap):
        return False  # max() would let a NaN through
    bound = max(brad + radius * (max(g0, g1) + SLACK_RAD), end_gap)
    return bound + SLACK_MM <= solver.limit


def _rule_room(rule: str, r0: float, r1: float) -> bool:
    """:func:`rule_ok` on two scalar radii, :data:`SLACK_MM` inside its every bound."""
    m = MARGIN_MM + SLACK_MM
    delta = abs(r1 - r0)
    if rule == "grbl":
        relative = delta <= GRBL_CEILING_MM - m and delta <= GRBL_RELATIVE * r0 - m
        return delta <= GRBL_TOLERANCE_MM - m or relative
    relative = delta <= LINUXCNC_RELATIVE * max(r0, r1) - m
    small = delta <= LINUXCNC_TOLERANCE_MM - m or relative
    big_enough = min(r0, r1) >= LINUXCNC_MIN_RADIUS_MM + m
    return small and delta <= LINUXCNC_CEILING_MM - m and big_enough


def _radial_span(
    rho0: float,
    rho1: float,
    u0x: float,
    u0y: float,
    dx: float,
    dy: float,
    delta: float,
    sweep: float,
) -> tuple[float, float]:
    """Least and greatest ``f(t) = ρ(t) + d·u(θ(t))`` over ``t ∈ [0, 1]`` (mm, ± float noise).

    ``ρ(t) = rho0 + (rho1 − rho0)·t``, ``θ(t) = θ0 + sweep·t`` (``θ0`` the angle of
    ``u0``), ``d = (dx, dy)``: ``f = rho0 + b·t + δ·cos(x0 + sweep·t)`` with
    ``x0 = θ0 − angle(d)``; its extremes are at the ends or where
    ``sin(x0 + sweep·t) = b/(δ·sweep)`` (``b = rho1 − rho0``).
    """
    b = rho1 - rho0
    if delta == 0.0:
        return min(rho0, rho1), max(rho0, rho1)
    x0 = math.atan2(u0y, u0x) - math.atan2(dy, dx)
    values = [rho0 + delta * math.cos(x0), rho1 + delta * math.cos(x0 + sweep)]
    k = b / (delta * sweep)
    if abs(k) <= 1.0 + 1e-9:
        root = math.asin(max(-1.0, min(1.0, k)))
        lo, hi = min(x0, x0 + sweep), max(x0, x0 + sweep)
        for base in (root, math.pi - root):
            n = math.ceil((lo - base) / (2 * math.pi))
            while base + 2 * math.pi * n <= hi:
                x = base + 2 * math.pi * n
                t = (x - x0) / sweep
                if 0.0 < t < 1.0:
                    values.append(rho0 + b * t + delta * math.cos(x))
                n += 1
    return min(values), max(values)


def _angle(v: Point, w: Point) -> float:
    """Unsigned angle between two vectors, rad (0…π)."""
    return math.atan2(abs(v[0] * w[1] - v[1] * w[0]), v[0] * w[0] + v[1] * w[1])


def _disk(rounded: IntArray, exact: FloatArray) -> IntArray:
    """Grid points ``(K, 2)`` within :data:`SEARCH_QUANTA` of the exact centre (in quanta)."""
    import numpy as np  # imported where used (see the module's imports)

    near = np.arange(-math.ceil(SEARCH_QUANTA), math.ceil(SEARCH_QUANTA) + 1)
    disk = rounded + np.array([(a, b) for a in near for b in near], dtype=np.int64)
    return disk[np.hypot(*(disk - exact).T) <= SEARCH_QUANTA]


def _path(
    rule: str,
    centres: FloatArray,
    u0: FloatArray,
    r0: FloatArray,
    r1: FloatArray,
    sweep: FloatArray,
    end: FloatArray,
) -> FloatArray:
    """Points ``(K, SAMPLES + 1, 2)`` (mm) along each candidate block as the controller moves.

    GRBL traces the start radius and goes straight to the end at last
    (``mc_arc``); LinuxCNC changes the radius linearly with the angle, a spiral
    (``pmCirclePoint``).
    """
    import numpy as np  # imported where used (see the module's imports)

    t = np.linspace(0.0, 1.0, SAMPLES)
    angle = np.arctan2(u0[:, 1], u0[:, 0])[:, None] + sweep[:, None] * t
    growth = np.zeros_like(r0) if rule == "grbl" else r1 - r0
    radius = r0[:, None] + np.outer(growth, t)
    x = centres[:, 0, None] + radius * np.cos(angle)
    y = centres[:, 1, None] + radius * np.sin(angle)
    last = np.broadcast_to(end, (len(centres), 1, 2))
    return np.concatenate((np.stack((x, y), axis=-1), last), axis=1)


# -- conform_arc ---------------------------------------------------------------------


@dataclass(frozen=True)
class ArcPiece:
    """One arc block to write: end point and absolute centre (mm, on the print grid).

    The block starts where the previous one ended; ``clockwise=True`` is G2.
    """

    end: Point
    centre: Point
    clockwise: bool


def conform_arc(
    start: Point,
    end: Point,
    centre: Point,
    clockwise: bool,
    *,
    rule: str,
    quantum_mm: float,
    exact_start: Point | None = None,
    shortcut: bool = True,
) -> list[ArcPiece]:
    """Arc blocks on the print grid that the controller accepts, following the exact arc.

    The exact end is rounded to the grid (halves away from zero, as the writer
    rounds) and, if the rounded centre fails :func:`arc_error` or strays, the
    nearby grid centres are tried — the one that best equalises the two radii,
    then the one nearest the exact centre. If none passes (a radius of a few
    quanta, or a coarse grid), the exact arc is halved at its mid angle, the
    mid point rounded to the grid, and each half conformed (recursively, at
    most :data:`MAX_SPLIT_DEPTH` times); a part whose halves fail tries, last,
    grid centres further along its chord's bisector (up to one radius away). A
    full circle stays one block when it passes. Every returned block passes
    :func:`arc_error` from the previous end (with :data:`MARGIN_MM` to spare),
    keeps the direction, sweeps within 90° of its part of the exact arc, and
    its path (as the controller moves) stays within :data:`DEVIATION_QUANTA`
    quanta of it.

    Args:
        start: the printed start the controller holds, mm (must be on the grid).
        end: the exact end, mm.
        centre: the exact absolute centre, mm; the exact radius is ``|end − centre|``.
        clockwise: G2 when True, G3 otherwise.
        rule: ``"grbl"`` or ``"linuxcnc"`` (:data:`RULES`).
        quantum_mm: the writer's resolution, mm (``0.001`` for 3 decimals in mm).
        exact_start: the exact start before rounding, mm. Pass it whenever
            ``start`` was rounded: the arc is a full circle exactly when it equals
            ``end`` (the :class:`~camtool.model.program.ArcMove` convention), and an
            arc whose ends print the same but that is not a full circle gives no
            block. Without it ``start`` is taken as the exact start (a full
            circle is then ``end == start``), and an ``end`` that prints as
            ``start`` without being equal to it is a ValueError: it cannot be
            told from a full circle.
        shortcut: test the rounded centre without the search first
            (:func:`plainly_passes`); the result is the same either way, False
            runs the search alone (tests compare the two).

    Returns:
        The blocks in cutting order, ``[]`` when the arc rounds away to nothing
        (its ends print the same and it lies within the deviation limit of its
        start). The last block ends at the rounded exact end. Coordinates are
        clean multiples of the quantum (``round(k·q, decimals)``).

    Raises:
        DialectError: even halved, the arc cannot be written (its radius is a
            few quanta or less); the message names the radius and the rule.
        UsageError: unknown ``rule`` or a quantum that is not a positive number.
        ValueError: ``start`` is not on the grid, more than a quantum from
            ``exact_start``, or ambiguous as above (caller bugs).
    """
    check_rule(rule)
    grid = Grid.of(quantum_mm)
    s = grid.on_grid(start, "start")
    if exact_start is not None and math.dist(start, exact_start) > grid.mm:
        raise ValueError(f"the arc start {start} is not the rounded exact start {exact_start}")
    e = grid.indices(end)
    if exact_start is None and e == s and start != tuple(end):
        raise ValueError(
            f"the arc end {end} prints as its start {start}: pass exact_start to tell a full "
            "circle from an arc that rounds away"
        )
    ref = _reference(start, end, centre, clockwise, exact_start)
    solver = Solver(grid, rule, clockwise, centre, shortcut)
    if e == s and abs(ref.sweep) < 2 * math.pi:
        import numpy as np  # imported where used (see the module's imports)

        samples = np.array([ref.at(t) for t in np.linspace(0.0, 1.0, SAMPLES)])
        if np.max(np.hypot(samples[:, 0] - start[0], samples[:, 1] - start[1])) <= solver.limit:
            return []
    try:
        blocks = solver.solve(s, e, ref)
    except Unsolvable as exc:
        raise DialectError(
            f"an arc of radius {ref.radius:.4f} mm cannot be written for {rule} at "
            f"{grid.quantum} mm resolution: {exc} — even split in halves, no printable centre "
            f"passes the controller's arc check ({RULE_TEXT[rule]}); write more decimals"
        ) from None
    return [ArcPiece(grid.point(k), grid.point(c), clockwise) for k, c in blocks]


def _reference(
    start: Point, end: Point, centre: Point, clockwise: bool, exact_start: Point | None
) -> Reference:
    """The exact arc: radius from the exact end, from the start's angle to the end's."""
    radius = math.dist(end, centre)
    if radius == 0.0:
        raise DialectError(f"arc ending at its centre {centre}: radius 0")
    first = start if exact_start is None else exact_start
    full = math.dist(first, end) <= 1e-12 * max(1.0, radius)
    a0 = math.atan2(first[1] - centre[1], first[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    sweep = 2 * math.pi if full else (a0 - a1 if clockwise else a1 - a0) % (2 * math.pi)
    return Reference(centre, radius, a0, -sweep if clockwise else sweep)
