"""Tool compensation: closed contours offset to the tool's side, oriented for climb or conventional.

Material is the even-odd region of the closed contours (:class:`~camtool.toolpath.order.Nesting`):
an outer boundary (even depth) has material inside, a hole (odd depth) outside. With
``--offset outside`` the tool runs on the side without material: outer boundaries grow by the
tool radius ``r`` and holes shrink; ``--offset inside`` is the opposite. The offsets keep arcs
exact (:mod:`~camtool.toolpath.offset`: OpenCASCADE, checked against shapely, with a fitted
buffer as fallback).

Direction (a clockwise M03 spindle): climb milling keeps the material that stays on the RIGHT
of travel, so with ``outside`` an outer boundary's path runs clockwise and a hole's
counter-clockwise; conventional milling runs the other way. ``--offset on`` keeps the drawn
direction unless ``--direction`` is given, which orients as for ``outside``.

What the stage reports (:class:`~camtool.toolpath.cuts.Finding`): open contours cut on the line
when a side was asked, offsets that needed the fallback, contours offset away entirely (with
their location and width), inside corners tighter than the tool radius (the part keeps a fillet
of radius ``r`` there), and places where the tool's swept area cuts into material (neighbouring
offsets colliding).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment
from camtool.toolpath.cuts import Cut, Finding, Stage, where
from camtool.toolpath.gouge import gouges
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting

__all__ = ["compensate", "tight_corners", "tool_inside"]

CORNER_TURN_DEG = 1.0
"""A joint turning more than this toward the tool is a corner the tool cannot follow."""


@dataclass(frozen=True)
class _Side:
    """Where the tool runs relative to one closed contour."""

    inside: bool  # the tool runs inside the contour's enclosed area
    climb: bool


def tool_inside(depth: int, offset: str) -> bool:
    """True when the tool runs inside a closed contour at nesting ``depth``.

    Outer boundaries (even depth) have material inside, holes (odd depth) outside;
    ``outside`` (and ``on`` with a direction) puts the tool on the side without
    material, ``inside`` on the side with it.
    """
    hole = depth % 2 == 1
    return hole != (offset == "inside")


def compensate(contours: Sequence[Contour], nest: Nesting, options: PlanOptions) -> Stage:
    """Turn contours into cuts: compensated for the tool (``outside``/``inside``) or on the line.

    Cuts come in contour order; ``group`` is the contour's index. Compensated
    profiles have ``may_reverse=False``, ``may_rotate=True``, ``material_side``
    ``"right"`` for climb (``"left"`` conventional) and ``outside_profile`` for
    outer boundaries cut ``outside``. A contour whose offset splits gives one
    cut per piece. Open contours give ``kind="open"`` cuts on the line, in their
    drawn direction (``may_reverse`` only with ``options.reverse_open``).

    Args:
        contours: chained, closed-where-possible contours, mm.
        nest: their nesting (:func:`~camtool.toolpath.order.nesting`).
        options: ``offset`` (on/outside/inside), ``radius``, ``direction``,
            ``tolerance``.

    Returns:
        The cuts and the findings (``open-on-line``, ``offset-fallback``,
        ``offset-vanished``, ``tight-corner``, ``gouge``).

    Raises:
        ToolpathError: every closed contour is offset away and nothing is left
            to cut (the message lists them); ``offset`` is ``pocket``.
    """
    if options.offset not in ("on", "outside", "inside"):
        raise ToolpathError(f"--offset {options.offset} is planned by the pocket stage")
    cuts: list[Cut] = []
    findings: list[Finding] = []
    vanished: list[Finding] = []
    open_count = 0
    for i, contour in enumerate(contours):
        if not contour.closed:
            open_count += 1
            # drawn direction unless --reverse-open: a drawn arc is a G02 or G03 as drawn
            cuts.append(Cut(contour, i, "open", may_reverse=options.reverse_open, may_rotate=False))
        elif options.offset == "on":
            cuts.append(_on_line(contour, i, nest, options))
        else:
            made, found = _compensated(contour, i, nest, options)
            cuts.extend(made)
            findings.extend(found)
            vanished.extend(f for f in found if f.kind == "offset-vanished")
    if not cuts and vanished:
        raise ToolpathError("nothing left to cut: " + "; ".join(f.message for f in vanished))
    if open_count and options.offset != "on":
        findings.append(
            Finding(
                "open-on-line",
                f"{open_count} open contour(s) cut on the line: --offset {options.offset} needs "
                "closed contours",
                value=float(open_count),
            )
        )
    if options.offset != "on":
        findings.extend(gouges(contours, nest, cuts, options))
    return Stage(tuple(cuts), tuple(findings))


def _on_line(contour: Contour, index: int, nest: Nesting, options: PlanOptions) -> Cut:
    """A closed contour cut on the line: drawn direction, or oriented when asked."""
    if options.direction is None:
        return Cut(contour, index, "profile", may_reverse=True, may_rotate=True)
    side = _Side(tool_inside(nest.depth(index), "on"), options.direction == "climb")
    return Cut(
        _oriented(contour, side),
        index,
        "profile",
        may_reverse=False,
        may_rotate=True,
        material_side="right" if side.climb else "left",
    )


def _compensated(
    contour: Contour, index: int, nest: Nesting, options: PlanOptions
) -> tuple[list[Cut], list[Finding]]:
    """The cuts of one closed contour offset to the tool's side, and what was found."""
    from camtool.toolpath.offset import offset_checked

    depth = nest.depth(index)
    side = _Side(tool_inside(depth, options.offset), options.direction != "conventional")
    drawn = _oriented(contour, side)
    r = options.radius
    result = offset_checked(drawn, -r if side.inside else r, options.tolerance)
    findings: list[Finding] = []
    if not result.pieces:
        return [], [_vanished(contour, options)]
    if result.fallback is not None:
        findings.append(_fallback(contour, result.fallback, options.tolerance))
    corners = tight_corners(drawn, side.inside, r, options.tolerance)
    if corners:
        findings.append(_tight(contour, corners, r))
    outside_profile = depth % 2 == 0 and options.offset == "outside"
    cuts = [
        Cut(
            piece,
            index,
            "profile",
            may_reverse=False,
            may_rotate=True,
            outside_profile=outside_profile,
            material_side="right" if side.climb else "left",
        )
        for piece in result.pieces
    ]
    return cuts, findings


