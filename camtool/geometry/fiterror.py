"""The curve fit's distances in operations that round the same everywhere.

:func:`~camtool.geometry.arcfit.fit_curve` decides each piece by comparing sampled
distances with the tolerance, and builds its arcs from unit tangents. Everything here uses
``+ − × ÷`` and ``√`` (IEEE 754 rounds each exactly), and ``math.atan2``/``math.cos``/
``math.sin`` of the C library one value at a time, never numpy's vectorised transcendental
functions (which may differ from the C library in the last bit on some processors) nor
``math.hypot`` (CPython's own algorithm). The compiled fitter of the accel layer
(``camtool/accel/fitkernels.py``) computes the same operations in the same order, so both
give the same floats and the same fit.

Shapes: points are ``(N, 2)`` float64 arrays in mm; segments are given by their floats
(``start``, ``end``, ``centre``, ``clockwise``) as :class:`~camtool.model.shapes.Arc`
stores them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from camtool.model.shapes import TAU, Arc, Line, Point, Segment

FloatArray = NDArray[np.float64]

SEG_SAMPLES = 16
"""Intervals per fitted segment for the segments -> curve direction of the error."""


def norm(x: float, y: float) -> float:
    """``√(x² + y²)``: the length of ``(x, y)`` rounded as the compiled fitter rounds it."""
    return math.sqrt(x * x + y * y)


def dist_line(xy: FloatArray, a: Point, b: Point) -> FloatArray:
    """``(N,)`` distances from ``xy`` to the segment ``a``–``b``, mm."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    rx, ry = xy[:, 0] - a[0], xy[:, 1] - a[1]
    ll = dx * dx + dy * dy
    if ll > 0:
        u = np.minimum(np.maximum((rx * dx + ry * dy) / ll, 0.0), 1.0)
        ex, ey = rx - u * dx, ry - u * dy
    else:
        ex, ey = rx, ry
    return np.sqrt(ex * ex + ey * ey)


def dist_arc(xy: FloatArray, arc: Arc) -> FloatArray:
    """``(N,)`` distances from ``xy`` to ``arc``: radial inside its sweep, else to its ends.

    A point is inside the sweep by the signs of two cross products (start × point and
    point × end, turned to the arc's direction): both ≥ 0 for a sweep up to 180°, either
    for a larger one. The nearer end is the one of the smaller squared distance
    (``√`` is monotone and correctly rounded: the same float as the smaller root).
    """
    (cx, cy), (sx, sy), (ex, ey) = arc.centre, arc.start, arc.end
    ux, uy, vx, vy = sx - cx, sy - cy, ex - cx, ey - cy
    if arc.clockwise:  # the cross products of the mirrored arc: signs turned
        ux, uy, vx, vy = uy, ux, vy, vx
    x, y = xy[:, 0], xy[:, 1]
    rx, ry = x - cx, y - cy
    qx, qy = (ry, rx) if arc.clockwise else (rx, ry)
    c1 = ux * qy - uy * qx
    c2 = qx * vy - qy * vx
    wide = ux * vy - uy * vx
    if wide > 0:
        inside = (c1 >= 0) & (c2 >= 0)
    elif wide < 0:
        inside = (c1 >= 0) | (c2 >= 0)
    elif ux * vx + uy * vy < 0:  # a half circle
        inside = c1 >= 0
    else:  # start and end on one ray: a full circle
        inside = np.ones(len(xy), dtype=bool)
    radial = np.abs(np.sqrt(rx * rx + ry * ry) - norm(ux, uy))
    if inside.all():  # the usual case: every sample beside the arc
        return radial
    ax, ay, bx, by = x - sx, y - sy, x - ex, y - ey
    ends = np.sqrt(np.minimum(ax * ax + ay * ay, bx * bx + by * by))
    return np.where(inside, radial, ends)


def distances(xy: FloatArray, segments: Sequence[Segment]) -> FloatArray:
    """``(N,)`` distance from each point to the nearest of ``segments`` (at least one)."""
    out: FloatArray | None = None
    for seg in segments:
        d = dist_line(xy, seg.start, seg.end) if isinstance(seg, Line) else dist_arc(xy, seg)
        out = d if out is None else np.minimum(out, d)
    assert out is not None
    return out


