"""SVG path segments to exact lines and arcs (mm, Y up), Béziers and ellipses biarc-fitted.

The SVG importer hands each shape's segments here in the shape's own (local) coordinates,
together with the full affine map from those coordinates to mm with Y up. Every curve is
mapped exactly before it is judged: a Bézier's control points map to the control points of
the image curve, and an elliptical arc ``c + a·cos t + b·sin t`` maps to ``C + A·cos t + B·sin t``
with ``A``, ``B`` the images of its conjugate semi-diameters ``a``, ``b``. The image is a circle
when ``A`` and ``B`` are perpendicular and of equal length, i.e. when the two singular values
of ``[A B]`` agree; a circle under a non-uniform scale or a skew is an ellipse and is fitted.

Sources: SVG 1.1 §8.3 (path data) and implementation notes F.6 (elliptical arcs);
segments are parsed by svgelements (``Move``, ``Line``, ``Close``, ``Arc``,
``QuadraticBezier``, ``CubicBezier``); curves are fitted by
:func:`camtool.geometry.arcfit.fit_curve`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from typing import Any, TypeAlias

import svgelements as se

from camtool.geometry.arcfit import fit_curve
from camtool.importers import MAX_COORDINATE_MM, check_curve_size
from camtool.model.errors import InputError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment, distance

Affine: TypeAlias = tuple[float, float, float, float, float, float]
"""``(a, b, c, d, e, f)``: ``x' = a·x + c·y + e``, ``y' = b·x + d·y + f`` (SVG's ``matrix()``)."""

IDENTITY: Affine = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)
ZERO_LENGTH_MM = 1e-9
"""Segments shorter than this (mm) are dropped; ends closer than this are one point."""
_SEMI = 1e-7  # a centre this close (× chord) to the chord midpoint is a half ellipse


def compose(outer: Affine, inner: Affine) -> Affine:
    """The map ``outer ∘ inner``: ``inner`` is applied first."""
    a1, b1, c1, d1, e1, f1 = outer
    a2, b2, c2, d2, e2, f2 = inner
    return (
        a1 * a2 + c1 * b2,
        b1 * a2 + d1 * b2,
        a1 * c2 + c1 * d2,
        b1 * c2 + d1 * d2,
        a1 * e2 + c1 * f2 + e1,
        b1 * e2 + d1 * f2 + f1,
    )


def apply(m: Affine, x: float, y: float) -> Point:
    """The image of the point ``(x, y)`` under ``m``."""
    return (m[0] * x + m[2] * y + m[4], m[1] * x + m[3] * y + m[5])


def affine_of(matrix: Any) -> Affine:
    """An svgelements ``Matrix`` as an :data:`Affine`."""
    return (
        float(matrix.a),
        float(matrix.b),
        float(matrix.c),
        float(matrix.d),
        float(matrix.e),
        float(matrix.f),
    )


Subpath: TypeAlias = tuple[tuple[Segment, ...], bool]
"""One subpath's segments (each starting where the previous ended) and whether it is closed."""


def convert(segments: Iterable[Any], m: Affine, tolerance: float) -> list[Subpath]:
    """Turn svgelements path segments (local coordinates) into subpaths in mm, Y up.

    Each ``Move`` starts a subpath; ``Close`` draws the line back to the subpath's start
    (unless already there) and closes it. A subpath whose last point is within 1e-9 mm of
    its first is closed too. Zero-length segments are dropped; consecutive arcs on one
    circle (a ``<circle>``'s quarters, an arc split in two) are merged.

    Args:
        segments: svgelements segments of one shape, untransformed.
        m: local coordinates to mm, Y up.
        tolerance: largest distance, mm, between a Bézier or a non-circular elliptical arc
            and the arcs and lines fitted to it (> 0).

    Returns:
        ``(segments, closed)`` per subpath that draws something.

    Raises:
        GeometryError: a curve could not be fitted (from :func:`fit_curve`).
        InputError: a point, control point or arc centre is NaN, infinite or beyond
            ±:data:`~camtool.importers.MAX_COORDINATE_MM` once mapped to mm (checked
            before any fitting, which would spin on a control point at 1e20).
    """
    out: list[Subpath] = []
    current: list[Segment] = []
    start: Point | None = None
    cursor: Point | None = None

    def flush(closed: bool) -> None:
        if current:
            segs = _merge_arcs(current)
            if start is not None and distance(segs[-1].end, start) <= ZERO_LENGTH_MM:
                segs[-1] = _with_end(segs[-1], start)
                closed = True
            out.append((tuple(segs), closed))
        current.clear()

    for seg in segments:
        if isinstance(seg, se.Move):
            flush(False)
            start = cursor = _pt(m, seg.end)
            continue
        if cursor is None or start is None:  # svgelements always starts with Move
            start = cursor = _pt(m, seg.start)
        if isinstance(seg, se.Close):
            if distance(cursor, start) > ZERO_LENGTH_MM:
                current.append(Line(cursor, start))
            flush(True)
            cursor = start
            continue
        new = segment(seg, cursor, m, tolerance)
        for piece in new:
            if isinstance(piece, Arc):
                _check(piece.centre, "an arc centre")
        current.extend(new)
        if new:
            cursor = new[-1].end
    flush(False)
    return out


