"""Pockets: clear the inside of closed contours, down to their islands.

The material to remove is the even-odd region of the closed contours: a contour at
even nesting depth bounds a pocket, the closed contours directly inside it (depth + 1)
are its islands, and a contour inside an island (depth + 2) starts a new pocket. Each
region is a shapely polygon with holes (arcs as chords within ``tolerance / 4``).

Design notes: docs/internals.md, ``camtool/toolpath/pocket.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from shapely import LineString, Polygon, affinity, prepared
from shapely import Point as ShapelyPoint
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from camtool.geometry.arcfit import fit_polyline
from camtool.geometry.area import enclosed
from camtool.model.errors import InputError, ToolpathError, UsageError
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import TAU, Arc, Contour, Line, Point, Segment, distance
from camtool.model.units import fmt_num
from camtool.toolpath.cuts import (
    MAX_LISTED,
    Cut,
    Finding,
    Stage,
    open_left_out,
    self_crossing,
    where,
)
from camtool.toolpath.offset import offset_contour
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting
from camtool.toolpath.pocket_uncut import polygons, quad_segs, uncut_findings

__all__ = ["Region", "pocket", "regions"]

Ring = tuple[tuple[Segment, ...], bool]
"""A closed tool path (segments, start == end) and whether it goes around an island."""

MAX_POCKET_PATHS = 100_000
"""Most rings (concentric) or lines (zigzag) one pocket region may need; a real job
(a 1 m pocket with a 10 µm step-over) stays under it."""

MAX_POCKET_WORK = 10_000_000
"""Most rings (or lines) × outline vertices a job's pockets may need together. Each ring
is a GEOS buffer of the whole region, its time about proportional to the region's
vertices (docs/performance.md): a detailed outline with a tool of a few µm would run for
hours; a real job (a 60 000-vertex outline with a 1 mm tool:
1.3e6; LibreCAD's ``kin100.dxf`` at 120 mm with a 0.01 mm tool: 5.5e6) stays under it."""
_ZIGZAG_MARGIN = 0.05  # zigzag lines stop this share of the diameter short of the wall pass


@dataclass(frozen=True)
class Region:
    """One connected area to clear: a pocket boundary minus its islands.

    Attributes:
        group: index of the boundary contour (the cuts' group).
        boundary: the pocket's boundary contour (for messages).
        area: the area, mm (exterior counter-clockwise, holes clockwise).
        islands: the island contours (closed, depth + 1).
        whole: ``area`` is the boundary's full polygon (not one piece of a
            self-touching or island-split outline), so exact offsets apply.
    """

    group: int
    boundary: Contour
    area: Polygon
    islands: tuple[Contour, ...]
    whole: bool


@dataclass(frozen=True)
class _Node:
    """One connected piece of an offset: its rings and the pieces nested inside."""

    polygon: Polygon
    rings: tuple[Ring, ...]
    children: tuple[_Node, ...]


@dataclass(frozen=True)
class _Path:
    """A piece of tool path in cutting order: a closed ring or a zigzag line."""

    segs: tuple[Segment, ...]
    ring: bool


def pocket(
    contours: Sequence[Contour],
    nest: Nesting,
    options: PlanOptions,
    progress: Progress = no_progress,
) -> Stage:
    """Clear the inside of every pocket region; open contours are not cut (said in findings).

    Args:
        contours: chained contours, mm.
        nest: their containment (:func:`~camtool.toolpath.order.nesting`).
        options: ``offset == "pocket"``; the tool, ``stepover``, ``pocket``,
            ``pocket_angle_deg``, ``direction`` and ``tolerance`` are used.
        progress: told the ``pocketing`` stage (``done`` of ``total`` regions cleared).

    Returns:
        Cuts of kind ``"pocket"`` (group = the pocket boundary's index; in each
        group the order given is the cutting order), and findings:
        ``open-left-out`` (:func:`~camtool.toolpath.cuts.open_left_out`), ``offset-vanished``
        (a pocket outline that encloses no area, width 0, at its start), ``uncut``
        (regions narrower than the tool, with location and area mm²), ``tight-corner``
        (corners left with the tool radius) and ``offset-fallback``.

    Raises:
        ToolpathError: no region can be pocketed at all (no closed contours, or
            every region narrower than the tool).
    """
    cuts: list[Cut] = []
    findings: list[Finding] = []
    no_area: list[int] = []
    invalid: list[int] = []
    outlines: dict[int, BaseGeometry] = {}
    todo = regions(contours, nest, options.tolerance, no_area, invalid, outlines)
    _check_work(todo, options)
    progress(Step("pocketing", 0, len(todo)))
    for done, region in enumerate(todo, start=1):
        region_cuts, found = _pocket_region(region, options)
        cuts.extend(region_cuts)
        findings.extend(found)
        progress(Step("pocketing", done, len(todo)))
    if not cuts:
        raise ToolpathError(_nothing_message(contours, options))
    findings[:0] = [
        *open_left_out(contours, "--offset pocket"),
        *(_no_area(contours[i]) for i in no_area),
        *filter(
            None,
            (
                self_crossing(contours[i], options.tolerance, "pocket")
                for i in invalid
                if i not in no_area  # drawn there and back: said so above
            ),
        ),
        *overlaps(contours, nest, outlines),
    ]
    return Stage(tuple(cuts), tuple(findings))


OVERLAP_MIN_MM2 = 1e-6
"""Common area, mm², below which two pocket outlines only touch (a shared edge, rounding)."""


def overlaps(
    contours: Sequence[Contour], nest: Nesting, outlines: dict[int, BaseGeometry]
) -> list[Finding]:
    """``overlap`` findings: pairs of pocket outlines whose areas overlap, neither inside the other.

    Each outline is cleared as a region of its own (:func:`regions`): the common area
    twice, and a contour inside both is two outlines deep, so it is cleared as a
    pocket of its own, not kept as an island. The drawing may mean either, so it is
    said, with the common area (mm²) at a point inside it (shapely, GEOS). At most
    :data:`~camtool.toolpath.cuts.MAX_LISTED` pairs are named, the rest counted.

    ``outlines``: each pocket outline's index and the area it encloses (:func:`regions`).
    """
    if len(outlines) < 2:
        return []
    indices, areas = list(outlines), list(outlines.values())
    left, right = shapely.STRtree(areas).query(areas, predicate="intersects")
    found: list[tuple[int, int, BaseGeometry]] = []
    for a, b in sorted((int(a), int(b)) for a, b in zip(left, right, strict=True) if a < b):
        i, j = indices[a], indices[b]
        if i in nest.parents[j] or j in nest.parents[i]:
            continue  # one inside the other: an outline in a pocket's island, not an overlap
        common = areas[a].intersection(areas[b])
        if common.area > OVERLAP_MIN_MM2:
            found.append((i, j, common))
    out = [_overlap(contours, nest, i, j, common) for i, j, common in found[:MAX_LISTED]]
    if len(found) > MAX_LISTED:
        rest = found[MAX_LISTED:]
        out.append(
            Finding(
                "overlap",
                f"{len(rest)} more pairs of pocket outlines overlap, each outline cleared whole",
                None,
                float(sum(common.area for _i, _j, common in rest)),
            )
        )
    return out


def _overlap(
    contours: Sequence[Contour], nest: Nesting, i: int, j: int, common: BaseGeometry
) -> Finding:
    """The ``overlap`` finding of pocket outlines ``i`` and ``j`` (:func:`overlaps`)."""
    inside = sum(1 for parents in nest.parents if i in parents and j in parents)
    spot = common.representative_point()
    at = (float(spot.x), float(spot.y))
    kept = (
        f"; {inside} contour{'s' if inside > 1 else ''} inside both "
        f"{'are' if inside > 1 else 'is'} cleared as a pocket, not kept as an island"
        if inside
        else ""
    )
    return Finding(
        "overlap",
        f"{where(contours[i])} and {where(contours[j])}: the pocket outlines overlap "
        f"({fmt_num(common.area, 3)} mm² around ({at[0]:.4f}, {at[1]:.4f}) mm): each is "
        f"cleared whole, the common area twice{kept}; draw one outline around an area meant "
        "as one, or pocket them in operations of their own",
        at,
        float(common.area),
    )


def _nothing_message(contours: Sequence[Contour], options: PlanOptions) -> str:
    if not any(c.closed for c in contours):
        return f"--offset pocket needs closed contours; the drawing has {len(contours)} open one(s)"
    return (
        f"every pocket is narrower than the {options.tool_diameter:g} mm tool; nothing can be "
        "cleared (use a smaller tool)"
    )


def regions(
    contours: Sequence[Contour],
    nest: Nesting,
    tolerance: float,
    no_area: list[int] | None = None,
    invalid: list[int] | None = None,
    outlines: dict[int, BaseGeometry] | None = None,
) -> list[Region]:
    """The even-odd regions to clear, one per connected piece of each pocket.

    Args:
        contours: contours, mm; open ones are ignored.
        nest: their containment.
        tolerance: arcs become chords within ``tolerance / 4`` mm.
        no_area: given, the indices of the pocket outlines that enclose no area (drawn
            there and back) are appended to it: they give no region.
        invalid: given, the indices of the pocket outlines that are no valid polygon (one
            that crosses itself: its region is the area it encloses) are appended to it.
        outlines: given, each pocket outline's index is mapped in it to the area it
            encloses, before its islands are taken out (:func:`overlaps` compares them).
    """
    out: list[Region] = []
    for i, contour in enumerate(contours):
        if not contour.closed or nest.depth(i) % 2:
            continue
        islands = tuple(
            c
            for j, c in enumerate(contours)
            if c.closed and i in nest.parents[j] and nest.depth(j) == nest.depth(i) + 1
        )
        outline = contour.points(tolerance / 4)
        if invalid is not None and not Polygon(outline).is_valid:
            invalid.append(i)
        area: BaseGeometry = enclosed(outline)
        if outlines is not None:
            outlines[i] = area
        if area.is_empty and no_area is not None:
            no_area.append(i)
        for island in islands:
            area = area.difference(enclosed(island.points(tolerance / 4)))
        parts = polygons(area)
        for part in parts:
            out.append(Region(i, contour, orient(part), islands, len(parts) == 1))
    return out


def _no_area(contour: Contour) -> Finding:
    """An ``offset-vanished`` finding of width 0 for a pocket outline that encloses no area.

    Located at its start, as an offset that vanishes on such a contour is
    (:func:`camtool.toolpath.compensate.compensate`).
    """
    return Finding(
        "offset-vanished",
        f"{where(contour)}: a closed contour that encloses no area (drawn there and back): "
        "no pocket to clear there; cut it on its line (--offset on, or an engrave "
        "operation) or draw it as an outline",
        contour.start,
        0.0,
    )


def _pocket_region(region: Region, options: PlanOptions) -> tuple[list[Cut], list[Finding]]:
    r, tol = options.radius, options.tolerance
    step = options.stepover * options.tool_diameter
    climb = options.direction != "conventional"
    zigzag = options.pocket == "zigzag"
    levels = _levels(region.area, r, step, tol, 1 if zigzag else None)
    if not levels:
        return [], uncut_findings(region.area, region.boundary, [], options)
    wall, findings = _wall_rings(region, levels[0], options)
    roots = _tree(levels, options, wall, centre=not zigzag)
    paths = _order_rings(roots, region.boundary.start, tol)
    if zigzag:
        area = region.area.buffer(-(r + _ZIGZAG_MARGIN * options.tool_diameter))
        here = paths[-1].segs[-1].end
        lines = order_lines(zigzag_lines(area, step, options.pocket_angle_deg), here)
        paths.extend(_Path((line,), False) for line in lines)
    cuts = _link(paths, region, r, tol, "right" if climb else "left")
    findings.extend(uncut_findings(region.area, region.boundary, cuts, options))
    return cuts, findings


def _check_work(todo: Sequence[Region], options: PlanOptions) -> None:
    """Refuse pockets needing too many rings or too much work, before any is made.

    A region needs at most ``(d - r) / step`` rings, ``d`` its inradius (the largest
    circle inside it, from GEOS's maximum inscribed circle, an upper bound here), or
    its diagonal over the step-over in zigzag lines; each costs about one pass over the
    region's outline vertices.

    Raises:
        UsageError: the step-over is finer than ``tolerance`` (each ring is fitted within
            it, so rings closer than it are not told apart and may cross); a region needs
            more than :data:`MAX_POCKET_PATHS` rings or lines, or the job more than
            :data:`MAX_POCKET_WORK` rings × vertices (names the region, --stepover and
            --tool-diameter).
    """
    step = options.stepover * options.tool_diameter
    if step < options.tolerance:
        raise UsageError(
            f"a pocket step-over of {step:g} mm ({_step_options(options)}) is finer than "
            f"--tolerance {options.tolerance:g} mm, within which each ring is fitted to its "
            "offset: neighbouring passes could not be told apart; give a --stepover of "
            f"at least {options.tolerance / options.tool_diameter:.3g}, or a finer --tolerance"
        )
    what = "zigzag lines" if options.pocket == "zigzag" else "rings"
    total, worst = 0.0, (-1.0, 0.0, 0, todo[0] if todo else None)  # work, rings, vertices
    for region in todo:
        count = _path_count(region.area, step, options)
        if count > MAX_POCKET_PATHS:
            raise UsageError(
                f"{_pocket_size(region)} would need about {count:.3g} {what} at a step-over "
                f"of {step:g} mm ({_step_options(options)}), more than the limit of "
                f"{MAX_POCKET_PATHS} per pocket; give a larger --stepover or tool"
            )
        vertices = int(shapely.get_num_coordinates(region.area))
        total += count * vertices
        if count * vertices > worst[0]:
            worst = (count * vertices, count, vertices, region)
    _, count, vertices, named = worst
    if total <= MAX_POCKET_WORK or named is None:
        return
    raise UsageError(
        f"{_pocket_size(named)} with {vertices} outline "
        f"vertices would need about {count:.3g} {what} at a step-over of {step:g} mm "
        f"({_step_options(options)}); the job's pockets together need {total:.3g} "
        f"{what} × vertices, more than the limit of {MAX_POCKET_WORK:.3g} for one job (each "
        "ring a pass over the outline); give a larger --stepover or tool, or a simpler outline"
    )


def _path_count(area: Polygon, step: float, options: PlanOptions) -> float:
    """Upper bound of the rings (or zigzag lines) a region needs at ``step`` mm apart."""
    x0, y0, x1, y1 = area.bounds
    w, h = x1 - x0, y1 - y0
    if options.pocket == "zigzag":
        return math.hypot(w, h) / step
    reach = min(w, h) / 2
    if reach > 0 and area.area > 0:
        slack = reach / 1000  # the circle's centre is found within it
        circle = shapely.maximum_inscribed_circle(area, tolerance=slack)
        reach = min(reach, circle.length + slack)
    return max(0.0, reach - options.radius) / step


def _pocket_size(region: Region) -> str:
    x0, y0, x1, y1 = region.area.bounds
    return f"{where(region.boundary)}: a {fmt_num(x1 - x0, 3)} × {fmt_num(y1 - y0, 3)} mm pocket"


def _step_options(options: PlanOptions) -> str:
    return f"--stepover {options.stepover:g} × --tool-diameter {options.tool_diameter:g} mm"


def _buffer(area: Polygon, amount: float, tol: float) -> list[Polygon]:
    """Pieces of ``area`` shrunk by ``amount`` mm; slivers thinner than ``tol``² dropped."""
    shrunk = area.buffer(-amount, quad_segs=quad_segs(amount, tol))
    return [p for p in polygons(shrunk) if p.area > tol * tol]


def _levels(
    area: Polygon, r: float, step: float, tol: float, limit: int | None
) -> list[list[Polygon]]:
    """Offsets of ``area`` at ``r + k·step`` until empty (at most ``limit`` levels).

    One at a time, though each level is ``area`` shrunk once and could be made on another
    core: GEOS's buffer of a large region holds about a gigabyte while it works, and two
    at once more than double the job's peak (docs/performance.md).
    """
    levels: list[list[Polygon]] = []
    while limit is None or len(levels) < limit:
        parts = _buffer(area, r + len(levels) * step, tol)
        if not parts:
            break
        levels.append(parts)
    return levels


def _tree(
    levels: list[list[Polygon]], options: PlanOptions, wall: list[Ring] | None, centre: bool
) -> list[_Node]:
    """Nodes of the offset levels, each holding the nodes of the next level inside it.

    With ``centre``, a piece with nothing inside gets the extra rings of :func:`_centre`.
    """
    r, tol = options.radius, options.tolerance
    step = options.stepover * options.tool_diameter
    climb = options.direction != "conventional"
    below: list[_Node] = []
    for k in range(len(levels) - 1, -1, -1):
        nodes = []
        for poly in levels[k]:
            inside = tuple(n for n in below if poly.contains(n.polygon.representative_point()))
            if not inside and centre:
                inside = _centre(poly, r, step, tol, climb)
            rings = tuple(wall) if k == 0 and wall is not None else _fitted_rings(poly, tol, climb)
            nodes.append(_Node(poly, rings, inside))
        below = nodes
    return below


def _centre(poly: Polygon, r: float, step: float, tol: float, climb: bool) -> tuple[_Node, ...]:
    """Extra rings where the middle of a last offset lies farther than ``r`` from its rings.

    The deepest distance inside each such part is found by bisection; the extra
    ring runs ``r / 2`` inside it, so the tool covers the middle.
    """
    out: list[_Node] = []
    for part in _buffer(poly, r, tol):
        lo, hi = 0.0, max(step, r)
        while _buffer(part, hi, tol):
            hi *= 2.0
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _buffer(part, mid, tol) else (lo, mid)
        for piece in _buffer(poly, r / 2 + lo, tol):
            out.append(_Node(piece, _fitted_rings(piece, tol, climb), ()))
    return tuple(out)


def _fitted_rings(poly: Polygon, tol: float, climb: bool) -> tuple[Ring, ...]:
    """The polygon's exterior then its holes as arcs and lines within ``tol / 2``."""
    rings = [(poly.exterior, False), *((hole, True) for hole in poly.interiors)]
    return tuple(_oriented(fit_ring(list(ring.coords), tol), hole, climb) for ring, hole in rings)


def _oriented(segs: Sequence[Segment], hole: bool, climb: bool) -> Ring:
    """Counter-clockwise along an outer wall and clockwise around an island for climb."""
    ccw = Contour(tuple(segs), True).signed_area() > 0
    if ccw != (climb != hole):
        segs = Contour(tuple(segs), True).reversed().segments
    return tuple(segs), hole


def _wall_rings(
    region: Region, level0: list[Polygon], options: PlanOptions
) -> tuple[list[Ring] | None, list[Finding]]:
    """The exact OpenCASCADE wall rings when each boundary offsets on its own, else ``None``."""
    if len(level0) != 1 or not region.whole or len(level0[0].interiors) != len(region.islands):
        return None, []
    r, tol = options.radius, options.tolerance
    climb = options.direction != "conventional"
    try:
        outer = offset_contour(region.boundary, -r)
        around = [offset_contour(island, r) for island in region.islands]
    except ToolpathError as exc:
        return None, [
            Finding(
                "offset-fallback",
                f"{where(region.boundary)}: the exact wall offset failed ({exc}); the wall pass "
                f"follows shapely's buffer fitted with arcs within {tol:g} mm",
                region.boundary.start,
            )
        ]
    poly = level0[0]
    expected = Polygon(poly.exterior).area - sum(Polygon(h).area for h in poly.interiors)
    got = abs(outer.signed_area()) - sum(abs(c.signed_area()) for c in around)
    perimeter = poly.exterior.length + sum(h.length for h in poly.interiors)
    if abs(got - expected) > tol * perimeter:
        return None, []
    rings = [_oriented(outer.segments, False, climb)]
    rings.extend(_oriented(c.segments, True, climb) for c in around)
    return rings, []


def _order_rings(roots: Sequence[_Node], start: Point, tol: float) -> list[_Path]:
    """Rings depth first, nearest piece first; each starts nearest the previous end."""
    out: list[_Path] = []
    here = start
    stack: list[list[_Node]] = [list(roots)]
    while stack:
        pending = stack[-1]
        if not pending:
            stack.pop()
            continue
        probe = ShapelyPoint(here)
        node = min(pending, key=lambda n: n.polygon.exterior.distance(probe))
        pending.remove(node)
        outer, *holes = node.rings
        for segs, _hole in [outer, *_nearest_first(holes, here)]:
            ring = start_near(segs, here, tol)
            out.append(_Path(ring, True))
            here = ring[0].start
        stack.append(list(node.children))
    return out


def _nearest_first(rings: Sequence[Ring], here: Point) -> list[Ring]:
    return sorted(rings, key=lambda ring: min(nearest_on(s, here)[0] for s in ring[0]))


def _link(paths: Sequence[_Path], region: Region, r: float, tol: float, side: str) -> list[Cut]:
    """Join consecutive paths by straight feed moves that keep the tool inside the region."""
    inside = prepared.prep(region.area.buffer(tol))

    def can_link(a: Point, b: Point) -> bool:
        if distance(a, b) <= tol:
            return True
        return bool(inside.covers(LineString([a, b]).buffer(r, quad_segs=8)))

    groups: list[list[_Path]] = []
    for path in paths:
        if groups and can_link(groups[-1][-1].segs[-1].end, path.segs[0].start):
            groups[-1].append(path)
        else:
            groups.append([path])
    return [_cut(group, region, side) for group in groups]


def _cut(group: list[_Path], region: Region, side: str) -> Cut:
    segs: list[Segment] = []
    for path in group:
        if segs and segs[-1].end != path.segs[0].start:
            segs.append(Line(segs[-1].end, path.segs[0].start))
        segs.extend(path.segs)
    closed = len(group) == 1 and group[0].ring
    boundary = region.boundary
    return Cut(
        Contour(tuple(segs), closed, boundary.layer, boundary.source),
        region.group,
        kind="pocket",
        may_reverse=False,
        may_rotate=False,
        material_side=side if all(p.ring for p in group) else None,
    )


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


def zigzag_lines(area: BaseGeometry, spacing: float, angle_deg: float) -> list[Line]:
    """Lines at ``angle_deg`` and ``spacing`` mm apart, clipped to ``area``.

    The lines are centred across the area (the outermost ones at most ``spacing / 2``
    from its edge). Each returned line runs in the direction of ``angle_deg``.

    Args:
        area: where the tool centre may go (polygon or multipolygon), mm.
        spacing: distance between neighbouring lines, mm (> 0).
        angle_deg: line direction, degrees CCW from +X.

    Returns:
        The pieces, row by row; empty when ``area`` is empty.
    """
    if area.is_empty:
        return []
    flat = affinity.rotate(area, -angle_deg, origin=(0.0, 0.0))
    x0, y0, x1, y1 = flat.bounds
    height = y1 - y0
    count = max(1, math.ceil(height / spacing - 1e-9))
    first = y0 + 0.5 * (height - (count - 1) * spacing)
    ys = first + spacing * np.arange(count)
    rows = shapely.linestrings(
        np.stack(
            [
                np.column_stack([np.full(count, x0 - 1.0), ys]),
                np.column_stack([np.full(count, x1 + 1.0), ys]),
            ],
            axis=1,
        )
    )
    cos_a, sin_a = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))

    def back(x: float, y: float) -> Point:
        return (x * cos_a - y * sin_a, x * sin_a + y * cos_a)

    out: list[Line] = []
    for row, y in zip(shapely.intersection(rows, flat), ys, strict=True):
        spans = sorted(
            (min(p[0] for p in g.coords), max(p[0] for p in g.coords)) for g in _lines_of(row)
        )
        out.extend(Line(back(a, float(y)), back(b, float(y))) for a, b in spans if b > a)
    return out


