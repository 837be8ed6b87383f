"""Mirror ordering for symmetric parts (UNAM-GMM S000-20, §5.3, L2816–L2841).

Design notes: docs/internals.md, ``camtool/toolpath/mirror.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from camtool.model.errors import ToolpathError
from camtool.model.shapes import TAU, Arc, Contour, Line, Point, Segment, distance
from camtool.toolpath.cuts import Cut, Finding, where
from camtool.toolpath.travel import oriented

_ARC_SAMPLES = 16
_SIDE = {"left": "right", "right": "left"}


@dataclass(frozen=True)
class MirrorPlan:
    """A mirror ordering.

    Attributes:
        cuts: cuts in cutting order (crossing cuts replaced by their pieces).
        axis: the mirror line, ``"x = 5.0000"`` or ``"y = 3.5000"`` (mm).
        point: the shared start point Ie, mm.
        findings: pieces whose direction could not be mirrored.
    """

    cuts: tuple[Cut, ...]
    axis: str
    point: Point
    findings: tuple[Finding, ...]


def mirror_order(
    cuts: Sequence[Cut],
    before: Sequence[Sequence[int]],
    depth: Sequence[int],
    origin: Point,
    tolerance: float,
) -> MirrorPlan:
    """Plan ``cuts`` in mirror order (see the module).

    Args:
        cuts: the cuts, mm.
        before: precedence (:func:`camtool.toolpath.travel.precedence`).
        depth: nesting depth of each cut's group (0 = outermost).
        origin: tool position before the first cut, mm.
        tolerance: how far a mirror image may be from its cut, mm.

    Raises:
        ToolpathError: the cuts are symmetric about neither axis; names the cut
            with no mirror image for each axis tried.
    """
    tol = max(tolerance, 1e-6)
    x0, y0, x1, y1 = _bbox(cuts)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    pairs, bad_x = _partners(cuts, cx, tol)
    if pairs is not None:
        return _plan(cuts, pairs, cx, before, depth, origin, tol, f"x = {cx:.4f}")
    swapped = [_swap_cut(c) for c in cuts]
    pairs, bad_y = _partners(swapped, cy, tol)
    if pairs is None:
        raise ToolpathError(
            f"--order mirror: the drawing is not symmetric about x = {cx:.4f} mm "
            f"({where(cuts[bad_x].path)} has no mirror image within {tol:g} mm) nor about "
            f"y = {cy:.4f} mm ({where(cuts[bad_y].path)} has none); use --order travel"
        )
    plan = _plan(swapped, pairs, cy, before, depth, (origin[1], origin[0]), tol, f"y = {cy:.4f}")
    return replace(plan, cuts=tuple(_swap_cut(c) for c in plan.cuts), point=_swap(plan.point))


def _plan(
    cuts: Sequence[Cut],
    pairs: list[int],
    c: float,
    before: Sequence[Sequence[int]],
    depth: Sequence[int],
    origin: Point,
    tol: float,
    axis: str,
) -> MirrorPlan:
    """Mirror plan about the vertical line ``x = c`` (``pairs[i]``: cut i's mirror image)."""
    split = {i: _split(cuts[i].path, c, tol) for i in range(len(cuts)) if pairs[i] == i}
    ie = _shared_point(cuts, split, depth, c, tol)
    units: list[list[Cut]] = []
    members: list[list[int]] = []
    findings: list[Finding] = []
    for i, j in enumerate(pairs):
        if i == j:
            units.append(_crossing_unit(cuts[i], split[i], c, ie, findings))
            members.append([i])
        elif i < j:
            right, left = (i, j) if _centre_x(cuts[i]) > c else (j, i)
            units.append(_pair_unit(cuts[right], cuts[left], c, ie, findings))
            members.append([i, j])
    order = _order_units(units, members, before, origin)
    out = tuple(cut for u in order for cut in units[u])
    return MirrorPlan(out, axis, ie, tuple(findings))


def _order_units(
    units: list[list[Cut]], members: list[list[int]], before: Sequence[Sequence[int]], origin: Point
) -> list[int]:
    """Units in nearest-first order from ``origin`` where precedence allows."""
    unit_of = {i: u for u, ms in enumerate(members) for i in ms}
    needs = [{unit_of[b] for a in ms for b in before[a]} - {u} for u, ms in enumerate(members)]
    done: set[int] = set()
    order: list[int] = []
    here = origin
    while len(order) < len(units):
        ready = [u for u in range(len(units)) if u not in done and needs[u] <= done]
        if not ready:
            raise ValueError("cyclic precedence between mirror units")
        u = min(ready, key=lambda u: (distance(here, units[u][0].path.start), u))
        order.append(u)
        done.add(u)
        here = units[u][-1].path.end
    return order


def _crossing_unit(
    cut: Cut, pieces: list[tuple[Contour, int]], c: float, ie: Point, findings: list[Finding]
) -> list[Cut]:
    rights = [p for p, side in pieces if side > 0]
    lefts = [p for p, side in pieces if side < 0]
    free = cut.may_reverse
    rights.sort(key=lambda p: min(distance(p.start, ie), distance(p.end, ie)))
    out_r: list[Cut] = []
    out_l: list[Cut] = []
    for r in rights:
        rev_r = free and distance(r.end, ie) < distance(r.start, ie)
        out_r.append(_piece(cut, r, rev_r))
        start = _mirror_point(out_r[-1].path.start, c)
        end = _mirror_point(out_r[-1].path.end, c)
        if not lefts:
            break
        k = min(
            range(len(lefts)),
            key=lambda k: min(
                distance(lefts[k].start, start) + distance(lefts[k].end, end),
                distance(lefts[k].end, start) + distance(lefts[k].start, end),
            ),
        )
        left = lefts.pop(k)
        rev_l = distance(left.end, start) < distance(left.start, start)
        if rev_l and not free:
            rev_l = False
            findings.append(_unmirrored(cut))
        out_l.append(_piece(cut, left, rev_l))
    out_l.extend(_piece(cut, p, False) for p in lefts)
    return out_r + out_l


def _pair_unit(right: Cut, left: Cut, c: float, ie: Point, findings: list[Finding]) -> list[Cut]:
    k = _nearest_vertex(right, ie)
    first = oriented(right, k, False)
    target = _mirror_point(first.path.start, c)
    if not left.path.closed:
        return [first, left]
    rev = (left.path.signed_area() > 0) == (first.path.signed_area() > 0)
    if rev and not left.may_reverse:
        rev = False
        findings.append(_unmirrored(left))
    return [first, oriented(left, _nearest_vertex(left, target), rev)]


def _nearest_vertex(cut: Cut, p: Point) -> int:
    if not (cut.path.closed and cut.may_rotate):
        return 0
    d = [distance(seg.start, p) for seg in cut.path.segments]
    return d.index(min(d))


def _unmirrored(cut: Cut) -> Finding:
    return Finding(
        "ordering",
        f"--order mirror: {where(cut.path)} keeps its direction (fixed by --direction), so "
        "its mirror half is not cut as the mirror image of the first",
        cut.path.start,
    )


def _piece(cut: Cut, path: Contour, rev: bool) -> Cut:
    piece = Cut(path, cut.group, cut.kind, False, False, cut.outside_profile, cut.material_side)
    return piece.reversed() if rev else piece


def _shared_point(
    cuts: Sequence[Cut],
    split: dict[int, list[tuple[Contour, int]]],
    depth: Sequence[int],
    c: float,
    eps: float,
) -> Point:
    """Ie: the highest crossing of the outermost closed cut crossing the axis."""

    def crossings(i: int) -> list[Point]:
        return [p.start for p, _ in split[i]] + [p.end for p, _ in split[i]]

    closed = [i for i in split if cuts[i].path.closed]
    if closed:
        i = min(closed, key=lambda i: (depth[i], -_area(cuts[i]), i))
        pts = [p for p in crossings(i) if abs(p[0] - c) <= eps]
    else:
        pts = [p for i in split for p in crossings(i) if abs(p[0] - c) <= eps]
    if pts:
        return max(pts, key=lambda p: p[1])
    return (c, _bbox(cuts)[3])


def _area(cut: Cut) -> float:
    x0, y0, x1, y1 = cut.path.bbox()
    return (x1 - x0) * (y1 - y0)


def _centre_x(cut: Cut) -> float:
    x0, _, x1, _ = cut.path.bbox()
    return (x0 + x1) / 2


def _bbox(cuts: Sequence[Cut]) -> tuple[float, float, float, float]:
    boxes = np.asarray([c.path.bbox() for c in cuts], dtype=np.float64).reshape(-1, 4)
    return (
        float(boxes[:, 0].min()),
        float(boxes[:, 1].min()),
        float(boxes[:, 2].max()),
        float(boxes[:, 3].max()),
    )


# ------------------------------------------------------------------ symmetry


def _partners(cuts: Sequence[Cut], c: float, tol: float) -> tuple[list[int] | None, int]:
    """Each cut's mirror image about ``x = c`` (itself when it crosses the axis).

    Returns ``(partners, -1)``, or ``(None, i)`` with ``i`` the first cut without one.
    """
    boxes = np.asarray([cut.path.bbox() for cut in cuts], dtype=np.float64).reshape(-1, 4)
    mirrored = np.stack([2 * c - boxes[:, 2], boxes[:, 1], 2 * c - boxes[:, 0], boxes[:, 3]], 1)
    crossing = (boxes[:, 0] < c - tol) & (boxes[:, 2] > c + tol)
    partners: list[int | None] = [None] * len(cuts)
    for i, cut in enumerate(cuts):
        if partners[i] is not None:
            continue
        if crossing[i]:
            if not _mirror_of(cut.path, cut.path, c, tol):
                return None, i
            partners[i] = i
            continue
        near = np.all(np.abs(boxes - mirrored[i]) <= tol, axis=1) & ~crossing
        for j in (int(j) for j in np.flatnonzero(near)):
            if j != i and partners[j] is None and _mirror_of(cut.path, cuts[j].path, c, tol):
                partners[i], partners[j] = j, i
                break
        else:
            return None, i
    return [int(p) for p in partners if p is not None], -1


def _mirror_of(a: Contour, b: Contour, c: float, tol: float) -> bool:
    """True when the mirror image of ``a`` about ``x = c`` lies within ``tol`` of ``b``."""
    am = Contour(tuple(_mirror_seg(s, c) for s in a.segments), a.closed)
    return bool(
        np.max(_distances(_samples(am), b)) <= tol and np.max(_distances(_samples(b), am)) <= tol
    )


def _samples(path: Contour) -> npt.NDArray[np.float64]:
    """``(N, 2)`` points exactly on ``path``: vertices and interior points, mm."""
    pts: list[Point] = []
    for seg in path.segments:
        if isinstance(seg, Arc):
            pts.extend(seg.point_at(k / _ARC_SAMPLES) for k in range(_ARC_SAMPLES))
        else:
            (x0, y0), (x1, y1) = seg.start, seg.end
            pts.extend((x0 + (x1 - x0) * t, y0 + (y1 - y0) * t) for t in (0.0, 0.25, 0.5, 0.75))
    pts.append(path.end)
    return np.asarray(pts, dtype=np.float64)


def _distances(pts: npt.NDArray[np.float64], path: Contour) -> npt.NDArray[np.float64]:
    """``(N,)`` exact distance of each point from ``path`` (lines and arcs), mm."""
    best = np.full(len(pts), np.inf)
    for seg in path.segments:
        if isinstance(seg, Arc):
            d = _arc_distance(pts, seg)
        else:
            a = np.asarray(seg.start)
            v = np.asarray(seg.end) - a
            vv = float(v @ v)
            t = np.clip(((pts - a) @ v) / vv, 0.0, 1.0) if vv > 0 else np.zeros(len(pts))
            d = np.hypot(*(pts - a - t[:, None] * v).T)
        best = np.minimum(best, d)
    return best


def _arc_distance(pts: npt.NDArray[np.float64], arc: Arc) -> npt.NDArray[np.float64]:
    rel = pts - np.asarray(arc.centre)
    theta = np.arctan2(rel[:, 1], rel[:, 0])
    s = 1.0 if arc.sweep > 0 else -1.0
    along = (s * (theta - arc.start_angle)) % TAU
    on = along <= abs(arc.sweep)
    radial = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - arc.radius)
    ends = np.minimum(
        np.hypot(*(pts - np.asarray(arc.start)).T), np.hypot(*(pts - np.asarray(arc.end)).T)
    )
    return np.where(on, radial, ends)


