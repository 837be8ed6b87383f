"""Cutting order: nesting of contours, and the order, starts and directions of the cuts.

Design notes: docs/internals.md, ``camtool/toolpath/order.py``.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from camtool.geometry.area import enclosed
from camtool.model.errors import UsageError
from camtool.model.shapes import Contour, Point, distance
from camtool.model.units import fmt_point
from camtool.toolpath.cuts import Cut, Finding
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.reversals import count_reversals, reversal_order
from camtool.toolpath.travel import Step, drawn_order, oriented, precedence, travel_order

_NEST_TOLERANCE_MM = 1e-4

_TOUCH_MM = 2 * _NEST_TOLERANCE_MM
"""How far a contour may leave a closed contour's chord polygon and lie inside it, mm: that
polygon lies up to :data:`_NEST_TOLERANCE_MM` inside the curve it stands for, so a contour
touching the curve from within may lie that far outside it (:func:`_touching_inside`)."""


@dataclass(frozen=True)
class Nesting:
    """Containment between contours.

    ``parents[i]`` lists the indices of the closed contours that contain contour
    ``i``; ``depth(i)`` is their count (0 = outermost). Even depth is an outer
    boundary of material, odd depth a hole (even-odd rule). ``near`` lists the closed
    contours ``(i, j, gap)``, ``i < j``, whose outlines lie within :data:`NEAR_MM` of each
    other all along (their Hausdorff distance ``gap``, mm): one outline drawn twice a little
    off (:func:`~camtool.toolpath.copies.drop_near_copies`).
    """

    parents: tuple[tuple[int, ...], ...]
    near: tuple[tuple[int, int, float], ...] = ()

    def depth(self, index: int) -> int:
        """Number of closed contours around contour ``index``."""
        return len(self.parents[index])

    def without(self, left_out: set[int]) -> Nesting:
        """The nesting of the contours but ``left_out``, indexed as they are kept.

        Containment is decided pair by pair, so this is what :func:`nesting` finds for the
        contours kept.
        """
        index: dict[int, int] = {}
        for i in range(len(self.parents)):
            if i not in left_out:
                index[i] = len(index)
        parents = tuple(
            tuple(index[p] for p in ps if p not in left_out)
            for i, ps in enumerate(self.parents)
            if i not in left_out
        )
        near = tuple(
            (index[i], index[j], gap)
            for i, j, gap in self.near
            if i not in left_out and j not in left_out
        )
        return Nesting(parents, near)


_NEAR_SAMPLE_MM = 0.5
"""The longest segment of the outlines :func:`_near` measures, mm."""

NEAR_MM = 0.01
"""How close a closed contour may run to another all along and be that outline drawn
again a little off, mm: 10 µm, the default ``--chain-tolerance``, a wall no tool cuts.
Fixed, not the chaining distance: ``--chain-tolerance 0.5`` would make a thin ring one
outline."""


COVER_PART = 256
"""Pairs :func:`nesting` gives a thread at a time to GEOS's ``covered_by``."""


