"""Closed pocket rings as exact arcs and lines: fitting, circle merging, start points.

Used by :mod:`camtool.toolpath.pocket`. A ring is a closed sequence of segments
(start == end). :func:`fit_ring` turns a shapely buffer ring into arcs and lines
(:func:`~camtool.geometry.arcfit.fit_polyline` within ``tolerance / 2``) and then
merges neighbours that lie on one circle, so a circular ring comes out as one full
circle rather than two half arcs and a left-over chord. :func:`start_near` rotates a
ring to start at its point nearest the tool, splitting a segment there.

Conventions: mm, Y up; ``Arc.clockwise`` is G02.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

from camtool.geometry.arcfit import fit_polyline
from camtool.model.errors import InputError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment, distance

__all__ = ["fit_ring", "nearest_on", "start_near"]


def fit_ring(coords: Sequence[tuple[float, float]], tolerance: float) -> tuple[Segment, ...]:
    """A closed polyline ``(N, 2)`` mm as arcs and lines within ``tolerance`` mm.

    The fit uses half the tolerance; neighbours on one circle (within a quarter of
    it) are then joined into arcs of equal sweep (≤ 180°), or one full circle when
    the whole ring is one. A sliver too thin to fit keeps its own edges.
    """
    try:
        segs = fit_polyline(list(coords), tolerance / 2, closed=True)
    except InputError:  # a degenerate sliver: follow it with its own edges
        pts = [(float(x), float(y)) for x, y in coords]
        return tuple(Line(a, b) for a, b in itertools.pairwise(pts) if a != b)
    return tuple(_merge_circles([_clean(s) for s in segs], tolerance / 4))


def _clean(seg: Segment) -> Segment:
    """The segment with plain float coordinates (the fitter may return numpy scalars)."""
    if isinstance(seg, Line):
        return seg
    return Arc(seg.start, seg.end, (float(seg.centre[0]), float(seg.centre[1])), seg.clockwise)


@dataclass(frozen=True)
class _Run:
    """Consecutive segments on one circle: from ``start`` to ``end``, ``sweep`` radians."""

    start: Point
    end: Point
    centre: Point
    radius: float
    sweep: float


def _merge_circles(segs: list[Segment], tol: float) -> list[Segment]:
    first_arc = next((k for k, s in enumerate(segs) if isinstance(s, Arc)), None)
    if first_arc is None or len(segs) < 2:
        return segs
    segs = segs[first_arc:] + segs[:first_arc]
    items: list[Segment | _Run] = []
    for seg in segs:
        last = items[-1] if items else None
        run = _extend(last, seg, tol) if isinstance(last, (_Run, Arc)) else None
        if run is not None:
            items[-1] = run
        else:
            items.append(seg)
    if len(items) > 1 and isinstance(items[0], (_Run, Arc)):
        head = _extend(items[-1], items[0], tol) if isinstance(items[-1], (_Run, Arc)) else None
        if head is not None:
            items = [head, *items[1:-1]]
    if len(items) == 1 and isinstance(items[0], _Run) and abs(items[0].sweep) > math.pi:
        run = items[0]
        return [Arc(run.start, run.start, run.centre, run.sweep < 0)]
    out: list[Segment] = []
    for item in items:
        out.extend(_arcs(item) if isinstance(item, _Run) else [item])
    return out


def _as_run(seg: _Run | Arc) -> _Run:
    if isinstance(seg, _Run):
        return seg
    return _Run(seg.start, seg.end, seg.centre, seg.radius, seg.sweep)


def _extend(prev: _Run | Arc | Segment, seg: _Run | Segment, tol: float) -> _Run | None:
    """``prev`` and ``seg`` as one run on ``prev``'s circle, or ``None`` when they are not."""
    if not isinstance(prev, (_Run, Arc)):
        return None
    run = _as_run(prev)
    c, r = run.centre, run.radius
    if isinstance(seg, (_Run, Arc)):
        other = _as_run(seg)
        same = distance(other.centre, c) <= tol and abs(other.radius - r) <= tol
        if not same or (other.sweep > 0) != (run.sweep > 0):
            return None
        sweep = other.sweep
    else:
        mid = (0.5 * (seg.start[0] + seg.end[0]), 0.5 * (seg.start[1] + seg.end[1]))
        if any(abs(distance(p, c) - r) > tol for p in (seg.start, seg.end, mid)):
            return None
        sweep = _angle(c, seg.start, seg.end)
        if sweep == 0.0 or (sweep > 0) != (run.sweep > 0):
            return None
    return _Run(run.start, seg.end, c, r, run.sweep + sweep)


