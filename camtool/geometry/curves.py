"""Smooth curves as lines and arcs: Béziers and ellipses evaluated, fitted piece by piece.

Design notes: docs/internals.md, ``camtool/geometry/curves.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import TypeAlias

import numpy as np

from camtool.geometry.arcfit import FloatArray, PointsFn, fit_curve
from camtool.geometry.chain import snap, with_end
from camtool.model.shapes import Arc, Point, Segment, distance

PointFn: TypeAlias = Callable[[float], Point]
"""A curve point (or derivative) at a parameter."""


def cubic_bezier(p: tuple[Point, Point, Point, Point]) -> tuple[PointFn, PointFn]:
    """Point and derivative of the cubic Bézier with control points ``p``, for u in [0, 1]."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = p

    def point_at(u: float) -> Point:
        v = 1.0 - u
        w0, w1, w2, w3 = v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u
        return (w0 * x0 + w1 * x1 + w2 * x2 + w3 * x3, w0 * y0 + w1 * y1 + w2 * y2 + w3 * y3)

    def tangent_at(u: float) -> Point:
        v = 1.0 - u
        w0, w1, w2 = 3.0 * v * v, 6.0 * v * u, 3.0 * u * u
        return (
            w0 * (x1 - x0) + w1 * (x2 - x1) + w2 * (x3 - x2),
            w0 * (y1 - y0) + w1 * (y2 - y1) + w2 * (y3 - y2),
        )

    return point_at, tangent_at


def cubic_bezier_points(p: tuple[Point, Point, Point, Point]) -> PointsFn:
    """:func:`cubic_bezier`'s ``point_at`` on an array of parameters: ``(N,)`` -> ``(N, 2)``.

    The same float operations in the same order, element by element, so every point is
    bit for bit the one ``point_at`` gives (IEEE 754 double arithmetic in both; numpy ufuncs
    round each operation like Python floats).
    """
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = p

    def points_at(u: FloatArray) -> FloatArray:
        v = 1.0 - u
        w0, w1, w2, w3 = v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u
        out = np.empty((len(u), 2))
        out[:, 0] = w0 * x0 + w1 * x1 + w2 * x2 + w3 * x3
        out[:, 1] = w0 * y0 + w1 * y1 + w2 * y2 + w3 * y3
        return out

    return points_at


def quadratic_bezier(p: tuple[Point, Point, Point]) -> tuple[PointFn, PointFn]:
    """Point and derivative of the quadratic Bézier with control points ``p``, u in [0, 1]."""
    (x0, y0), (x1, y1), (x2, y2) = p

    def point_at(u: float) -> Point:
        v = 1.0 - u
        w0, w1, w2 = v * v, 2.0 * v * u, u * u
        return (w0 * x0 + w1 * x1 + w2 * x2, w0 * y0 + w1 * y1 + w2 * y2)

    def tangent_at(u: float) -> Point:
        v = 1.0 - u
        return (
            2.0 * (v * (x1 - x0) + u * (x2 - x1)),
            2.0 * (v * (y1 - y0) + u * (y2 - y1)),
        )

    return point_at, tangent_at


def quadratic_bezier_points(p: tuple[Point, Point, Point]) -> PointsFn:
    """:func:`quadratic_bezier`'s ``point_at`` on an array, bit for bit.

    As :func:`cubic_bezier_points`: the same operations in the same order.
    """
    (x0, y0), (x1, y1), (x2, y2) = p

    def points_at(u: FloatArray) -> FloatArray:
        v = 1.0 - u
        w0, w1, w2 = v * v, 2.0 * v * u, u * u
        out = np.empty((len(u), 2))
        out[:, 0] = w0 * x0 + w1 * x1 + w2 * x2
        out[:, 1] = w0 * y0 + w1 * y1 + w2 * y2
        return out

    return points_at