def nesting(contours: Sequence[Contour]) -> Nesting:
    """Find which closed contours contain which contours.

    A contour (open or closed, by its outline: arcs as chords within
    :data:`_NEST_TOLERANCE_MM`) lies inside a closed contour when the closed contour's
    filled polygon (:func:`~camtool.geometry.area.enclosed`: the nonzero winding rule where
    the outline crosses or touches itself) covers it, or it lies within :data:`_TOUCH_MM` of
    that polygon all along (touching its edge from within, :func:`_touching_inside`), and is
    strictly larger (a polygon covers its own outline and an identical duplicate's).
    Shapely's vectorised constructors and one bulk ``STRtree.query(…, "covered_by")``
    answer as one geometry and one query per contour did (:func:`_nesting_one_by_one`,
    kept for the tests): the same coordinates, the same GEOS predicate (asked of the
    candidate pairs in parts on every core, :func:`camtool.accel.pool.parts_threaded`).

    Args:
        contours: contours in mm.

    Returns:
        The containment relation, indexed like ``contours``.
    """
    import numpy as np
    import shapely

    from camtool.accel.pool import parts_threaded

    if not contours:
        return Nesting(())
    coords, counts = _outline_coords(contours, _NEST_TOLERANCE_MM)
    owner = np.repeat(np.arange(len(contours)), counts)
    outlines = shapely.linestrings(coords, indices=owner)
    closed = [i for i, c in enumerate(contours) if c.closed]
    if not closed:
        return Nesting(((),) * len(contours))
    in_closed = np.zeros(len(contours), dtype=bool)
    in_closed[closed] = True
    keep = in_closed[owner]
    try:
        rank = np.cumsum(in_closed) - 1  # closed contour → its polygon
        rings = shapely.linearrings(coords[keep], indices=rank[owner[keep]])
    except (ValueError, shapely.errors.GEOSException):
        return _nesting_one_by_one(contours)  # the same contour refused, as before
    raw = shapely.polygons(rings)
    polygons = shapely.buffer(raw, 0)
    for k in np.flatnonzero(~shapely.is_valid(raw)).tolist():  # crosses or touches itself
        polygons[k] = enclosed(shapely.get_coordinates(rings[k]))
    area = np.zeros(len(contours))
    area[closed] = shapely.area(polygons)
    # Candidates by their boxes; a polygon covers its own outline and an identical
    # duplicate's, so a parent must also be strictly larger: that test, which needs no
    # geometry, goes first, and GEOS decides the rest (as the tree's predicate query did).
    which, around = shapely.STRtree(polygons).query(outlines)
    parent = np.asarray(closed, dtype=np.int64)[around]
    larger = area[parent] > np.where(in_closed[which], area[which], 0.0)
    which, around, parent = which[larger], around[larger], parent[larger]
    covered = parts_threaded(
        lambda part: shapely.covered_by(outlines[which[part]], polygons[around[part]]),
        len(which),
        COVER_PART,
        dtype=bool,
    )
    covered |= _touching_inside(outlines, polygons, which, around, covered)
    which, parent = which[covered], parent[covered]
    order = np.lexsort((parent, which))
    parents: list[list[int]] = [[] for _ in contours]
    for i, j in zip(which[order].tolist(), parent[order].tolist(), strict=True):
        parents[i].append(j)
    return Nesting(tuple(tuple(p) for p in parents), _near(outlines, closed))


def _touching_inside(outlines: Any, polygons: Any, which: Any, around: Any, covered: Any) -> Any:
    """Of the pairs ``covered_by`` refused, those inside, touching the polygon's edge.

    Their outline lies within :data:`_TOUCH_MM` of the polygon all along. A circle drawn
    touching its parent's edge from inside (a hole tangent to the outline) is covered by
    the parent's filled circle, but not always by the polygon of its chords, which lies up
    to :data:`_NEST_TOLERANCE_MM` inside it: where the two meet, the test is decided by
    the last bits of two cosines. Read as an outline of its own, such a hole would be cut
    on the wrong side, into the part. A contour that leaves the polygon by more crosses it
    (:func:`~camtool.toolpath.compensate.crossings` reports the pair when what lies on
    either side is wider than the tolerance). Only pairs whose boxes and first points allow
    it are measured, each polygon grown once (``(N,)`` bool, like ``covered``).
    """
    import numpy as np
    import shapely

    out = np.zeros(len(which), dtype=bool)
    todo = np.flatnonzero(~covered)
    if not len(todo):
        return out
    inner = shapely.bounds(outlines[which[todo]])
    outer = shapely.bounds(polygons[around[todo]])
    fits = np.all(inner[:, :2] >= outer[:, :2] - _TOUCH_MM, axis=1) & np.all(
        inner[:, 2:] <= outer[:, 2:] + _TOUCH_MM, axis=1
    )
    todo = todo[fits]
    starts = shapely.get_point(outlines[which[todo]], 0)  # as near as the whole must be
    todo = todo[shapely.dwithin(polygons[around[todo]], starts, _TOUCH_MM)]
    if not len(todo):
        return out
    grown = np.empty(len(polygons), dtype=object)
    used = np.unique(around[todo])
    grown[used] = shapely.buffer(polygons[used], _TOUCH_MM, quad_segs=2)
    out[todo] = shapely.covered_by(outlines[which[todo]], grown[around[todo]])
    return out