def segment(seg: Any, p0: Point, m: Affine, tolerance: float) -> list[Segment]:
    """One svgelements drawing segment from ``p0`` (mm, already mapped) as lines and arcs.

    Raises:
        ValueError: ``seg`` is of a kind svgelements does not produce in a path.
    """
    if isinstance(seg, se.Line):
        return _line(p0, _pt(m, seg.end))
    if isinstance(seg, se.CubicBezier):
        ctrl = (p0, _pt(m, seg.control1), _pt(m, seg.control2), _pt(m, seg.end))
        _check_size(ctrl, tolerance)
        return _fit(*_cubic(ctrl), tolerance)
    if isinstance(seg, se.QuadraticBezier):
        ctrl3 = (p0, _pt(m, seg.control), _pt(m, seg.end))
        _check_size(ctrl3, tolerance)
        return _fit(*_quadratic(ctrl3), tolerance)
    if isinstance(seg, se.Arc):
        return _arc(seg, p0, m, tolerance)
    raise ValueError(f"unexpected path segment {type(seg).__name__}")


def _pt(m: Affine, p: Any) -> Point:
    """``p`` mapped to mm, checked to be finite and within the bound."""
    return _check(apply(m, float(p.x), float(p.y)), "a point")


def _check_size(points: Iterable[Point], tolerance: float) -> None:
    """Refuse a curve whose control points span too much for ``tolerance`` (InputError)."""
    xs, ys = zip(*points, strict=True)
    try:
        check_curve_size(2.0 * max(max(xs) - min(xs), max(ys) - min(ys)), tolerance)
    except ValueError as exc:
        raise InputError(str(exc).replace(" across", " mm across", 1)) from None


def _check(p: Point, what: str) -> Point:
    x, y = p
    if not (abs(x) <= MAX_COORDINATE_MM and abs(y) <= MAX_COORDINATE_MM):
        raise InputError(
            f"{what} at ({x:g}, {y:g}) mm, not a finite number within ±1e9 mm; the "
            "path data, a transform or the viewBox holds a number far too large"
        )
    return p


def _line(p0: Point, p1: Point) -> list[Segment]:
    return [Line(p0, p1)] if distance(p0, p1) > ZERO_LENGTH_MM else []


PointFn: TypeAlias = Callable[[float], Point]


def _fit(point_at: PointFn, tangent_at: PointFn, tolerance: float) -> list[Segment]:
    segs = fit_curve(point_at, tangent_at, 0.0, 1.0, tolerance)
    return segs if sum(s.length for s in segs) > ZERO_LENGTH_MM else []


def _cubic(p: tuple[Point, Point, Point, Point]) -> tuple[PointFn, PointFn]:
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


def _quadratic(p: tuple[Point, Point, Point]) -> tuple[PointFn, PointFn]:
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