def _lines_of(geom: BaseGeometry) -> list[BaseGeometry]:
    if geom.is_empty:
        return []
    if geom.geom_type == "LineString":
        return [geom]
    return [g for part in getattr(geom, "geoms", ()) for g in _lines_of(part)]


def order_lines(lines: Sequence[Line], start: Point) -> list[Line]:
    """Greedy nearest-end order: each line starts at its end nearest the previous end.

    Args:
        lines: the line pieces, mm.
        start: the tool position before the first line, mm.

    Returns:
        The lines in cutting order, each possibly reversed.
    """
    if not lines:
        return []
    ends = np.array([[*ln.start, *ln.end] for ln in lines], dtype=np.float64)
    left = np.ones(len(lines), dtype=bool)
    out: list[Line] = []
    here = np.array(start, dtype=np.float64)
    for _ in range(len(lines)):
        d_start = np.hypot(ends[:, 0] - here[0], ends[:, 1] - here[1])
        d_end = np.hypot(ends[:, 2] - here[0], ends[:, 3] - here[1])
        d_start[~left] = np.inf
        d_end[~left] = np.inf
        k_start, k_end = int(np.argmin(d_start)), int(np.argmin(d_end))
        if d_end[k_end] < d_start[k_start]:
            line = lines[k_end].reversed()
            left[k_end] = False
        else:
            line = lines[k_start]
            left[k_start] = False
        out.append(line)
        here = np.array(line.end, dtype=np.float64)
    return out