def _near(outlines: Any, closed: list[int]) -> tuple[tuple[int, int, float], ...]:
    """The closed contours whose outlines lie within :data:`NEAR_MM` all along (Nesting.near).

    Pairs whose boxes differ by at most :data:`NEAR_MM` on every side
    (:func:`_same_boxes`) are measured:
    shapely's discrete Hausdorff distance of their vertices (each one's distance to the
    other outline; a lower bound), then for those within :data:`NEAR_MM` with their
    segments cut to :data:`_NEAR_SAMPLE_MM` at most (arcs are already chords within
    :data:`_NEST_TOLERANCE_MM`).
    """
    import numpy as np
    import shapely

    rings = outlines[closed]
    a, b = _same_boxes(shapely.bounds(rings), NEAR_MM)
    within = shapely.hausdorff_distance(rings[a], rings[b]) <= NEAR_MM
    a, b = a[within], b[within]
    if not len(a):
        return ()
    gaps = shapely.hausdorff_distance(
        shapely.segmentize(rings[a], _NEAR_SAMPLE_MM), shapely.segmentize(rings[b], _NEAR_SAMPLE_MM)
    )
    ids = np.asarray(closed, dtype=np.int64)
    found = np.flatnonzero(gaps <= NEAR_MM)
    return tuple(
        (int(ids[a[k]]), int(ids[b[k]]), float(gaps[k]))
        for k in found[np.lexsort((b[found], a[found]))]
    )


def _outline_coords(contours: Sequence[Contour], tolerance: float) -> tuple[Any, Any]:
    """Every contour's :meth:`~camtool.model.shapes.Contour.points`, as arrays, bit for bit.

    Returns ``(coords, counts)``: ``(N, 2)`` float64 mm, the contours' polylines one after
    the other, and ``(len(contours),)`` int64 points per contour. The arcs' chords are
    computed together: the angles ``a0 + sweep·(k/n)`` and the products and sums in numpy
    (IEEE operations, the same bits as Python's), the radius, angles, cosines and sines
    with Python's own ``math`` functions (numpy's ``hypot``, ``arctan2``, ``cos`` may differ
    in the last bit) and the chord count by :func:`~camtool.model.shapes.chord_count`
    itself (its errors included).

    Raises:
        GeometryError, UsageError: as :func:`~camtool.model.shapes.chord_count`.
    """
    import itertools
    import math
    import operator

    import numpy as np

    from camtool.model.shapes import FULL_CIRCLE_EPS, TAU, Arc

    segs = [s for c in contours for s in c.segments]
    per_contour = np.fromiter((len(c.segments) for c in contours), np.int64, len(contours))
    is_arc = np.fromiter((type(s) is Arc for s in segs), bool, len(segs))
    arcs = [s for s in segs if type(s) is Arc]
    adds = np.ones(len(segs), dtype=np.int64)  # points a segment adds after its start
    if arcs:
        flat = itertools.chain.from_iterable
        points3 = map(operator.attrgetter("start", "end", "centre"), arcs)
        ends6 = np.fromiter(flat(flat(points3)), np.float64, 6 * len(arcs)).reshape(-1, 6)
        sx, sy, ex, ey, cx, cy = ends6.T
        cw = np.fromiter((a.clockwise for a in arcs), bool, len(arcs))
        dx0, dy0 = (sx - cx).tolist(), (sy - cy).tolist()
        r = np.fromiter(map(math.hypot, dx0, dy0), np.float64, len(arcs))
        a0 = np.fromiter(map(math.atan2, dy0, dx0), np.float64, len(arcs))
        a1 = np.fromiter(
            map(math.atan2, (ey - cy).tolist(), (ex - cx).tolist()), np.float64, len(arcs)
        )
        gap = np.fromiter(map(math.hypot, (ex - sx).tolist(), (ey - sy).tolist()), np.float64)
        with np.errstate(all="ignore"):
            full = gap <= FULL_CIRCLE_EPS * np.where(r > 1.0, r, 1.0)  # max(1.0, r)
            ccw = np.remainder(a1 - a0, TAU)  # Python's float % (floored, as fmod then sign)
        ccw[ccw == 0.0] = TAU
        sweep = np.where(cw, -(TAU - ccw), ccw)
        sweep[full] = np.where(cw[full], -TAU, TAU)
        n = _chord_counts(r, np.abs(sweep), tolerance)
        adds[is_arc] = n
    counts = np.add.reduceat(adds, np.r_[0, np.cumsum(per_contour)[:-1]]) + 1
    coords = np.empty((int(counts.sum()), 2), dtype=np.float64)
    # where each segment's added points begin: after its contour's start and the segments before
    seg_contour = np.repeat(np.arange(len(contours)), per_contour)
    first_point = np.r_[0, np.cumsum(counts)[:-1]]
    seg_first = np.cumsum(adds) - adds + seg_contour + 1  # past each earlier contour's start
    starts = itertools.chain.from_iterable(c.segments[0].start for c in contours)
    coords[first_point] = np.fromiter(starts, np.float64, 2 * len(contours)).reshape(-1, 2)
    ends = itertools.chain.from_iterable(s.end for s in segs)
    coords[seg_first + adds - 1] = np.fromiter(ends, np.float64, 2 * len(segs)).reshape(-1, 2)
    if arcs:
        inner = n - 1
        rep = np.repeat(np.arange(len(arcs)), inner)
        k = np.arange(len(rep)) - np.repeat(np.cumsum(inner) - inner, inner) + 1
        angle = a0[rep] + sweep[rep] * (k / n[rep])
        cos = np.fromiter(map(math.cos, angle.tolist()), np.float64, len(angle))
        sin = np.fromiter(map(math.sin, angle.tolist()), np.float64, len(angle))
        at = np.repeat(seg_first[is_arc], inner) + k - 1
        coords[at, 0] = cx[rep] + r[rep] * cos
        coords[at, 1] = cy[rep] + r[rep] * sin
    return coords, counts