def _arc(seg: Any, p0: Point, m: Affine, tolerance: float) -> list[Segment]:
    """An svgelements elliptical arc: an exact Arc where its image is a circle, else fitted.

    svgelements keeps the arc as centre ``c``, ``prx`` (the point at t = 0), ``pry`` (at
    t = π/2) and a signed ``sweep`` in t, so the local curve is ``c + a cos t + b sin t``
    with ``a = prx - c``, ``b = pry - c``.
    """
    p1 = _pt(m, seg.end)
    sweep = float(seg.sweep or 0.0)
    (cx, cy), (sx, sy), (ex, ey) = _xy(seg.center), _xy(seg.start), _xy(seg.end)
    ax, ay = float(seg.prx.x) - cx, float(seg.prx.y) - cy
    bx, by = float(seg.pry.x) - cx, float(seg.pry.y) - cy
    det = ax * by - ay * bx
    if sweep == 0.0 or not math.isfinite(det) or abs(det) <= 1e-300:
        return _line(p0, p1)  # SVG F.6.2: a zero radius makes a straight line
    # svgelements takes the centre from sqrt(max-radius-correction), which leaves ~1e-8
    # of noise on half ellipses (radii scaled up to fit the chord); put them back exactly
    mx, my = 0.5 * (sx + ex), 0.5 * (sy + ey)
    if math.hypot(cx - mx, cy - my) <= _SEMI * math.hypot(ex - sx, ey - sy):
        cx, cy, sweep = mx, my, math.copysign(math.pi, sweep)
    dx, dy = sx - cx, sy - cy
    t0 = math.atan2((ax * dy - ay * dx) / det, (dx * by - dy * bx) / det)
    centre = apply(m, cx, cy)
    big_a = (m[0] * ax + m[2] * ay, m[1] * ax + m[3] * ay)
    big_b = (m[0] * bx + m[2] * by, m[1] * bx + m[3] * by)
    cross = big_a[0] * big_b[1] - big_a[1] * big_b[0]
    if _axes_gap(big_a, big_b, cross) <= 0.1 * tolerance:
        return _circular(p0, p1, centre, ccw=cross * sweep > 0.0, sweep=sweep)
    _check(centre, "an ellipse centre")
    _check_size([centre, (centre[0] + big_a[0], centre[1] + big_a[1]),
                 (centre[0] + big_b[0], centre[1] + big_b[1]), p0, p1], tolerance)  # fmt: skip
    return _fit(*_ellipse(centre, big_a, big_b, t0, sweep, p0, p1), tolerance)


def _xy(p: Any) -> Point:
    return (float(p.x), float(p.y))


def _axes_gap(a: Point, b: Point, cross: float) -> float:
    """Difference of the semi-axes (singular values) of the ellipse with semi-diameters a, b.

    With s1, s2 the singular values of ``[a b]``: s1² + s2² = |a|² + |b|², s1·s2 = |a × b|,
    so (s1 - s2)² = |a|² + |b|² - 2|a × b|.
    """
    return math.sqrt(max(0.0, a[0] ** 2 + a[1] ** 2 + b[0] ** 2 + b[1] ** 2 - 2.0 * abs(cross)))


def _circular(p0: Point, p1: Point, centre: Point, *, ccw: bool, sweep: float) -> list[Segment]:
    if distance(p0, p1) <= ZERO_LENGTH_MM:
        if abs(abs(sweep) - TAU) > 1e-9:
            return []  # SVG F.6.2: an arc whose ends coincide is omitted
        return [Arc(p0, p0, centre, not ccw)]
    # centre exactly on the bisector of the chord, so both ends are on one circle
    (x0, y0), (x1, y1) = p0, p1
    mx, my = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    chord = math.hypot(x1 - x0, y1 - y0)
    nx, ny = -(y1 - y0) / chord, (x1 - x0) / chord
    lam = (centre[0] - mx) * nx + (centre[1] - my) * ny
    return [Arc(p0, p1, (mx + lam * nx, my + lam * ny), not ccw)]


def _ellipse(
    centre: Point, a: Point, b: Point, t0: float, sweep: float, p0: Point, p1: Point
) -> tuple[PointFn, PointFn]:
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


def _with_end(seg: Segment, end: Point) -> Segment:
    if isinstance(seg, Line):
        return Line(seg.start, end)
    return Arc(seg.start, end, seg.centre, seg.clockwise)


def _merge_arcs(segs: list[Segment]) -> list[Segment]:
    """Join neighbouring arcs of one circle and direction (total sweep up to a full turn)."""
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
