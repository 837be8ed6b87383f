"""Gouge check: does the tool's swept area cut into the material that must stay?

Each compensated path sweeps a band of the tool radius on both sides
(``LineString(path).buffer(r)``). A correct offset only touches the material;
where offsets of neighbouring contours collide (two parts closer than the tool,
a wall between two holes thinner than the tool with ``--offset inside``) the band
overlaps the material. Material is the even-odd region of the closed contours for
``outside`` and its complement for ``inside`` (:mod:`~camtool.toolpath.compensate`).

Cost: the material is split into one polygon per contour (an outer boundary minus
its holes), indexed by an STRtree; each path is intersected only with the
polygons its band reaches. Polylines use chords within ``tolerance/4``, so a
correct offset overlaps by slivers narrower than ``tolerance/2``; an overlap is
reported when its mean width (2·area / perimeter) exceeds ``tolerance``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from camtool.model.shapes import Contour
from camtool.toolpath.cuts import Cut, Finding, where
from camtool.toolpath.offset import quad_segs
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting

__all__ = ["gouges", "material"]


def material(
    contours: Sequence[Contour], nest: Nesting, offset: str, tolerance: float
) -> list[Any]:
    """The material that must stay, as shapely polygons (mm), one per region.

    For ``outside``: each outer boundary (even depth) minus the holes directly
    inside it. For ``inside``: each hole minus the islands directly inside it,
    and the area around the outermost contours (a box 10 mm larger).

    Args:
        contours: contours, mm; open ones are ignored.
        nest: their nesting.
        offset: ``outside`` or ``inside``.
        tolerance: chord tolerance of the polygons, mm.
    """
    from shapely import Polygon, box, union_all

    closed = [i for i, c in enumerate(contours) if c.closed]
    polys = {i: Polygon(contours[i].points(tolerance)).buffer(0) for i in closed}
    keep = 0 if offset == "outside" else 1
    regions = []
    for i in closed:
        if nest.depth(i) % 2 != keep:
            continue
        kids = [j for j in closed if i in nest.parents[j] and nest.depth(j) == nest.depth(i) + 1]
        regions.append(polys[i].difference(union_all([polys[j] for j in kids])))
    if offset == "inside" and closed:
        top = union_all([polys[i] for i in closed if nest.depth(i) == 0])
        x0, y0, x1, y1 = top.bounds
        regions.append(box(x0 - 10, y0 - 10, x1 + 10, y1 + 10).difference(top))
    return [r for r in regions if not r.is_empty]


def gouges(
    contours: Sequence[Contour], nest: Nesting, cuts: Sequence[Cut], options: PlanOptions
) -> list[Finding]:
    """``gouge`` findings where a compensated cut's swept area overlaps the material.

    Args:
        contours: the contours the cuts come from (``cut.group`` indexes them), mm.
        nest: their nesting.
        cuts: the cuts; only closed profiles are checked (open contours are cut
            on the line on purpose).
        options: ``offset`` (outside/inside), ``radius``, ``tolerance``.

    Returns:
        One finding per overlapping region and cut: ``at`` its centroid, ``value``
        its area in mm².
    """
    from shapely import LineString, STRtree, intersection

    tol = options.tolerance / 4
    regions = material(contours, nest, options.offset, tol)
    if not regions or options.radius <= 0:
        return []
    tree = STRtree(regions)
    segs = quad_segs(options.radius, tol)
    out: list[Finding] = []
    for cut in cuts:
        if cut.kind != "profile":
            continue
        swept = LineString(cut.path.points(tol)).buffer(options.radius, quad_segs=segs)
        for k in tree.query(swept, predicate="intersects"):
            overlap = intersection(swept, regions[k])
            for part in getattr(overlap, "geoms", [overlap]):
                if (
                    part.geom_type == "Polygon"
                    and 2.0 * part.area > options.tolerance * part.length
                ):
                    out.append(_finding(contours[cut.group], part, options))
    return out


def _finding(contour: Contour, part: Any, options: PlanOptions) -> Finding:
    c = part.centroid
    x, y, area = float(c.x), float(c.y), float(part.area)
    return Finding(
        "gouge",
        f"{where(contour)}: the {options.tool_diameter:g} mm tool cuts into the part around "
        f"({x:.4f}, {y:.4f}) mm ({area:.3g} mm²): neighbouring contours are closer than the "
        "tool; use a smaller tool or move them apart",
        (x, y),
        area,
    )
