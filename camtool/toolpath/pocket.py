"""Pockets: clear the inside of closed contours, down to their islands.

The material to remove is the even-odd region of the closed contours: a contour at
even nesting depth bounds a pocket, the closed contours directly inside it (depth + 1)
are its islands, and a contour inside an island (depth + 2) starts a new pocket. Each
region is a shapely polygon with holes (arcs as chords within ``tolerance / 4``).

Two styles (``--pocket``):

- ``concentric``: rings at distances ``r, r + s, r + 2s, ...`` inside the region
  (``r`` tool radius, ``s = stepover × diameter``), outermost (the wall pass) first
  and innermost last. The wall ring is the exact OpenCASCADE offset when each boundary
  offsets on its own (:func:`~camtool.toolpath.offset.offset_contour`); the other rings
  are shapely buffers fitted with arcs and lines
  (:func:`~camtool.geometry.arcfit.fit_polyline`). Where a ring splits around islands
  the rings form a tree, cut depth first so each sub-pocket is finished before the next.
- ``zigzag``: the wall ring, then parallel lines at spacing ``s`` and the angle
  ``--pocket-angle`` (:mod:`~camtool.toolpath.pocket_zigzag`).

Consecutive paths are linked by a straight feed move when the tool, moving along it,
stays inside the region (it cuts only material that is removed anyway); elsewhere a new
:class:`~camtool.toolpath.cuts.Cut` starts and the passes stage retracts. Direction:
climb keeps the wall on the right of travel (rings along an outer wall run
counter-clockwise, rings around an island clockwise); conventional is the opposite.
What the tool cannot reach is reported by :mod:`~camtool.toolpath.pocket_uncut`.

Error budget of a fitted ring against the true offset: region chords ``tolerance / 4``,
buffer chords ``tolerance / 4``, arc fit ``tolerance / 2`` and the joining of arcs on one
circle ``tolerance / 4`` (:mod:`~camtool.toolpath.pocket_rings`); in the worst case
``1.25·tolerance``, usually well within ``tolerance``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from shapely import LineString, Polygon, prepared
from shapely import Point as ShapelyPoint
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from camtool.model.errors import ToolpathError, UsageError
from camtool.model.shapes import Contour, Line, Point, Segment, distance
from camtool.model.units import fmt_num
from camtool.toolpath.cuts import Cut, Finding, Stage, where
from camtool.toolpath.offset import offset_contour
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting
from camtool.toolpath.pocket_rings import fit_ring, nearest_on, start_near
from camtool.toolpath.pocket_uncut import polygons, quad_segs, uncut_findings
from camtool.toolpath.pocket_zigzag import order_lines, zigzag_lines

__all__ = ["Region", "pocket", "regions"]

Ring = tuple[tuple[Segment, ...], bool]
"""A closed tool path (segments, start == end) and whether it goes around an island."""

MAX_POCKET_PATHS = 100_000
"""Most rings (concentric) or lines (zigzag) one pocket region may need; a real job
(a 1 m pocket with a 10 µm step-over) stays under it."""
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


def pocket(contours: Sequence[Contour], nest: Nesting, options: PlanOptions) -> Stage:
    """Clear the inside of every pocket region; cut open contours on the line.

    Args:
        contours: chained contours, mm.
        nest: their containment (:func:`~camtool.toolpath.order.nesting`).
        options: ``offset == "pocket"``; the tool, ``stepover``, ``pocket``,
            ``pocket_angle_deg``, ``direction`` and ``tolerance`` are used.

    Returns:
        Cuts of kind ``"pocket"`` (group = the pocket boundary's index; in each
        group the order given is the cutting order) and ``"open"``, and findings:
        ``open-on-line``, ``uncut`` (regions narrower than the tool, with
        location and area mm²), ``tight-corner`` (corners left with the tool
        radius) and ``offset-fallback``.

    Raises:
        ToolpathError: no region can be pocketed at all (no closed contours, or
            every region narrower than the tool).
    """
    cuts: list[Cut] = []
    findings: list[Finding] = []
    for region in regions(contours, nest, options.tolerance):
        region_cuts, found = _pocket_region(region, options)
        cuts.extend(region_cuts)
        findings.extend(found)
    if not cuts:
        raise ToolpathError(_nothing_message(contours, options))
    opened = [i for i, c in enumerate(contours) if not c.closed]
    for i in opened:
        cuts.append(Cut(contours[i], i, kind="open", may_rotate=False))
    if opened:
        first = contours[opened[0]]
        findings.append(
            Finding(
                "open-on-line",
                f"{len(opened)} open contour(s) cut on the line: --offset pocket needs closed "
                f"contours (first: {where(first)})",
                first.start,
            )
        )
    return Stage(tuple(cuts), tuple(findings))


def _nothing_message(contours: Sequence[Contour], options: PlanOptions) -> str:
    if not any(c.closed for c in contours):
        return f"--offset pocket needs closed contours; the drawing has {len(contours)} open one(s)"
    return (
        f"every pocket is narrower than the {options.tool_diameter:g} mm tool; nothing can be "
        "cleared (use a smaller tool)"
    )


def regions(contours: Sequence[Contour], nest: Nesting, tolerance: float) -> list[Region]:
    """The even-odd regions to clear, one per connected piece of each pocket.

    Args:
        contours: contours, mm; open ones are ignored.
        nest: their containment.
        tolerance: arcs become chords within ``tolerance / 4`` mm.
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
        area: BaseGeometry = Polygon(contour.points(tolerance / 4)).buffer(0)
        for island in islands:
            area = area.difference(Polygon(island.points(tolerance / 4)).buffer(0))
        parts = polygons(area)
        for part in parts:
            out.append(Region(i, contour, orient(part), islands, len(parts) == 1))
    return out


