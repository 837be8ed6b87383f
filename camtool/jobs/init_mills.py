"""``camtool job init``'s end mills: the one that fits a layer's holes, or the gaps between parts.

Design notes: docs/internals.md, ``camtool/jobs/init.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from typing import Any, NamedTuple

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


class MillFit(NamedTuple):
    """What :func:`mill_that_fits` answers.

    ``diameter``: the end mill, mm (``None``: no common one fits); ``line``: its ``tool =``
    line; ``unfit``: when none fits, why (which contours, how narrow), else ``""``.
    """

    diameter: float | None
    line: str
    unfit: str = ""


def mill_that_fits(contours: Sequence[Contour], tool: float, noun: str = "hole") -> MillFit:
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
        return MillFit(tool, "tool = {end-mill}")
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
        advice = "no common end mill fits; give this operation a tool that does, then uncomment it"
        return MillFit(None, "tool = {end-mill}" + why(f"{said}: {advice}"), said)
    mill = fits[-1]
    them = "it" if len(widths) == 1 else "them"
    return MillFit(
        mill, f"tool = {{end-mill {mill:g}}}" + why(f"{said}: a {mill:g} mm one cuts {them}")
    )


class Parts:
    """The drawing's parts (its outermost closed contours) and the areas they enclose, mm.

    The areas (:func:`~camtool.geometry.area.enclosed`) and their shapely ``STRtree`` are
    made once, when :func:`mill_between` first asks, and shared by every operation.
    """

    def __init__(self, contours: Sequence[Contour]) -> None:
        self.contours = tuple(contours)
        self._index = {id(c): i for i, c in enumerate(self.contours)}

    @cached_property
    def areas(self) -> tuple[Any, ...]:
        """Each part's area (a shapely polygon or multipolygon), in :attr:`contours`' order."""
        from camtool.geometry.area import enclosed

        return tuple(enclosed(c.points(WIDTH_TOLERANCE_MM)) for c in self.contours)

    @cached_property
    def tree(self) -> Any:
        """A shapely ``STRtree`` of :attr:`areas`."""
        import shapely

        return shapely.STRtree(self.areas)

    def index(self, contour: Contour) -> int | None:
        """``contour``'s place among the parts, or ``None`` when it is none of them."""
        return self._index.get(id(contour))


def mill_between(mine: Sequence[Contour], parts: Parts, tool: float) -> tuple[float, str]:
    """The end mill an outside profile of ``mine`` cuts with, and its ``tool =`` line.

    Each part's toolpath lies the tool's radius outside it, so its cut is the tool's
    diameter wide: another of ``parts`` closer than that loses material to it (boxes.py
    spaces its parts half a stock thickness apart, for a laser's kerf). The job's end mill
    (``tool``, mm) when no two are closer than it, or when they touch or overlap (nothing
    fits there: ``post`` names where the tool cuts into a part); else the largest of
    :data:`END_MILLS_MM` within :data:`FIT_MARGIN` of the narrowest gap, said in the
    comment with where it is, or the job's when none fits (the comment says so).
    """
    gap = _narrowest_gap(mine, parts, tool)
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
    mine: Sequence[Contour], parts: Parts, tool: float
) -> tuple[float, Point] | None:
    """The smallest gap under ``tool`` between one of ``mine`` and another part, mm.

    Gaps of zero (touching, overlapping) are not counted. Returns the gap and the middle
    of the shortest line across it (shapely's ``distance`` and ``shortest_line`` between
    the parts' areas), or ``None``.
    """
    import shapely

    best: tuple[float, Point] | None = None
    for contour in mine:
        i = parts.index(contour)
        if i is None:
            continue
        here = parts.areas[i]
        for j in parts.tree.query(here, predicate="dwithin", distance=tool).tolist():
            d = float(shapely.distance(here, parts.areas[j]))
            if j != i and 0.0 < d < tool and (best is None or d < best[0]):
                (x0, y0), (x1, y1) = shapely.shortest_line(here, parts.areas[j]).coords
                best = (d, ((x0 + x1) / 2.0, (y0 + y1) / 2.0))
    return best