def ellipse(centre: Point, a: Point, b: Point) -> tuple[PointFn, PointFn]:
    """Point and derivative of ``c + a·cos t + b·sin t`` at the angle parameter ``t``, rad.

    With ``a`` the major axis and ``b`` the minor one this is a DXF ELLIPSE (``b`` is the
    extrusion × major axis × ratio, so an extrusion of (0, 0, −1) runs clockwise).
    """
    cx, cy = centre
    mx, my = a
    nx, ny = b

    def point_at(t: float) -> Point:
        c, s = math.cos(t), math.sin(t)
        return (cx + mx * c + nx * s, cy + my * c + ny * s)

    def tangent_at(t: float) -> Point:
        c, s = math.cos(t), math.sin(t)
        return (-mx * s + nx * c, -my * s + ny * c)

    return point_at, tangent_at


def ellipse_extent(centre: Point, a: Point, b: Point, t0: float, t1: float) -> float:
    """Width or height, the larger, of the arc of ``c + a·cos t + b·sin t`` over [t0, t1].

    The part of the ellipse a fit follows, not the whole ellipse: a nearly straight arc
    of an ellipse kilometres across is short. Its box is spanned by the ends and the
    parameters where x' or y' is zero (``tan t = b_x / a_x``, ``tan t = b_y / a_y``);
    ``t0 ≤ t1``, rad, at most a turn apart.
    """
    point_at, _ = ellipse(centre, a, b)
    ts = [t0, t1]
    for e in (math.atan2(b[0], a[0]), math.atan2(b[1], a[1])):
        first = e + math.pi * math.ceil((t0 - e) / math.pi)
        ts += [t for k in range(3) if t0 < (t := first + math.pi * k) < t1]
    xs, ys = zip(*map(point_at, ts), strict=True)
    return max(max(xs) - min(xs), max(ys) - min(ys))


def ellipse_arc(
    centre: Point, a: Point, b: Point, t0: float, sweep: float, p0: Point, p1: Point
) -> tuple[PointFn, PointFn]:
    """The arc of ``c + a·cos t + b·sin t`` from ``t0`` over ``sweep`` rad, for u in [0, 1].

    ``t = t0 + sweep·u``; the ends are exactly ``p0`` (u ≤ 0) and ``p1`` (u ≥ 1), the end
    points the path data gives (SVG elliptical arcs), whatever the rounding of the form.
    """
    cx, cy = centre

    def point_at(u: float) -> Point:
        if u <= 0.0:
            return p0
        if u >= 1.0:
            return p1
        t = t0 + sweep * u
        c, s = math.cos(t), math.sin(t)
        return (cx + a[0] * c + b[0] * s, cy + a[1] * c + b[1] * s)

    def tangent_at(u: float) -> Point:
        t = t0 + sweep * u
        c, s = math.cos(t), math.sin(t)
        return (sweep * (b[0] * c - a[0] * s), sweep * (b[1] * c - a[1] * s))

    return point_at, tangent_at


def ellipse_arc_points(
    centre: Point, a: Point, b: Point, t0: float, sweep: float, p0: Point, p1: Point
) -> PointsFn:
    """:func:`ellipse_arc`'s ``point_at`` on an array, bit for bit.

    Cosine and sine come from :mod:`math` one parameter at a time (numpy's may differ in
    the last bit); the rest is element-wise in the same order.
    """
    cx, cy = centre

    def points_at(u: FloatArray) -> FloatArray:
        t = t0 + sweep * u
        c = np.array([math.cos(x) for x in t.tolist()])
        s = np.array([math.sin(x) for x in t.tolist()])
        out = np.empty((len(u), 2))
        out[:, 0] = cx + a[0] * c + b[0] * s
        out[:, 1] = cy + a[1] * c + b[1] * s
        out[u <= 0.0] = p0
        out[u >= 1.0] = p1
        return out

    return points_at