# ------------------------------------------------------------------ splitting


def _split(path: Contour, c: float, eps: float) -> list[tuple[Contour, int]]:
    """Pieces of ``path`` between its crossings of ``x = c``, with their side.

    Side +1 is right, -1 left; pieces in path order; a closed path's first piece
    starts at a crossing.
    """
    segs: list[Segment] = [part for seg in path.segments for part in _split_segment(seg, c, eps)]
    on = [abs(seg.start[0] - c) <= eps for seg in segs]
    if path.closed and any(on):
        k = on.index(True)
        segs, on = segs[k:] + segs[:k], on[k:] + on[:k]
    runs: list[list[Segment]] = []
    for seg, at_axis in zip(segs, on, strict=True):
        if at_axis or not runs:
            runs.append([])
        runs[-1].append(seg)
    sides = [_side(run, c) for run in runs]
    merged: list[tuple[list[Segment], int]] = []
    for run, side in zip(runs, sides, strict=True):
        if merged and side in (0, merged[-1][1]):
            merged[-1][0].extend(run)
        else:
            merged.append((list(run), side))
    if path.closed and len(merged) > 1 and merged[0][1] == merged[-1][1]:
        last = merged.pop()
        merged[0] = (last[0] + merged[0][0], last[1])
    return [(Contour(tuple(run), False, path.layer, path.source), side) for run, side in merged]