def _pocket_region(region: Region, options: PlanOptions) -> tuple[list[Cut], list[Finding]]:
    r, tol = options.radius, options.tolerance
    step = options.stepover * options.tool_diameter
    climb = options.direction != "conventional"
    zigzag = options.pocket == "zigzag"
    _check_path_count(region, step, options)
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


def _check_path_count(region: Region, step: float, options: PlanOptions) -> None:
    """Refuse a pocket needing more than :data:`MAX_POCKET_PATHS` rings or lines, before any.

    Rings: at most half the region's smaller bounding-box side over the step-over;
    zigzag lines: at most its diagonal over the step-over.

    Raises:
        UsageError: the bound exceeds the limit (names --stepover, --tool-diameter).
    """
    x0, y0, x1, y1 = region.area.bounds
    w, h = x1 - x0, y1 - y0
    zigzag = options.pocket == "zigzag"
    span = math.hypot(w, h) if zigzag else max(0.0, min(w, h) / 2 - options.radius)
    count = span / step
    if count <= MAX_POCKET_PATHS:
        return
    what = "zigzag lines" if zigzag else "rings"
    raise UsageError(
        f"{where(region.boundary)}: a {fmt_num(w, 3)} × {fmt_num(h, 3)} mm pocket would need "
        f"about {count:.3g} {what} at a step-over of {step:g} mm (--stepover "
        f"{options.stepover:g} × --tool-diameter {options.tool_diameter:g} mm), more than the "
        f"limit of {MAX_POCKET_PATHS} per pocket; give a larger --stepover or tool"
    )


def _buffer(area: Polygon, amount: float, tol: float) -> list[Polygon]:
    """Pieces of ``area`` shrunk by ``amount`` mm; slivers thinner than ``tol``² dropped."""
    shrunk = area.buffer(-amount, quad_segs=quad_segs(amount, tol))
    return [p for p in polygons(shrunk) if p.area > tol * tol]


def _levels(
    area: Polygon, r: float, step: float, tol: float, limit: int | None
) -> list[list[Polygon]]:
    """Offsets of ``area`` at ``r + k·step`` until empty (at most ``limit`` levels)."""
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
