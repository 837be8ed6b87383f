"""DXF curves without an exact arc form: ELLIPSE and SPLINE, fitted with biarcs.

Both entities live in the WCS. Their true curve is evaluated with ezdxf's construction
tools (:class:`ezdxf.math.ConstructionEllipse`, :class:`ezdxf.math.BSpline`) and fitted by
the shared fitter :func:`camtool.geometry.arcfit.fit_curve`, so the output lies within the
tolerance of the curve and the curve within the tolerance of the output. A circular
ellipse (both axes equal) is returned as exact arcs, without fitting.

Everything here is in drawing units (the caller scales to mm afterwards), so the
tolerance passed in must already be in drawing units.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import Any

from camtool.geometry.arcfit import fit_curve
from camtool.model.errors import GeometryError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment, distance

_RELATIVE = 1e-9  # times the size: a z spread that is still planar, ends that coincide
_CIRCULAR = 1e-3  # an ellipse whose axes differ by < this share of the tolerance is a circle


class Unsupported(Exception):
    """An entity that cannot become a contour; ``reason`` is the user-facing why."""

    def __init__(self, reason: str, detail: str = "") -> None:
        super().__init__(reason)
        self.reason = reason
        self.detail = detail


class BadEntity(ValueError):
    """An entity holds a number camtool refuses; the message names the entity and value.

    Raised by :func:`camtool.importers.dxf_entities.check_numbers`; the DXF importer
    turns it into an :class:`~camtool.model.errors.InputError` naming the file.
    """


def ellipse_segments(entity: Any, tolerance: float) -> tuple[list[Segment], bool]:
    """An ELLIPSE as lines and arcs within ``tolerance``, and whether it is closed.

    The curve is ``c + M cos t + m sin t`` for ``t`` from ``start_param`` to
    ``end_param`` counter-clockwise about the extrusion, with ``M`` the major axis and
    ``m = extrusion × M · ratio`` (DXF reference, ELLIPSE); an extrusion of (0, 0, −1)
    therefore runs clockwise seen from +Z. An ellipse sweeping more than half a turn
    whose two ends meet within the tolerance is closed (full): CAD programs that round
    ``end_param`` to 6.28318 still give a closed contour.

    Args:
        entity: an ezdxf ``Ellipse`` (WCS), possibly a virtual one from a block.
        tolerance: largest distance between curve and output, drawing units (> 0).

    Returns:
        ``(segments, closed)`` in drawing units, Y up.

    Raises:
        Unsupported: the ellipse is not parallel to XY, or has zero size.
    """
    if not math.hypot(*entity.dxf.major_axis) > 0.0:
        raise Unsupported("zero size")  # ezdxf's construction tool refuses a null axis
    ce = entity.construction_tool()
    ex, ey, ez = ce.extrusion
    if abs(ex) > 1e-9 or abs(ey) > 1e-9 or abs(ce.major_axis[2]) > 1e-9 * ce.major_axis.magnitude:
        raise Unsupported("not parallel to XY")
    (cx, cy), (mx, my), (nx, ny) = _xy(ce.center), _xy(ce.major_axis), _xy(ce.minor_axis)
    a, b = math.hypot(mx, my), math.hypot(nx, ny)
    if a <= 0.0 or b <= 0.0:
        raise Unsupported("zero size")
    _check_size(2.0 * max(a, b), tolerance)
    t0 = float(ce.start_param)
    t1 = float(ce.end_param)
    if t1 <= t0:
        t1 += TAU * math.ceil((t0 - t1) / TAU + 1e-15)
    t1 = min(t1, t0 + TAU)

    def point_at(t: float) -> Point:
        c, s = math.cos(t), math.sin(t)
        return (cx + mx * c + nx * s, cy + my * c + ny * s)

    def tangent_at(t: float) -> Point:
        c, s = math.cos(t), math.sin(t)
        return (-mx * s + nx * c, -my * s + ny * c)

    closed = t1 - t0 >= TAU or (
        t1 - t0 > math.pi and distance(point_at(t0), point_at(t1)) <= tolerance
    )
    if closed:
        t1 = t0 + TAU
    if abs(a - b) <= _CIRCULAR * tolerance:
        start = point_at(t0)
        end = start if closed else point_at(t1)
        return [Arc(start, end, (cx, cy), ez < 0)], closed
    return _fit(point_at, tangent_at, [t0, t1], tolerance, closed), closed


def spline_segments(entity: Any, tolerance: float) -> tuple[list[Segment], bool]:
    """A SPLINE (any degree, rational or not, control or fit points) as lines and arcs.

    The curve is the B-spline over its valid domain ``[u_p, u_n]`` (p the degree,
    n the control point count; the same as ``[0, max_t]`` for clamped splines, the
    periodic part for closed unclamped ones). It is fitted piecewise between knots
    of multiplicity ≥ p, where the curve may have a corner. Splines given by fit points
    only are rebuilt as AutoCAD does (:func:`ezdxf.math.fit_points_to_cad_cv`, with the
    stored end tangents); a closed one is closed through its first fit point. The contour
    is closed when the spline's ends coincide, or when it is flagged closed and its ends
    meet within the tolerance.

    Args:
        entity: an ezdxf ``Spline`` (WCS), possibly a virtual one from a block.
        tolerance: largest distance between curve and output, drawing units (> 0).

    Returns:
        ``(segments, closed)`` in drawing units, Y up.

    Raises:
        Unsupported: invalid spline data, a spline not parallel to XY, or one whose
            curve is a single point.
    """
    spline = _construction(entity)
    pts = spline.control_points
    zs = [p[2] for p in pts]
    size = max(1.0, *(max(abs(p[0]), abs(p[1])) for p in pts))
    if max(zs) - min(zs) > _RELATIVE * size:
        raise Unsupported("not parallel to XY")
    p, n = spline.degree, spline.count
    knots = spline.knots()
    t0, t1 = float(knots[p]), float(knots[n])
    if not t1 > t0:
        raise Unsupported("invalid spline data", "empty parameter range")
    breaks = [t0, *_corner_knots(knots, p, t0, t1), t1]
    xs, ys = [q[0] for q in pts], [q[1] for q in pts]
    _check_size(max(max(xs) - min(xs), max(ys) - min(ys)), tolerance)

    def point_at(t: float) -> Point:
        return _xy(spline.point(t))

    gap = distance(point_at(t0), point_at(t1))
    closed = gap <= _RELATIVE * size or (bool(entity.closed) and gap <= tolerance)
    return _fit(point_at, lambda t: _xy(spline.derivative(t, 1)[1]), breaks, tolerance, closed), (
        closed
    )


def _check_size(extent: float, tolerance: float) -> None:
    from camtool.importers import check_curve_size

    try:
        check_curve_size(extent, tolerance)
    except ValueError as exc:
        raise BadEntity(f"{exc} (drawing units)") from None


def _construction(entity: Any) -> Any:
    """The entity's BSpline, with AutoCAD-style periodic knot vectors unwrapped."""
    from ezdxf.math import BSpline, fit_points_to_cad_cv

    try:
        if entity.control_point_count() == 0 and entity.fit_point_count() > 0 and entity.closed:
            fit = [tuple(v) for v in entity.fit_points]
            if distance(_xy(fit[0]), _xy(fit[-1])) > 0.0:
                fit.append(fit[0])
            tangents = None
            if entity.dxf.hasattr("start_tangent") and entity.dxf.hasattr("end_tangent"):
                tangents = [entity.dxf.start_tangent, entity.dxf.end_tangent]
            return fit_points_to_cad_cv(fit, tangents=tangents)
        count = entity.control_point_count()
        if entity.closed and count and len(entity.knots) == count + 1:
            cps, knots, weights = _unwrap_periodic(
                [tuple(v) for v in entity.control_points],
                list(entity.knots),
                list(entity.weights),
                int(entity.dxf.degree),
            )
            return BSpline(cps, int(entity.dxf.degree) + 1, knots, weights or None)
        return entity.construction_tool()
    except (ValueError, IndexError, ZeroDivisionError) as exc:  # ezdxf's DXFValueError too
        raise Unsupported("invalid spline data", str(exc)) from exc