def _chord_counts(radius: Any, sweep: Any, tolerance: float) -> Any:
    """:func:`~camtool.model.shapes.chord_count` of each ``(radius, sweep)``, bit for bit.

    ``radius``, ``sweep``: ``(A,)`` float64 (mm, unsigned radians). The usual arcs (finite,
    the tolerance under the radius and over a millionth of it, the count within
    :data:`~camtool.model.shapes.MAX_CHORDS`) are counted together, with Python's
    ``math.acos``; every other arc by ``chord_count`` itself, in order, so that its errors
    are the same.
    """
    import itertools
    import math

    import numpy as np

    from camtool.model.shapes import _SMALL_RATIO, MAX_CHORDS, chord_count

    with np.errstate(all="ignore"):
        ratio = tolerance / radius
        usual = (
            np.isfinite(radius)
            & np.isfinite(sweep)
            & (tolerance < radius)
            & (ratio > _SMALL_RATIO)
            & bool(tolerance > 0 and math.isfinite(tolerance))
        )
        half = np.fromiter(map(math.acos, (1.0 - ratio[usual]).tolist()), np.float64)
        count = sweep[usual] / (2.0 * half)
    usual[usual] = count <= MAX_CHORDS
    count = count[count <= MAX_CHORDS]
    n = np.empty(len(radius), dtype=np.int64)
    n[usual] = np.maximum(1, np.ceil(count - 1e-9)).astype(np.int64)
    odd = np.flatnonzero(~usual)
    n[odd] = np.fromiter(
        map(chord_count, radius[odd].tolist(), sweep[odd].tolist(), itertools.repeat(tolerance)),
        np.int64,
        len(odd),
    )
    return n


