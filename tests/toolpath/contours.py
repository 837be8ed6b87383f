"""Canonical contours for the compensation and offset tests (mm, counter-clockwise as drawn)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from camtool.geometry.arcfit import distances
from camtool.model.shapes import Arc, Contour, Line, Point, Segment
from tests.shapes import segment_samples


def polygon(points: Sequence[Point]) -> Contour:
    """A closed contour of lines through ``points`` in order."""
    n = len(points)
    return Contour(tuple(Line(points[i], points[(i + 1) % n]) for i in range(n)), True)


def rect(x0: float, y0: float, x1: float, y1: float) -> Contour:
    """A counter-clockwise rectangle starting at its lower-left corner."""
    return polygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def circle(cx: float, cy: float, r: float) -> Contour:
    """A counter-clockwise full circle, one arc starting at its rightmost point."""
    return Contour((Arc((cx + r, cy), (cx + r, cy), (cx, cy), False),), True)


def stadium(x0: float, x1: float, y: float, r: float) -> Contour:
    """A slot: the centres of its semicircular ends at ``(x0, y)`` and ``(x1, y)``, radius r."""
    segs: list[Segment] = [
        Line((x0, y - r), (x1, y - r)),
        Arc((x1, y - r), (x1, y + r), (x1, y), False),
        Line((x1, y + r), (x0, y + r)),
        Arc((x0, y + r), (x0, y - r), (x0, y), False),
    ]
    return Contour(tuple(segs), True)


def dumbbell() -> Contour:
    """Two 10 × 10 squares joined by a 10 mm long waist 2 mm wide (y from 4 to 6)."""
    return polygon(
        [(0, 0), (10, 0), (10, 4), (20, 4), (20, 0), (30, 0),
         (30, 10), (20, 10), (20, 6), (10, 6), (10, 10), (0, 10)]
    )  # fmt: skip


def l_shape() -> Contour:
    """A 10 × 10 L, legs 3 mm wide, its one inside corner at (3, 3)."""
    return polygon([(0, 0), (10, 0), (10, 3), (3, 3), (3, 10), (0, 10)])


def two_way_distance(a: Sequence[Contour], b: Sequence[Contour]) -> float:
    """Largest distance from sample points of ``a`` to ``b``'s segments and back, mm."""
    segs_a = [s for c in a for s in c.segments]
    segs_b = [s for c in b for s in c.segments]
    there = max(float(np.max(distances(segment_samples(c.segments), segs_b))) for c in a)
    back = max(float(np.max(distances(segment_samples(c.segments), segs_a))) for c in b)
    return max(there, back)


def ccw(contour: Contour) -> bool:
    """True when the closed contour runs counter-clockwise."""
    return contour.signed_area() > 0


def radius_of(seg: Segment) -> float:
    """An arc's radius, ``math.inf`` for a line."""
    return seg.radius if isinstance(seg, Arc) else math.inf
