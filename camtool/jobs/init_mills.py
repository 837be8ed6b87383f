"""``camtool job init``'s end mills: the one that fits a layer's holes, or the gaps between parts.

Design notes: docs/internals.md, ``camtool/jobs/init.py``.
"""

from __future__ import annotations

from collections.abc import Sequence

from camtool.model.shapes import Contour, Point
from camtool.model.units import fmt_point


def why(text: str) -> str:
    """``text`` as a TOML comment after a value: what ``job init`` says of each guess."""
    return f"  # {text}"


END_MILLS_MM = (0.5, 0.8, 1.0, 1.5, 2.0, 2.5, 3.0, 3.175, 4.0, 5.0, 6.0, 6.35, 8.0, 10.0, 12.0)
"""Common end mill diameters, mm (metric and 1/8", 1/4"): the sizes job init proposes."""

FIT_MARGIN = 0.95
"""A proposed end mill is at most this fraction of the narrowest hole's width."""

WIDTH_TOLERANCE_MM = 0.01
"""How closely a hole's width (its largest inscribed circle) is measured, mm."""


def mill_that_fits(
    contours: Sequence[Contour], tool: float, noun: str = "hole"
) -> tuple[float | None, str]:
    """The end mill for a layer of holes (or pockets) and its ``tool =`` line.

    ``noun``: what the comment calls them (``"pocket"`` for a layer of pockets, whose
    clearing needs the same: ``post`` clears nothing narrower than its tool).

    The job's end mill (``tool``, mm) when it fits in every hole; else the largest of
    :data:`END_MILLS_MM` within :data:`FIT_MARGIN` of the narrowest hole's width (the
    diameter of its largest inscribed circle, :func:`~camtool.geometry.area.inscribed_width`),
    said in the line's comment; ``None`` when none fits (the operation is then left
    commented out). ``post`` cuts nothing in a hole narrower than its tool, and stops
    when that is every contour of an operation.
    """
    from camtool.geometry.area import enclosed, inscribed_width

    widths = [
        inscribed_width(enclosed(c.points(WIDTH_TOLERANCE_MM)), WIDTH_TOLERANCE_MM)
        for c in contours
    ]
    narrow = [w for w in widths if w < tool]
    if not narrow:
        return tool, "tool = {end-mill}"
    least = min(narrow)
    if len(widths) == 1:
        said = f"the {noun} is narrower than the {tool:g} mm end mill (about {least:.3g} mm wide)"
    else:
        which = "all" if len(narrow) == len(widths) else f"{len(narrow)} of the"
        said = (
            f"{which} {len(widths)} {noun}s are narrower than the {tool:g} mm end mill (the "
            f"narrowest about {least:.3g} mm wide)"
        )
    fits = [d for d in END_MILLS_MM if d <= FIT_MARGIN * least]
    if not fits:
        return None, "tool = {end-mill}" + why(
            f"{said}: no common end mill fits; give this operation a tool that does, then "
            "uncomment it"
        )
    mill = fits[-1]
    them = "it" if len(widths) == 1 else "them"
    return mill, f"tool = {{end-mill {mill:g}}}" + why(f"{said}: a {mill:g} mm one cuts {them}")


def mill_between(
    parts: Sequence[Contour], others: Sequence[Contour], tool: float
) -> tuple[float | None, str]:
    """The end mill an outside profile of ``parts`` cuts with, and its ``tool =`` line.

    Each part's toolpath lies the tool's radius outside it, so its cut is the tool's
    diameter wide: a neighbour closer than that (another of ``parts`` or of ``others``,
    the drawing's other outermost closed contours, mm) loses material to it (boxes.py
    spaces its parts half a stock thickness apart, for a laser's kerf). The job's end mill
    (``tool``, mm) when no two are closer than it, or when they touch or overlap (nothing
    fits there: ``post`` names where the tool cuts into a part); else the largest of
    :data:`END_MILLS_MM` within :data:`FIT_MARGIN` of the narrowest gap, said in the
    comment with where it is, or the job's when none fits (the comment says so).
    """
    gap = _narrowest_gap(parts, others, tool)
    if gap is None:
        return tool, "tool = {end-mill}"
    width, at = gap
    said = (
        f"parts {width:.3g} mm apart at {fmt_point(at)} mm, closer than the {tool:g} mm end mill, "
        "which would cut into the neighbour"
    )
    fits = [d for d in END_MILLS_MM if d <= FIT_MARGIN * width]
    if not fits:
        return tool, "tool = {end-mill}" + why(
            f"{said}: no common end mill fits; move the parts apart (post names each place)"
        )
    mill = fits[-1]
    return mill, f"tool = {{end-mill {mill:g}}}" + why(
        f"{said}: a {mill:g} mm one fits; or move them apart and keep the {tool:g} mm one"
    )


def _narrowest_gap(
    parts: Sequence[Contour], others: Sequence[Contour], tool: float
) -> tuple[float, Point] | None:
    """The smallest gap under ``tool`` between one of ``parts`` and another contour, mm.

    Gaps of zero (touching, overlapping) are not counted. Returns the gap and the middle
    of the shortest line across it (shapely's ``distance`` and ``shortest_line`` between
    the areas the contours enclose, :func:`~camtool.geometry.area.enclosed`), or ``None``.
    """
    import shapely

    from camtool.geometry.area import enclosed

    mine = {id(c) for c in parts}
    every = [*parts, *(c for c in others if id(c) not in mine)]
    areas = [enclosed(c.points(WIDTH_TOLERANCE_MM)) for c in every]
    tree = shapely.STRtree(areas)
    best: tuple[float, Point] | None = None
    for i in range(len(parts)):
        for j in tree.query(areas[i], predicate="dwithin", distance=tool):
            j = int(j)
            if j == i or (j < len(parts) and j < i):
                continue
            d = float(shapely.distance(areas[i], areas[j]))
            if 0.0 < d < tool and (best is None or d < best[0]):
                line = shapely.shortest_line(areas[i], areas[j])
                (x0, y0), (x1, y1) = line.coords
                best = (d, ((x0 + x1) / 2.0, (y0 + y1) / 2.0))
    return best
