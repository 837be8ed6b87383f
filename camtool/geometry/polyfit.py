"""Polyline fitting: a dense polyline becomes lines and arcs within a tolerance.

Split out of :mod:`camtool.geometry.arcfit`, which re-exports :func:`fit_polyline`. The planner
turns dense polylines (buffers, point lists) into G02/G03-ready arcs with it.

Conventions: mm, Y up, arcs exact (``clockwise=True`` is G02). The tolerance is checked both
ways. Source: circle fit after I. Kåsa, "A circle fitting procedure and its error analysis",
IEEE Trans. Instrum. Meas. 25(1), 1976, constrained here to pass through the run's two end
points.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import ArrayLike

from camtool.geometry.fitgeom import (
    MAX_SWEEP,
    FloatArray,
    check_tolerance,
    dist_arc,
    dist_line,
)
from camtool.model.errors import InputError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment

CORNER_ANGLE_DEG = 30.0
"""Default turn, degrees, above which :func:`fit_polyline` keeps a vertex as a corner."""

_CORNER_SPAN = 5.0  # polyline corners are judged over this many tolerances of length
_DUPLICATE = 1e-9  # mm: polyline points closer than this to the previous one are dropped


def fit_polyline(
    points: ArrayLike,
    tolerance: float,
    *,
    closed: bool = False,
    corner_angle_deg: float = CORNER_ANGLE_DEG,
) -> list[Segment]:
    """Turn a dense polyline into lines and arcs within ``tolerance`` mm of it.

    Corners are kept: a vertex whose turn over ±5 tolerances of length exceeds
    ``corner_angle_deg`` (the sharpest in that neighbourhood, so noise and dense sampling
    near a corner give one corner), or whose own turn does so with both edges longer than the
    tolerance. A buffer with shapely's default 8 segments per quarter turns 11.25° per vertex
    and stays smooth. Between corners, segments grow greedily (doubling, then bisection) to
    the longest run that fits one Line (every point within tolerance of the chord) or one Arc
    through the run's end points, its centre fitted by least squares (Kåsa, constrained to
    the chord bisector) and verified: every point within tolerance, points in order along
    the sweep, each edge's sagitta plus radial error within tolerance, sweep ≤ :data:`MAX_SWEEP`.
    Points closer than 1e-9 mm to the previous one are dropped.

    Args:
        points: ``(N, 2)`` float64 vertices, mm; for ``closed`` the last may repeat the first.
        tolerance: largest distance between polyline and output, both ways, mm (> 0).
        closed: the polyline returns from the last vertex to the first.
        corner_angle_deg: turn in degrees above which a vertex is a corner.

    Returns:
        Segments from the first vertex through the last exactly (back to the first when
        ``closed``), each starting at the end of the one before.

    Raises:
        InputError: points are not ``(N, 2)`` finite numbers, or fewer than 2 distinct
            (3 when ``closed``).
        UsageError: bad ``tolerance``.
    """
    tol = check_tolerance(tolerance)
    xy = _clean(points, closed)
    tp = [(float(x), float(y)) for x, y in xy]
    if closed:
        tp[-1] = tp[0]
    breaks = _breaks(xy, tol, math.radians(corner_angle_deg), closed)
    out: list[Segment] = []
    for a, b in itertools.pairwise(breaks):
        out.extend(_fit_run(xy, tp, a, b, tol))
    return out


def _clean(points: ArrayLike, closed: bool) -> FloatArray:
    """Finite ``(M, 2)`` vertices without repeats; for ``closed`` the first is appended."""
    try:
        xy = np.array(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"polyline points must be numbers: {exc}") from exc
    if xy.size == 0:
        raise InputError("a polyline needs 2 distinct points, got none")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"polyline points must be an (N, 2) array, got shape {xy.shape}")
    if not np.all(np.isfinite(xy)):
        raise InputError("polyline points must be finite, found NaN or infinity")
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.hypot(*np.diff(xy, axis=0).T) > _DUPLICATE
    xy = xy[keep]
    if closed:
        while len(xy) > 1 and math.dist(xy[-1], xy[0]) <= _DUPLICATE:
            xy = xy[:-1]
        if len(xy) < 3:
            raise InputError(f"a closed polyline needs 3 distinct points, got {len(xy)}")
        xy = np.vstack([xy, xy[:1]])
    elif len(xy) < 2:
        raise InputError(f"a polyline needs 2 distinct points, got {len(xy)}")
    xy.setflags(write=False)
    return xy


def _breaks(xy: FloatArray, tol: float, corner: float, closed: bool) -> list[int]:
    """Sorted vertex indices where runs end: both ends and the corners.

    A closed ring is tripled so that turns and neighbourhoods near vertex 0 wrap around;
    its corners are read from the middle copy.
    """
    ring = xy[:-1] if closed else xy
    n = len(ring)
    ext = np.vstack([ring, ring, ring]) if closed else ring
    idx = np.arange(1, len(ext) - 1)
    if len(idx) == 0:
        return [0, len(xy) - 1]
    edge = np.hypot(*np.diff(ext, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(edge)])
    span = _CORNER_SPAN * tol
    back = np.minimum(np.searchsorted(s, s[idx] - span, side="right") - 1, idx - 1)
    ahead = np.maximum(np.searchsorted(s, s[idx] + span, side="left"), idx + 1)
    back, ahead = np.maximum(back, 0), np.minimum(ahead, len(ext) - 1)
    wide = _turn(ext[idx] - ext[back], ext[ahead] - ext[idx])
    near = _turn(ext[idx] - ext[idx - 1], ext[idx + 1] - ext[idx])
    sharp = (near > corner) & (np.minimum(edge[idx - 1], edge[idx]) > tol)
    corners = set(idx[sharp].tolist())
    cand = np.flatnonzero(wide > corner)
    where = s[idx[cand]]
    for k, pos in zip(cand, where, strict=True):  # the sharpest within ±span (ties: the first)
        lo, hi = np.searchsorted(where, [pos - span, pos + span])
        window = cand[lo:hi]
        if window[np.argmax(wide[window])] == k:
            corners.add(int(idx[k]))
    if closed:
        corners = {i - n for i in corners if n <= i < 2 * n}
    inner = sorted(i for i in corners if 0 < i < len(xy) - 1)
    return [0, *inner, len(xy) - 1]


def _turn(u: FloatArray, v: FloatArray) -> FloatArray:
    """Unsigned angle (radians) between direction rows ``u`` and ``v``, both ``(N, 2)``."""
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    dot = u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1]
    return np.abs(np.arctan2(cross, dot))


def _fit_run(xy: FloatArray, tp: list[Point], a: int, b: int, tol: float) -> list[Segment]:
    """Greedy longest segments from vertex ``a`` to vertex ``b``."""
    out: list[Segment] = []
    s = a
    while s < b:
        ok, seg = s + 1, _try(xy, tp, s, s + 1, tol)
        fail = None
        step = 2
        while ok < b:  # doubling ...
            e = min(s + step, b)
            got = _try(xy, tp, s, e, tol)
            if got is None:
                fail = e
                break
            ok, seg, step = e, got, 2 * step
        while fail is not None and fail - ok > 1:  # ... then bisection
            mid = (ok + fail) // 2
            got = _try(xy, tp, s, mid, tol)
            if got is None:
                fail = mid
            else:
                ok, seg = mid, got
        assert seg is not None  # two vertices always make a line
        out.append(seg)
        s = ok
    return out


def _try(xy: FloatArray, tp: list[Point], s: int, e: int, tol: float) -> Segment | None:
    """A Line (preferred) or an Arc from vertex ``s`` to ``e`` within ``tol``, else None."""
    if e == s + 1:
        return Line(tp[s], tp[e])
    if math.dist(tp[s], tp[e]) <= _DUPLICATE:  # a loop back to its start is two segments
        return None
    pts = xy[s : e + 1]
    if float(np.max(dist_line(pts, tp[s], tp[e]))) <= tol:
        return Line(tp[s], tp[e])
    return _fit_arc(pts, tp[s], tp[e], tol)


def _fit_arc(pts: FloatArray, a: Point, b: Point, tol: float) -> Arc | None:
    """Arc from ``a`` to ``b`` (the ends of ``pts``) fitted to ``pts`` and verified."""
    rel = pts - pts[0]
    vx, vy = rel[-1]
    chord = math.hypot(vx, vy)
    nx, ny = -vy / chord, vx / chord
    # centre c = v/2 + lam n (origin at a): |r_i - c|² - |c|² = |r_i|² - r_i·v - 2 lam n·r_i
    rhs = np.einsum("ij,ij->i", rel, rel) - (rel[:, 0] * vx + rel[:, 1] * vy)
    coef = 2.0 * (rel[:, 0] * nx + rel[:, 1] * ny)
    den = float(coef @ coef)
    side = float(np.sum(vx * rel[:, 1] - vy * rel[:, 0]))
    if den == 0.0 or side == 0.0:
        return None
    lam = float(rhs @ coef) / den
    centre = (a[0] + 0.5 * vx + lam * nx, a[1] + 0.5 * vy + lam * ny)
    arc = Arc(a, b, centre, side > 0)  # points right of the chord: counter-clockwise
    if abs(arc.sweep) > MAX_SWEEP + 1e-9 or not _arc_fits(arc, pts, tol):
        return None
    return arc


def _arc_fits(arc: Arc, pts: FloatArray, tol: float) -> bool:
    """Every point within ``tol``, in order along the sweep, every edge's bulge within ``tol``."""
    if float(np.max(dist_arc(pts, arc))) > tol:
        return False
    r, sweep = arc.radius, abs(arc.sweep)
    rel = pts - np.asarray(arc.centre)
    ang = np.arctan2(rel[:, 1], rel[:, 0]) - arc.start_angle
    delta = np.mod(-ang if arc.clockwise else ang, TAU)
    delta = np.where(delta > 0.5 * (sweep + TAU), delta - TAU, delta)  # just before the start
    slack = tol / r
    if np.any(delta < np.maximum.accumulate(delta) - slack):
        return False
    radial = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - r)
    step = np.minimum(np.abs(np.diff(delta)), math.pi)
    bulge = 2.0 * r * np.sin(0.25 * step) ** 2 + np.maximum(radial[:-1], radial[1:])
    return bool(np.max(bulge) <= tol)