def arc_sweep(arc: Arc) -> float:
    """Signed sweep, radians (> 0 counter-clockwise), of an arc whose ends differ.

    :attr:`Arc.sweep <camtool.model.shapes.Arc.sweep>`'s formula without its full-circle
    case: ``(atan2(end) − atan2(start)) mod 2π``, ``2π`` for 0.
    """
    (cx, cy), (sx, sy), (ex, ey) = arc.centre, arc.start, arc.end
    ccw = (math.atan2(ey - cy, ex - cx) - math.atan2(sy - cy, sx - cx)) % TAU
    if ccw == 0.0:
        ccw = TAU
    return -(TAU - ccw) if arc.clockwise else ccw


def sample(seg: Segment, n: int = SEG_SAMPLES) -> FloatArray:
    """``(n + 1, 2)`` points evenly along ``seg`` (by length), both ends included."""
    out = np.empty((n + 1, 2))
    if isinstance(seg, Line):
        (x0, y0), (x1, y1) = seg.start, seg.end
        u = np.arange(n + 1) / n
        out[:, 0] = x0 + u * (x1 - x0)
        out[:, 1] = y0 + u * (y1 - y0)
        return out
    (cx, cy), (sx, sy) = seg.centre, seg.start
    start = math.atan2(sy - cy, sx - cx)
    sweep = arc_sweep(seg)
    r = norm(sx - cx, sy - cy)
    angles = [start + sweep * (k / n) for k in range(n + 1)]
    out[:, 0] = cx + r * np.array([math.cos(a) for a in angles])
    out[:, 1] = cy + r * np.array([math.sin(a) for a in angles])
    return out


def pairwise_dist_line(xy: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """``(N,)`` distance from ``xy[i]`` to the segment ``a[i]``–``b[i]`` (all ``(N, 2)``)."""
    dx, dy = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    rx, ry = xy[:, 0] - a[:, 0], xy[:, 1] - a[:, 1]
    ll = dx * dx + dy * dy
    u = np.minimum(np.maximum((rx * dx + ry * dy) / np.where(ll > 0, ll, 1.0), 0.0), 1.0)
    ex, ey = rx - u * dx, ry - u * dy
    return np.sqrt(ex * ex + ey * ey)


def dist_polyline(xy: FloatArray, poly: FloatArray) -> FloatArray:
    """``(N,)`` distances from ``xy`` to the polyline through ``poly`` ``(M, 2)``, M ≥ 2."""
    px, py = poly[:, 0], poly[:, 1]
    ax, ay = px[:-1], py[:-1]
    dx, dy = px[1:] - ax, py[1:] - ay  # (M-1,)
    rx, ry = xy[:, 0, None] - ax, xy[:, 1, None] - ay  # (N, M-1)
    ll = dx * dx + dy * dy
    u = np.minimum(np.maximum((rx * dx + ry * dy) / np.where(ll > 0, ll, 1.0), 0.0), 1.0)
    ex, ey = rx - u * dx, ry - u * dy
    return np.sqrt((ex * ex + ey * ey).min(axis=1))  # √ of the least: the least √


def piece_error(
    segs: Sequence[Segment], fine: FloatArray, pa: Point, limit: float = math.inf
) -> float:
    """Two-sided error between ``segs`` and the curve samples ``fine`` ``(2n+1, 2)``, mm.

    Curve -> segments: each sample's distance to the nearest segment. Segments -> curve:
    each of :data:`SEG_SAMPLES` + 1 points per segment to the sampled polyline, plus half
    the largest sagitta of the coarse chords (``fine[::2]``) at their midpoints
    (``fine[1::2]``): the sampled polyline lies about a quarter of that from the curve.
    With no segments, the samples' largest distance from ``pa``. When the first direction
    alone exceeds ``limit`` it is returned at once (the caller only compares with ``limit``).
    """
    if not segs:
        dx, dy = fine[:, 0] - pa[0], fine[:, 1] - pa[1]
        return float(np.sqrt(dx * dx + dy * dy).max())
    forward = float(distances(fine, segs).max())
    if forward > limit:
        return forward
    coarse = fine[::2]
    mids = fine[1::2]
    sag = float(pairwise_dist_line(mids, coarse[:-1], coarse[1:]).max()) if len(mids) else 0.0
    out = np.vstack([sample(s) for s in segs])
    backward = float(dist_polyline(out, fine).max()) + 0.5 * sag
    return max(forward, backward)
