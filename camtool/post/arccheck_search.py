"""The search behind :func:`camtool.post.arccheck.conform_arc`: printable centres and splits.

Grid points are integer index pairs ``(i, j)`` for the point ``(i·q, j·q)`` mm.
A block from grid point ``s`` to ``e`` gets the rounded exact centre if the
controller accepts it and the path stays near the exact arc; else the nearby
grid centres are tried; if none passes, the exact arc is halved and each half
solved on its own; a part that cannot be halved into solvable halves tries the
centres along its chord's bisector (further from the exact centre) last.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.model.shapes import Point
from camtool.post.arccheck_rules import arc_error, max_difference, rule_ok, travel

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
IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Grid:
    """The points the writer can print: integer multiples of ``quantum`` mm."""

    quantum: Decimal

    @classmethod
    def of(cls, quantum_mm: float) -> Grid:
        """The grid of a resolution in mm.

        Raises:
            UsageError: ``quantum_mm`` is not a positive finite number.
        """
        if not (math.isfinite(quantum_mm) and quantum_mm > 0):
            raise UsageError(f"the arc quantum must be a positive number of mm, got {quantum_mm!r}")
        return cls(Decimal(repr(float(quantum_mm))))

    @property
    def mm(self) -> float:
        """The quantum, mm."""
        return float(self.quantum)

    def index(self, value_mm: float) -> int:
        """Nearest grid index, halves away from zero (as ``NumberFormat`` rounds)."""
        q = Decimal(repr(float(value_mm))) / self.quantum
        return int(q.quantize(Decimal(1), rounding=ROUND_HALF_UP))

    def indices(self, p: Point) -> Index:
        """The grid point nearest ``p`` (mm)."""
        return self.index(p[0]), self.index(p[1])

    def value(self, k: int) -> float:
        """Grid index ``k`` in mm: the float of the exact decimal, so it prints as itself."""
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


def _disk(rounded: IntArray, exact: FloatArray) -> IntArray:
    """Grid points ``(K, 2)`` within :data:`SEARCH_QUANTA` of the exact centre (in quanta)."""
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
    t = np.linspace(0.0, 1.0, SAMPLES)
    angle = np.arctan2(u0[:, 1], u0[:, 0])[:, None] + sweep[:, None] * t
    growth = np.zeros_like(r0) if rule == "grbl" else r1 - r0
    radius = r0[:, None] + np.outer(growth, t)
    x = centres[:, 0, None] + radius * np.cos(angle)
    y = centres[:, 1, None] + radius * np.sin(angle)
    last = np.broadcast_to(end, (len(centres), 1, 2))
    return np.concatenate((np.stack((x, y), axis=-1), last), axis=1)
