"""Geometry the arc fitters share: distances to lines and arcs, samples, tolerance checks.

Split out of :mod:`camtool.geometry.arcfit` so that :mod:`~camtool.geometry.arcfit` (curves) and
:mod:`~camtool.geometry.polyfit` (polylines) share one set of exact distance functions.
Conventions: mm, Y up; arrays of points are ``(N, 2)`` float64.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from camtool.model.errors import UsageError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment

FloatArray: TypeAlias = NDArray[np.float64]

MAX_SWEEP = math.pi
"""Largest sweep of one output arc, radians: 180° arcs are safe in every dialect (I/J or R)."""


def check_tolerance(tolerance: float) -> float:
    """``tolerance`` as a float, mm.

    Raises:
        UsageError: it is not a positive finite number.
    """
    tol = float(tolerance)
    if not (math.isfinite(tol) and tol > 0):
        raise UsageError(
            f"arc fitting tolerance must be a positive number of mm, got {tolerance!r}"
        )
    return tol


def distances(xy: ArrayLike, segments: Sequence[Segment]) -> FloatArray:
    """Distance from each point to the nearest of ``segments`` (exact for lines and arcs).

    Args:
        xy: ``(N, 2)`` float64 points, mm.
        segments: at least one line or arc.

    Returns:
        ``(N,)`` float64 distances, mm.
    """
    pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    return np.min([dist_segment(pts, s) for s in segments], axis=0)


def sample_segment(seg: Segment, n: int) -> FloatArray:
    """``(n + 1, 2)`` points evenly along ``seg``, ends included."""
    u = np.linspace(0.0, 1.0, n + 1)
    if isinstance(seg, Line):
        (x0, y0), (x1, y1) = seg.start, seg.end
        return np.column_stack([x0 + u * (x1 - x0), y0 + u * (y1 - y0)])
    a = seg.start_angle + seg.sweep * u
    r = seg.radius
    return np.column_stack([seg.centre[0] + r * np.cos(a), seg.centre[1] + r * np.sin(a)])


def dist_segment(xy: FloatArray, seg: Segment) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to one line or arc, mm."""
    return dist_line(xy, seg.start, seg.end) if isinstance(seg, Line) else dist_arc(xy, seg)


def dist_line(xy: FloatArray, a: Point, b: Point) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to the segment ``a``–``b``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    rx, ry = xy[:, 0] - a[0], xy[:, 1] - a[1]
    ll = dx * dx + dy * dy
    u = np.clip((rx * dx + ry * dy) / ll, 0.0, 1.0) if ll > 0 else np.zeros(len(xy))
    return np.hypot(rx - u * dx, ry - u * dy)


def dist_arc(xy: FloatArray, arc: Arc) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to ``arc``: radial inside the sweep, else ends."""
    rx, ry = xy[:, 0] - arc.centre[0], xy[:, 1] - arc.centre[1]
    sweep = arc.sweep
    ang = np.arctan2(ry, rx) - arc.start_angle
    inside = np.mod(ang if sweep > 0 else -ang, TAU) <= abs(sweep)
    ends = np.minimum(
        np.hypot(xy[:, 0] - arc.start[0], xy[:, 1] - arc.start[1]),
        np.hypot(xy[:, 0] - arc.end[0], xy[:, 1] - arc.end[1]),
    )
    return np.where(inside, np.abs(np.hypot(rx, ry) - arc.radius), ends)


def pairwise_dist_line(xy: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """``(N,)`` distance from ``xy[i]`` to the segment ``a[i]``–``b[i]`` (all ``(N, 2)``)."""
    d = b - a
    r = xy - a
    ll = np.einsum("ij,ij->i", d, d)
    u = np.clip(np.einsum("ij,ij->i", r, d) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    return np.hypot(*(r - u[:, None] * d).T)


def dist_polyline(xy: FloatArray, poly: FloatArray) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to the polyline through ``poly`` ``(M, 2)``."""
    a, d = poly[:-1], np.diff(poly, axis=0)  # (M-1, 2)
    r = xy[:, None, :] - a[None, :, :]  # (N, M-1, 2)
    ll = np.einsum("ij,ij->i", d, d)
    u = np.clip(np.einsum("nij,ij->ni", r, d) / np.where(ll > 0, ll, 1.0), 0.0, 1.0)
    gap = r - u[:, :, None] * d[None, :, :]
    return np.min(np.hypot(gap[..., 0], gap[..., 1]), axis=1)