def _side(run: Sequence[Segment], c: float) -> int:
    mids = [s.point_at(0.5) if isinstance(s, Arc) else _midpoint(s) for s in run]
    far = max((p[0] - c for p in mids), key=abs)
    return 0 if far == 0 else (1 if far > 0 else -1)


def _midpoint(seg: Line) -> Point:
    return ((seg.start[0] + seg.end[0]) / 2, (seg.start[1] + seg.end[1]) / 2)


def _split_segment(seg: Segment, c: float, eps: float) -> list[Segment]:
    """``seg`` cut where it crosses ``x = c`` away from its ends (crossings exactly on it)."""
    if isinstance(seg, Line):
        (x0, y0), (x1, y1) = seg.start, seg.end
        if (x0 - c) * (x1 - c) >= 0 or min(abs(x0 - c), abs(x1 - c)) <= eps:
            return [seg]
        t = (c - x0) / (x1 - x0)
        p = (c, y0 + t * (y1 - y0))
        return [Line(seg.start, p), Line(p, seg.end)]
    r = seg.radius
    u = (c - seg.centre[0]) / r
    if abs(u) >= 1 - 1e-12:
        return [seg]
    s = 1.0 if seg.sweep > 0 else -1.0
    cuts = []
    for theta in (math.acos(u), -math.acos(u)):
        d = (s * (theta - seg.start_angle)) % TAU
        if eps / r < d < abs(seg.sweep) - eps / r:
            cuts.append((d, (c, seg.centre[1] + r * math.sin(theta))))
    cuts.sort()
    pts = [seg.start, *(p for _, p in cuts), seg.end]
    return [Arc(a, b, seg.centre, seg.clockwise) for a, b in itertools.pairwise(pts)]


# ------------------------------------------------------------------ reflections


def _mirror_point(p: Point, c: float) -> Point:
    return (2 * c - p[0], p[1])


def _mirror_seg(seg: Segment, c: float) -> Segment:
    if isinstance(seg, Line):
        return Line(_mirror_point(seg.start, c), _mirror_point(seg.end, c))
    return Arc(
        _mirror_point(seg.start, c),
        _mirror_point(seg.end, c),
        _mirror_point(seg.centre, c),
        not seg.clockwise,
    )


def _swap(p: Point) -> Point:
    return (p[1], p[0])


def _swap_cut(cut: Cut) -> Cut:
    """``cut`` reflected about the line y = x (orientation and material side swap)."""
    segs: list[Segment] = []
    for seg in cut.path.segments:
        if isinstance(seg, Line):
            segs.append(Line(_swap(seg.start), _swap(seg.end)))
        else:
            segs.append(Arc(_swap(seg.start), _swap(seg.end), _swap(seg.centre), not seg.clockwise))
    path = Contour(tuple(segs), cut.path.closed, cut.path.layer, cut.path.source)
    side = _SIDE.get(cut.material_side or "")
    return replace(cut, path=path, material_side=side)