def _oriented(contour: Contour, side: _Side) -> Contour:
    """The contour traversed so the tool is on the left (climb) or right (conventional).

    Climb keeps the material on the right, so the tool is on the left: a tool
    inside the contour means counter-clockwise travel.
    """
    want_ccw = side.inside == side.climb
    return contour if (contour.signed_area() > 0) == want_ccw else contour.reversed()


def tight_corners(contour: Contour, inside: bool, radius: float, tolerance: float) -> list[Point]:
    """Corners of a closed contour that a tool of ``radius`` on one side cannot follow.

    A joint is tight when the contour turns toward the tool by more than
    :data:`CORNER_TURN_DEG` (concave as seen from the tool: the corners of a
    rectangular hole with the tool inside it, the inner corner of an L cut
    outside); an arc is tight when it curves toward the tool with a radius
    below ``radius − tolerance``. The tool leaves a fillet of ``radius`` there.

    Args:
        contour: a closed contour as drawn, mm (either orientation).
        inside: the tool runs inside the enclosed area.
        radius: tool radius, mm.
        tolerance: radius slack, mm.

    Returns:
        The corner points (arc midpoints for tight arcs), mm, in contour order.
    """
    ccw = contour.signed_area() > 0
    tool_left = ccw == inside
    segs = contour.segments
    out: list[Point] = []
    for k, seg in enumerate(segs):
        prev = segs[k - 1]
        turn = _turn(_tangent(prev, at_end=True), _tangent(seg, at_end=False))
        if abs(turn) > math.radians(CORNER_TURN_DEG) and (turn > 0) == tool_left:
            out.append(seg.start)
        if (
            isinstance(seg, Arc)
            and seg.radius < radius - tolerance
            and (not seg.clockwise) == tool_left
        ):
            out.append(seg.point_at(0.5))
    return out


def _tangent(seg: Segment, *, at_end: bool) -> Point:
    """Unit direction of travel at the start or end of a segment."""
    if isinstance(seg, Line):
        dx, dy = seg.end[0] - seg.start[0], seg.end[1] - seg.start[1]
    else:
        p = seg.end if at_end else seg.start
        rx, ry = p[0] - seg.centre[0], p[1] - seg.centre[1]
        dx, dy = (ry, -rx) if seg.clockwise else (-ry, rx)
    n = math.hypot(dx, dy) or 1.0
    return (dx / n, dy / n)


def _turn(a: Point, b: Point) -> float:
    """Signed turn from direction ``a`` to ``b``, radians, > 0 to the left."""
    return math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])


def _vanished(contour: Contour, options: PlanOptions) -> Finding:
    """An ``offset-vanished`` finding: where the contour is and how wide it is."""
    from shapely import Polygon, maximum_inscribed_circle

    tol = options.tolerance / 4
    poly = Polygon(contour.points(tol)).buffer(0)
    centre = poly.centroid
    width = 2.0 * maximum_inscribed_circle(poly, tol).length  # twice the largest inradius
    x, y = float(centre.x), float(centre.y)
    d = options.tool_diameter
    return Finding(
        "offset-vanished",
        f"{where(contour)}: the region around ({x:.4f}, {y:.4f}) mm is about {width:.3g} mm "
        f"wide, narrower than the {d:g} mm tool: nothing can be cut there; use a smaller tool",
        (x, y),
        float(width),
    )


def _fallback(contour: Contour, reason: str, tolerance: float) -> Finding:
    return Finding(
        "offset-fallback",
        f"{where(contour)}: OpenCASCADE could not offset it ({reason}); used shapely's buffer "
        f"fitted with arcs within {tolerance:g} mm",
        contour.start,
    )


def _tight(contour: Contour, corners: list[Point], radius: float) -> Finding:
    x, y = corners[0]
    n = len(corners)
    return Finding(
        "tight-corner",
        f"{where(contour)}: {n} inside corner{'s' if n > 1 else ''} tighter than the "
        f"{radius:g} mm tool radius (first at ({x:.4f}, {y:.4f}) mm); the part keeps a "
        f"{radius:g} mm radius there",
        (x, y),
        float(n),
    )