def semi_axes_gap(a: Point, b: Point, cross: float) -> float:
    """Difference of the semi-axes (singular values) of the ellipse with semi-diameters a, b.

    With s1, s2 the singular values of ``[a b]``: s1² + s2² = |a|² + |b|², s1·s2 = |a × b|,
    so (s1 - s2)² = |a|² + |b|² - 2|a × b|. ``cross`` is ``a × b``. Zero for a circle.
    """
    return math.sqrt(max(0.0, a[0] ** 2 + a[1] ** 2 + b[0] ** 2 + b[1] ** 2 - 2.0 * abs(cross)))


def corner_knots(knots: Sequence[float], p: int, t0: float, t1: float) -> list[float]:
    """Inner knots of multiplicity ≥ p (the B-spline of degree p is only C0 there), ascending."""
    inner = [float(k) for k in knots if t0 < k < t1]
    return [k for k, run in itertools.groupby(inner) if len(list(run)) >= p]


def fit_pieces(
    point_at: PointFn,
    tangent_at: PointFn,
    breaks: Sequence[float],
    tolerance: float,
    closed: bool,
    points_at: PointsFn | None = None,
) -> list[Segment]:
    """Fit each piece between ``breaks``; tangents at a piece's end are taken from inside.

    A closed curve's last point is snapped onto its first (they are within the
    tolerance; for full ellipses and periodic splines within rounding).

    Args:
        point_at: curve point at a parameter in ``[breaks[0], breaks[-1]]``.
        tangent_at: curve derivative there (any length, towards increasing parameter).
        breaks: ascending parameters: both ends and the possible corners between.
        tolerance: largest distance between curve and output, both ways (> 0).
        closed: the curve ends where it starts.
        points_at: optional, ``point_at`` on an array of parameters at once, bit for bit
            (:func:`~camtool.geometry.arcfit.fit_curve`).

    Returns:
        Segments each starting exactly where the one before ends; empty when the curve is
        one point.

    Raises:
        GeometryError: a piece could not be fitted (from
            :func:`~camtool.geometry.arcfit.fit_curve`).
        UsageError: bad ``tolerance`` or parameter range.
    """
    segs: list[Segment] = []
    for a, b in itertools.pairwise(breaks):
        inside = math.nextafter(b, -math.inf)

        def tangent(t: float, inside: float = inside) -> Point:
            return tangent_at(min(t, inside))

        segs.extend(fit_curve(point_at, tangent, a, b, tolerance, points_at=points_at))
    return joined_run(segs, closed)


def joined_run(segs: Sequence[Segment], closed: bool) -> list[Segment]:
    """A curve's pieces' fits as one run: each segment starts where the one before ends.

    A closed curve's last point is moved onto its first.

    Args:
        segs: the pieces' segments, each piece starting where the one before ends (to
            ~1e-15 mm), mm.
        closed: the curve ends where it starts (within the tolerance it was fitted to).

    Returns:
        The segments moved onto each other's ends; empty when ``segs`` is.
    """
    if not segs:
        return []
    out = snap(segs)
    if closed and out[-1].end != out[0].start:
        out[-1] = with_end(out[-1], out[0].start)
    return out


def merge_arcs(segs: list[Segment]) -> list[Segment]:
    """Join neighbouring arcs of one circle and direction (total sweep up to a full turn).

    Centres and radii must agree within 1e-9 × max(1, radius) and the sweeps must add up:
    arcs that were one arc before the drawing split them (a circle's quarters).
    """
    out: list[Segment] = []
    for seg in segs:
        prev = out[-1] if out else None
        if isinstance(prev, Arc) and isinstance(seg, Arc) and prev.clockwise == seg.clockwise:
            r = max(1.0, prev.radius)
            same = distance(prev.centre, seg.centre) <= 1e-9 * r
            if same and abs(prev.radius - seg.radius) <= 1e-9 * r:
                joined = Arc(prev.start, seg.end, prev.centre, prev.clockwise)
                if abs(joined.sweep - prev.sweep - seg.sweep) <= 1e-9:
                    out[-1] = joined
                    continue
        out.append(seg)
    return out
