"""The bulk nesting (shapely array functions, one query) equals the one-by-one nesting.

Issue 17: :func:`camtool.toolpath.order.nesting` builds every outline and polygon in one
call each; :func:`~camtool.toolpath.order.nesting_one_by_one` is the kept slow form. Both
must give the same parents on many random drawings: nested, touching, duplicated,
open, self-crossing and degenerate contours.
"""

from __future__ import annotations

import itertools
import math
import random

import pytest

from camtool.model.shapes import Arc, Contour, Line, Point
from camtool.toolpath import order
from camtool.toolpath.order import nesting, nesting_one_by_one


def _polygon(points: list[Point], closed: bool = True) -> Contour:
    ring = [*points, points[0]] if closed else points
    segs = tuple(Line(a, b) for a, b in itertools.pairwise(ring) if a != b)
    return Contour(segs, closed)


def _circle(cx: float, cy: float, r: float, cw: bool) -> Contour:
    p = (cx + r, cy)
    return Contour((Arc(p, p, (cx, cy), cw),), True)


def _random_drawing(rng: random.Random) -> list[Contour]:
    out: list[Contour] = []
    for _ in range(rng.randint(0, 25)):
        kind = rng.random()
        cx, cy = rng.uniform(0, 50), rng.uniform(0, 50)
        size = rng.choice([0.5, 2.0, 5.0, 10.0, 20.0])
        if kind < 0.3:
            out.append(_circle(cx, cy, size, rng.random() < 0.5))
        elif kind < 0.6:
            pts = [(cx, cy), (cx + size, cy), (cx + size, cy + size), (cx, cy + size)]
            out.append(_polygon(pts if rng.random() < 0.5 else pts[::-1]))
        elif kind < 0.75:  # a bow tie (self-crossing; buffer(0) repairs it)
            out.append(
                _polygon([(cx, cy), (cx + size, cy + size), (cx + size, cy), (cx, cy + size)])
            )
        elif kind < 0.9:  # open polyline
            n = rng.randint(2, 6)
            pts = [(cx + rng.uniform(0, size), cy + rng.uniform(0, size)) for _ in range(n)]
            out.append(_polygon(pts, closed=False))
        elif out:  # an exact duplicate of an earlier one
            out.append(rng.choice(out))
    return out


@pytest.mark.parametrize("seed", range(60))
def test_bulk_equals_one_by_one(seed: int) -> None:
    contours = _random_drawing(random.Random(seed))
    points = [c.points(order._NEST_TOLERANCE_MM) for c in contours]
    closed = [i for i, c in enumerate(contours) if c.closed]
    assert nesting(contours) == nesting_one_by_one(points, closed)
    assert order._nesting_bulk(points, closed) == nesting_one_by_one(points, closed)


def test_empty_and_nested_squares() -> None:
    assert nesting([]) == nesting_one_by_one([], [])
    squares = [_polygon([(-s, -s), (s, -s), (s, s), (-s, s)]) for s in (3.0, 2.0, 1.0)]
    assert nesting(squares).parents == ((), (0,), (0, 1))


def test_degenerate_ring_raises_as_before() -> None:
    """A closed contour of 2 distinct points (there and back): both refuse it alike."""
    there_back = Contour((Line((0, 0), (1, 0)), Line((1, 0), (0, 0))), True)
    contours = [there_back, _circle(0.0, 0.0, math.pi, False)]
    points = [c.points(order._NEST_TOLERANCE_MM) for c in contours]
    try:
        expected = nesting_one_by_one(points, [0, 1])
    except ValueError as exc:
        with pytest.raises(type(exc)):
            nesting(contours)
    else:
        assert nesting(contours) == expected
