"""Tangent lead-in and lead-out arcs for closed profiles (``--lead-in MM``).

The tool reaches a closed profile along a quarter circle that ends at the path's
start tangent to its first segment, and leaves it along the mirror-image quarter
circle that starts at the path's end tangent to its last segment. Both lie on the
side of the path away from the material (the waste), so the tool never dwells or
plunges against the finished wall.

Conventions: mm, Y up; a cut's ``material_side`` is the side of the travel
direction on which the material stays (:mod:`camtool.toolpath.cuts`). Material on
the right means the waste is on the left: the tool turns left, counter-clockwise,
along both arcs (clockwise for material on the left).
"""

from __future__ import annotations

from camtool.geometry import Arc, Point
from camtool.toolpath.cuts import Cut
from camtool.toolpath.split import Track, end_tangent, start_tangent


def has_leads(cut: Cut, radius: float) -> bool:
    """True when ``cut`` gets lead arcs: a closed profile with a material side, ``radius`` > 0."""
    return (
        radius > 0
        and cut.kind == "profile"
        and cut.path.closed
        and cut.material_side is not None
        and bool(Track.of(cut.path).segments)
    )


def lead_arcs(cut: Cut, radius: float) -> tuple[Arc, Arc]:
    """The lead-in and lead-out arcs of a closed profile.

    Args:
        cut: a closed cut with ``material_side`` set (see :func:`has_leads`).
        radius: lead arc radius, mm (> 0); each arc sweeps 90°.

    Returns:
        ``(lead_in, lead_out)``: ``lead_in`` ends at the path's start, tangent to
        the first segment; ``lead_out`` starts at the path's end (the same point),
        tangent to the last segment. Both curve away from the material side.

    Raises:
        ValueError: the cut has no material side.
    """
    if cut.material_side is None:
        raise ValueError("lead arcs need the cut's material side")
    track = Track.of(cut.path)
    p0, p1 = track.start, track.end
    left = cut.material_side == "right"  # the waste lies left of travel
    tin = start_tangent(track.segments[0])
    tout = end_tangent(track.segments[-1])
    nin, nout = _normal(tin, left), _normal(tout, left)
    cin = (p0[0] + radius * nin[0], p0[1] + radius * nin[1])
    cout = (p1[0] + radius * nout[0], p1[1] + radius * nout[1])
    start = (cin[0] - radius * tin[0], cin[1] - radius * tin[1])
    end = (cout[0] + radius * tout[0], cout[1] + radius * tout[1])
    clockwise = not left
    return Arc(start, p0, cin, clockwise), Arc(p1, end, cout, clockwise)


def _normal(t: Point, left: bool) -> Point:
    """Unit normal of the unit tangent ``t``: to the left of travel or to the right."""
    return (-t[1], t[0]) if left else (t[1], -t[0])
