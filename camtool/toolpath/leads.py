"""Tangent lead-in and lead-out arcs for closed profiles (``--lead-in MM``).

Design notes: docs/internals.md, ``camtool/toolpath/leads.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from camtool.model.shapes import Arc, Point
from camtool.toolpath.cuts import Cut
from camtool.toolpath.split import Track, end_tangent, start_tangent

MAX_HALVINGS = 6
"""A lead radius is halved at most this often (to 1/64 of ``--lead-in``) to fit."""

_SAMPLES = 16  # points per lead arc checked against the waste side
_CHORD_MM = 1e-4  # chord error of the path polygon
_NEAR_MM = 1e-3  # sample points this close to the path count as touching it


@dataclass(frozen=True)
class KeepOff:
    """The material that stays, of every contour of the plan, and how far lead arcs keep off it.

    A lead arc on its own path's waste side can still reach another contour: a hole's lead
    the part's outline around it, a part's lead its neighbour in a nest.

    Attributes:
        material: the material's regions (shapely polygons, mm), as
            :func:`camtool.toolpath.compensate.material` gives them.
        distance: the least distance from the material to a lead arc (the tool centre's
            path), mm: the tool radius less the tolerance.
        tolerance: chord tolerance of the arcs' polylines, mm (> 0).
    """

    material: Any
    distance: float
    tolerance: float
    _tree: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        import shapely

        object.__setattr__(self, "_tree", shapely.STRtree(self.material))

    def clear(self, *arcs: Arc) -> bool:
        """Whether every arc keeps at least :attr:`distance` from every region."""
        import shapely

        lines = shapely.linestrings([a.points(self.tolerance) for a in arcs])
        near = self._tree.query(lines, predicate="dwithin", distance=self.distance)
        return not near.size


def leads_for(cut: Cut, radius: float, keep_off: KeepOff | None = None) -> tuple[Arc, Arc] | None:
    """The lead arcs ``cut`` gets for ``--lead-in radius``, or ``None``.

    A cut gets them when it is a closed profile with a material side, ``radius``
    is > 0 and a lead radius fits on the waste side (:func:`fitted_radius`; the
    arcs are computed once, at that radius).
    """
    if radius <= 0 or cut.kind != "profile" or not cut.path.closed:
        return None
    if cut.material_side is None or not Track.of(cut.path).segments:
        return None
    fitted = fitted_radius(cut, radius, keep_off)
    return _arcs(cut, fitted) if fitted > 0 else None


def fitted_radius(cut: Cut, radius: float, keep_off: KeepOff | None = None) -> float:
    """The largest of ``radius``, ``radius/2``, … whose lead arcs stay on the waste side; 0: none.

    The waste side is the inside of the closed path's polygon when the material
    lies outside it (the right of a counter-clockwise path), else the outside;
    every sampled point of both arcs farther than 1 µm from the path must lie there.
    With ``keep_off``, both arcs must also keep its distance from the plan's material
    (:meth:`KeepOff.clear`).
    """
    import shapely

    polygon = shapely.Polygon(cut.path.points(_CHORD_MM))
    shapely.prepare(polygon)
    material_right = cut.material_side == "right"
    waste_inside = (cut.path.signed_area() > 0) == material_right
    for _ in range(MAX_HALVINGS + 1):
        lead_in, lead_out = _arcs(cut, radius)
        fractions = [k / _SAMPLES for k in range(_SAMPLES)]  # lead-in: all but its end
        points = [lead_in.point_at(f) for f in fractions]
        points += [lead_out.point_at(1.0 - f) for f in fractions]
        xy = shapely.points(points)
        clear = shapely.distance(polygon.exterior, xy) > _NEAR_MM  # off the path itself
        wrong = shapely.contains(polygon, xy) != waste_inside
        if not bool((wrong & clear).any()) and (
            keep_off is None or keep_off.clear(lead_in, lead_out)
        ):
            return radius
        radius /= 2.0
    return 0.0


def lead_arcs(cut: Cut, radius: float) -> tuple[Arc, Arc]:
    """The lead-in and lead-out arcs of a closed profile, at :func:`fitted_radius`.

    Args:
        cut: a closed cut with ``material_side`` set.
        radius: asked lead arc radius, mm (> 0); each arc sweeps 90°.

    Returns:
        ``(lead_in, lead_out)``: ``lead_in`` ends at the path's start, tangent to
        the first segment; ``lead_out`` starts at the path's end (the same point),
        tangent to the last segment. Both curve away from the material side.

    Raises:
        ValueError: the cut has no material side, or no lead radius fits.
    """
    if cut.material_side is None:
        raise ValueError("lead arcs need the cut's material side")
    fitted = fitted_radius(cut, radius)
    if fitted <= 0:
        raise ValueError(f"no lead radius up to {radius:g} mm fits on the waste side")
    return _arcs(cut, fitted)


def _arcs(cut: Cut, radius: float) -> tuple[Arc, Arc]:
    """Both quarter-circle lead arcs of ``radius`` (no fitting)."""
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