def _angle(c: Point, a: Point, b: Point) -> float:
    """Signed angle from ``a`` to ``b`` seen from ``c``, radians (> 0 counter-clockwise)."""
    ux, uy = a[0] - c[0], a[1] - c[1]
    vx, vy = b[0] - c[0], b[1] - c[1]
    return math.atan2(ux * vy - uy * vx, ux * vx + uy * vy)


def _arcs(run: _Run) -> list[Segment]:
    """The run as arcs of equal sweep, each at most 180°; its ends kept exactly."""
    parts = max(1, math.ceil(abs(run.sweep) / math.pi - 1e-9))
    cx, cy = run.centre
    r = distance(run.centre, run.start)
    a0 = math.atan2(run.start[1] - cy, run.start[0] - cx)
    pts = [run.start]
    for k in range(1, parts):
        a = a0 + run.sweep * k / parts
        pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    pts.append(run.end)
    return [Arc(p, q, run.centre, run.sweep < 0) for p, q in itertools.pairwise(pts)]


def start_near(segs: Sequence[Segment], p: Point, snap: float) -> tuple[Segment, ...]:
    """The closed ring rotated to start at its point nearest ``p``.

    The segment holding that point is split there unless a vertex lies within
    ``snap`` mm (then the ring starts at the vertex); a full circle starts anywhere.
    """
    dists = [nearest_on(s, p) for s in segs]
    i = min(range(len(segs)), key=lambda k: dists[k][0])
    seg, q = segs[i], dists[i][1]
    if isinstance(seg, Arc) and seg.is_full_circle:
        return (Arc(q, q, seg.centre, seg.clockwise),)
    if distance(q, seg.end) <= snap:
        i = (i + 1) % len(segs)
        seg, q = segs[i], segs[i].start
    if distance(q, seg.start) <= snap:
        return (*segs[i:], *segs[:i])
    head, tail = _split(seg, q)
    return (tail, *segs[i + 1 :], *segs[:i], head)


def _split(seg: Segment, q: Point) -> tuple[Segment, Segment]:
    if isinstance(seg, Line):
        return Line(seg.start, q), Line(q, seg.end)
    return Arc(seg.start, q, seg.centre, seg.clockwise), Arc(q, seg.end, seg.centre, seg.clockwise)


def nearest_on(seg: Segment, p: Point) -> tuple[float, Point]:
    """Distance from ``p`` to ``seg`` and the nearest point of ``seg``, mm."""
    if isinstance(seg, Line):
        (x0, y0), (x1, y1) = seg.start, seg.end
        dx, dy = x1 - x0, y1 - y0
        ll = dx * dx + dy * dy
        u = 0.0 if ll == 0 else min(1.0, max(0.0, ((p[0] - x0) * dx + (p[1] - y0) * dy) / ll))
        q = (x0 + u * dx, y0 + u * dy)
        return distance(p, q), q
    cx, cy = seg.centre
    a = math.atan2(p[1] - cy, p[0] - cx)
    travel = (seg.start_angle - a) % TAU if seg.clockwise else (a - seg.start_angle) % TAU
    if seg.is_full_circle or travel <= abs(seg.sweep):
        q = (cx + seg.radius * math.cos(a), cy + seg.radius * math.sin(a))
        return distance(p, q), q
    return min((distance(p, seg.start), seg.start), (distance(p, seg.end), seg.end))