def _same_boxes(bounds: Any, near: float) -> tuple[Any, Any]:
    """The pairs ``(a, b)`` (int64 arrays, ``a < b``) of rows of ``bounds`` within ``near``.

    ``bounds`` is ``(n, 4)``: boxes ``(xmin, ymin, xmax, ymax)``, mm. The boxes are put in
    cells ``2·near`` wide on each side, once for each of the 16 ways of shifting the cells
    by ``near`` or not on each side: two values within ``near`` share a cell in one of the
    two shifts of their side, so two boxes within ``near`` share their four cells in one of
    the 16. Only boxes that share cells are compared, so boxes lined up on one edge (a
    thousand parts at X0) cost no more than boxes apart.
    """
    import itertools

    import numpy as np

    found: set[tuple[int, int]] = set()
    for shift in itertools.product((0.0, near), repeat=4):
        cells = np.floor((bounds + np.asarray(shift)) / (2.0 * near)).astype(np.int64)
        order = np.lexsort(cells.T[::-1])
        ordered = cells[order]
        new = np.r_[True, (ordered[1:] != ordered[:-1]).any(axis=1)]
        starts = np.flatnonzero(new)
        sizes = np.diff(np.r_[starts, len(order)])
        shared = sizes > 1
        for start, size in zip(starts[shared].tolist(), sizes[shared].tolist(), strict=True):
            group = sorted(order[start : start + size].tolist())
            found.update(itertools.combinations(group, 2))
    pairs = np.array(sorted(found), dtype=np.int64).reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    keep = np.abs(bounds[a] - bounds[b]).max(axis=1) <= near if len(a) else np.zeros(0, bool)
    return a[keep], b[keep]


def _nesting_one_by_one(contours: Sequence[Contour]) -> Nesting:
    """:func:`nesting` with one shapely geometry and one tree query per contour (the reference)."""
    from shapely import LineString, STRtree

    outlines = [LineString(c.points(_NEST_TOLERANCE_MM)) for c in contours]
    closed = [i for i, c in enumerate(contours) if c.closed]
    polygons = [enclosed(outlines[i].coords) for i in closed]
    areas = {i: poly.area for i, poly in zip(closed, polygons, strict=True)}
    tree = STRtree(polygons)
    parents: list[tuple[int, ...]] = []
    grown = [poly.buffer(_TOUCH_MM, quad_segs=2) for poly in polygons]
    for i, outline in enumerate(outlines):
        around = set(tree.query(outline, predicate="covered_by").tolist())
        x0, y0, x1, y1 = outline.bounds
        for k in tree.query(outline):  # touching its edge from within (_touching_inside)
            a0, b0, a1, b1 = polygons[k].bounds
            box = x0 >= a0 - _TOUCH_MM and y0 >= b0 - _TOUCH_MM
            if box and x1 <= a1 + _TOUCH_MM and y1 <= b1 + _TOUCH_MM and grown[k].covers(outline):
                around.add(int(k))
        inside = (closed[k] for k in around)
        parents.append(tuple(sorted(j for j in inside if areas[j] > areas.get(i, 0.0))))
    import numpy as np

    return Nesting(tuple(parents), _near(np.array(outlines, dtype=object), closed))


MAX_SEARCH_CUTS = 5000
"""Most cuts ``--order reversals`` and ``--order mirror`` plan (their searches grow with the
square of the count; the parts they are for have tens of cuts). ``travel`` has no limit."""

SMALL_PART_MM = 1.0
"""Parts smaller than this (bounding box of the cuts) fail after about 16 compensations."""
MAX_REVERSALS_SMALL = 16
"""Reversals above which a small part is warned about (UNAM-GMM S000-19, L3205–L3211)."""

ORDER_KEYS = ("drawn", "travel", "planned")
"""Keys of :attr:`Ordering.reversals` and :attr:`Ordering.travel_mm`."""