def _unwrap_periodic(
    cps: list[tuple[float, ...]], knots: list[float], weights: list[float], p: int
) -> tuple[list[tuple[float, ...]], list[float], list[float]]:
    """Periodic spline stored with ``n + 1`` knots (ObjectARX style) as an unclamped one.

    The ``n`` knot intervals repeat with the period; the first ``p`` control points (and
    weights) are appended, and ``p`` knots are added on each side, so that the valid
    domain ``[u_p, u_n]`` of the result is the stored ``[k_0, k_n]``.
    """
    n = len(cps)
    d = [knots[i + 1] - knots[i] for i in range(n)]
    left = [knots[0]]
    for i in range(p):
        left.insert(0, left[0] - d[(n - 1 - i) % n])
    right = [knots[n] + (knots[i] - knots[0]) for i in range(1, p + 1)]
    full = left[:-1] + knots + right
    return cps + cps[:p], full, (weights + weights[:p]) if weights else []


def _corner_knots(knots: Sequence[float], p: int, t0: float, t1: float) -> list[float]:
    """Inner knots of multiplicity ≥ p (the curve is only C0 there), ascending."""
    inner = [float(k) for k in knots if t0 < k < t1]
    return [k for k, run in itertools.groupby(inner) if len(list(run)) >= p]


def _fit(
    point_at: Callable[[float], Point],
    tangent_at: Callable[[float], Point],
    breaks: Sequence[float],
    tolerance: float,
    closed: bool,
) -> list[Segment]:
    """Fit each piece between ``breaks``; tangents at a piece's end are taken from inside.

    A closed curve's last point is snapped onto its first (they are within the
    tolerance; for full ellipses and periodic splines within rounding).
    """
    segs: list[Segment] = []
    for a, b in itertools.pairwise(breaks):
        inside = math.nextafter(b, -math.inf)

        def tangent(t: float, inside: float = inside) -> Point:
            return tangent_at(min(t, inside))

        try:
            segs.extend(fit_curve(point_at, tangent, a, b, tolerance))
        except GeometryError as exc:
            raise Unsupported("curve could not be fitted", str(exc)) from exc
    if not segs:
        raise Unsupported("zero length")
    segs = _snap(segs)
    if closed and segs[-1].end != segs[0].start:
        last = segs[-1]
        segs[-1] = (
            Line(last.start, segs[0].start)
            if isinstance(last, Line)
            else Arc(last.start, segs[0].start, last.centre, last.clockwise)
        )
    return segs


def _snap(segs: list[Segment]) -> list[Segment]:
    """Make each segment start exactly where the one before ends (pieces meet to ~1e-15)."""
    out = [segs[0]]
    for seg in segs[1:]:
        prev = out[-1].end
        if seg.start != prev:
            seg = (
                Line(prev, seg.end)
                if isinstance(seg, Line)
                else Arc(prev, seg.end, seg.centre, seg.clockwise)
            )
        out.append(seg)
    return out


def _xy(p: Any) -> Point:
    return (float(p[0]), float(p[1]))