@dataclass(frozen=True)
class Ordering:
    """The cutting order and what it costs.

    Attributes:
        cuts: cuts in cutting order, each rotated/reversed (or split, for
            ``mirror``) as it will be cut.
        mode: the ``--order`` that made it.
        reversals: ``(x, y)`` axis reversals (:func:`~camtool.toolpath.reversals.count_reversals`,
            rapids included) for the ``"drawn"`` order (as given, inside before
            outside), the ``"travel"`` order and the ``"planned"`` one.
        travel_mm: rapid travel of the same three, mm (origin → first start included).
        mirror_axis: the mirror line for ``mirror`` (``"x = 5.0000"``, mm), else ``None``.
        mirror_point: the shared start point Ie of ``mirror``, mm, else ``None``.
        findings: what the user must know about the order.
    """

    cuts: tuple[Cut, ...]
    mode: str
    reversals: Mapping[str, tuple[int, int]]
    travel_mm: Mapping[str, float]
    mirror_axis: str | None = None
    mirror_point: Point | None = None
    findings: tuple[Finding, ...] = field(default=())

    def summary(self) -> list[str]:
        """One or two lines for stderr: reversals and rapids before and after."""
        p = self.reversals["planned"]
        rapids = f"rapids {self.travel_mm['drawn']:.3f} → {self.travel_mm['planned']:.3f} mm"
        if self.mode == "travel":
            return [f"order travel: {rapids}; X/Y reversals {p[0]}/{p[1]}"]
        d, t = self.reversals["drawn"], self.reversals["travel"]
        text = (
            f"order {self.mode}: X/Y reversals {d[0]}/{d[1]} → {p[0]}/{p[1]} "
            f"(travel order {t[0]}/{t[1]}); {rapids}"
        )
        if self.mirror_point is None:
            return [text]
        point = fmt_point(self.mirror_point)
        return [text, f"  mirror about {self.mirror_axis} mm from {point} mm"]

    def to_json(self) -> dict[str, Any]:
        """``{"mode", "reversals": {key: {"x", "y"}}, "travel_mm": {key: mm}, "mirror_axis"}``."""
        return {
            "mode": self.mode,
            "reversals": {k: {"x": v[0], "y": v[1]} for k, v in self.reversals.items()},
            "travel_mm": dict(self.travel_mm),
            "mirror_axis": self.mirror_axis,
            "mirror_point": self.mirror_point,
        }


def order_cuts(
    cuts: Sequence[Cut], nest: Nesting, options: PlanOptions, backlash_um: tuple[float, float]
) -> Ordering:
    """Order the cuts as ``options.order`` asks, inside before outside.

    Args:
        cuts: the compensated or pocket cuts, mm; ``cut.group`` indexes ``nest``.
        nest: containment of the groups (:func:`nesting`).
        options: ``order``, ``origin`` (tool position before the first cut, mm),
            ``reverse_open`` (``reversals`` may cut open cuts with ``may_reverse``
            backwards, as ``travel`` does) and ``tolerance`` (how far a mirror image may
            be, mm) are used.
        backlash_um: ``(bx, by)`` reversal weight of each axis, µm (the machine's
            backlash; both 0 when unknown: every reversal weighs 1).

    Returns:
        The order, with the reversal counts and rapids of the drawn, travel and
        planned orders, and a finding when a part under 1 mm still needs more
        than 16 reversals outside mirror order (UNAM-GMM S000-19).

    Raises:
        ToolpathError: ``mirror`` on a drawing symmetric about neither axis.
        UsageError: ``reversals`` or ``mirror`` on more than :data:`MAX_SEARCH_CUTS` cuts.
    """
    origin = options.origin
    if options.order != "travel" and len(cuts) > MAX_SEARCH_CUTS:
        raise UsageError(
            f"--order {options.order} plans at most {MAX_SEARCH_CUTS} cuts and this drawing "
            f"has {len(cuts)}; use --order travel, or plan part of it (--layers)"
        )
    before = precedence(cuts, nest.parents)
    drawn_seq = drawn_order(cuts, before)
    travel_seq = travel_order(cuts, before, origin)
    sequences = {"drawn": _cuts(cuts, drawn_seq), "travel": _cuts(cuts, travel_seq)}
    axis: str | None = None
    point: Point | None = None
    findings: list[Finding] = []
    if options.order == "travel":
        sequences["planned"] = sequences["travel"]
    elif options.order == "reversals":
        allowed = [drawn_seq]
        flips = any(rev and not cuts[i].path.closed for i, _, rev in travel_seq)
        if options.reverse_open or not flips:
            allowed.append(travel_seq)
        planned = reversal_order(
            cuts, before, origin, backlash_um, allowed, flip_open=options.reverse_open
        )
        sequences["planned"] = _cuts(cuts, planned)
    else:
        from camtool.toolpath.mirror import mirror_order

        depth = [nest.depth(cut.group) for cut in cuts]
        plan = mirror_order(cuts, before, depth, origin, options.tolerance)
        sequences["planned"] = plan.cuts
        axis, point = plan.axis, plan.point
        findings.extend(plan.findings)
    travel: dict[str, float] = {}
    for k, v in sequences.items():
        same = next((j for j in travel if sequences[j] is v), None)  # planned = travel
        travel[k] = travel[same] if same else _rapids(v, origin)
    reversals = ReversalCounts(sequences, origin)
    findings.extend(_small_part(sequences["planned"], reversals, options.order))
    return Ordering(
        tuple(sequences["planned"]),
        options.order,
        reversals,
        MappingProxyType(travel),
        axis,
        point,
        tuple(findings),
    )


class ReversalCounts(Mapping[str, tuple[int, int]]):
    """``(x, y)`` axis reversals of each order (:func:`count_reversals`), read-only.

    Each order is counted when first read: the summary of ``--order travel`` reads only
    the planned one, the drawn order's is read by the report and the search orders'
    summaries. An order that is the same sequence as another is counted once.
    """

    def __init__(self, sequences: Mapping[str, Sequence[Cut]], origin: Point) -> None:
        self._sequences = dict(sequences)
        self._origin = origin
        # each key → the first key of the same sequence (the planned order is the travel one)
        self._first = {
            k: next(j for j, v in sequences.items() if v is s) for k, s in sequences.items()
        }
        self._counted: dict[str, tuple[int, int]] = {}

    def __getitem__(self, key: str) -> tuple[int, int]:
        first = self._first[key]
        if first not in self._counted:
            self._counted[first] = count_reversals(self._sequences[first], self._origin)
        return self._counted[first]

    def __iter__(self) -> Iterator[str]:
        return iter(self._sequences)

    def __len__(self) -> int:
        return len(self._sequences)


def _cuts(cuts: Sequence[Cut], seq: Sequence[Step]) -> tuple[Cut, ...]:
    return tuple(oriented(cuts[i], k, rev) for i, k, rev in seq)


def _rapids(cuts: Sequence[Cut], origin: Point) -> float:
    here, total = origin, 0.0
    for cut in cuts:
        total += distance(here, cut.path.start)
        here = cut.path.end
    return total


def _small_part(cuts: Sequence[Cut], reversals: ReversalCounts, mode: str) -> list[Finding]:
    """UNAM-GMM S000-19 (L3205–L3211): a part under 1 mm fails after about 16 compensations.

    The part's size is tested first: the planned order's reversals are counted only for a
    part under 1 mm.
    """
    if not cuts or mode == "mirror":
        return []
    x0, y0, x1, y1 = cuts[0].path.bbox()
    for cut in cuts[1:]:
        if max(x1 - x0, y1 - y0) >= SMALL_PART_MM:
            return []  # large already: the other boxes cannot make it small
        b = cut.path.bbox()
        x0, y0, x1, y1 = min(x0, b[0]), min(y0, b[1]), max(x1, b[2]), max(y1, b[3])
    size = max(x1 - x0, y1 - y0)
    counts = reversals["planned"]
    if size >= SMALL_PART_MM or sum(counts) <= MAX_REVERSALS_SMALL:
        return []
    better = "--order mirror" if mode == "reversals" else "--order reversals or --order mirror"
    return [
        Finding(
            "ordering",
            f"order {mode}: {sum(counts)} axis reversals (X {counts[0]}, Y {counts[1]}) on a "
            f"part of {size:.3f} mm: parts under {SMALL_PART_MM:g} mm fail after about "
            f"{MAX_REVERSALS_SMALL} backlash compensations (UNAM-GMM §5.3); try {better}",
            None,
            float(sum(counts)),
        )
    ]
