"""Lead arcs keep the tool off every contour's material, not only their own path's.

A hole's lead arcs lie on its waste side, between the hole and the part's outline; a lead
long enough reaches that outline. The expected distances are geometry: every point the tool
centre passes at cutting depth lies at least one tool radius (less the tolerance) from the
drawing's boundary, measured with shapely on the exact square and a finely sampled circle.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from camtool.model.program import ArcMove, Linear, Rapid
from camtool.model.shapes import Arc, Contour, Drawing, Line
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.plan import plan_drawing

R_TOOL = 1.0
TOL = 0.01


def _square(x0: float, y0: float, x1: float, y1: float) -> Contour:
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return Contour(
        tuple(Line(a, b) for a, b in zip(corners, corners[1:] + corners[:1], strict=True)), True
    )


def _circle(cx: float, cy: float, r: float) -> Contour:
    start = (cx + r, cy)
    return Contour((Arc(start, start, (cx, cy), False),), True)


def _cutting_points(moves: tuple[object, ...]) -> np.ndarray:
    """Points every 0.02 mm along the feed moves that start and end below Z 0."""
    x = y = z = 0.0
    out: list[tuple[float, float]] = []
    for m in moves:
        nz = z if getattr(m, "z", None) is None else float(m.z)  # type: ignore[attr-defined]
        if isinstance(m, Rapid):
            x, y, z = m.x, m.y, nz
            continue
        assert isinstance(m, Linear | ArcMove)
        if z < 0 and nz < 0:
            if isinstance(m, Linear):
                n = max(2, int(math.hypot(m.x - x, m.y - y) / 0.02))
                out += [(x + (m.x - x) * k / n, y + (m.y - y) * k / n) for k in range(n + 1)]
            else:
                arc = Arc((x, y), (m.x, m.y), (m.cx, m.cy), m.clockwise)
                n = max(2, int(arc.length / 0.02))
                out += [arc.point_at(k / n) for k in range(n + 1)]
        x, y, z = m.x, m.y, nz
    return np.array(out)


@pytest.mark.parametrize("lead_in", [2.0, 4.0, 8.0])
@pytest.mark.parametrize("offset", ["inside", "outside"])
def test_a_hole_s_lead_arcs_stay_a_tool_radius_off_the_outline(offset: str, lead_in: float) -> None:
    # a ø3 hole 2 mm from the square's left edge: the hole's path runs 1 mm from that edge
    # ("inside": the tool between hole and edge) and its lead arcs swing toward it
    square, hole = _square(0, 0, 40, 40), _circle(3.5, 20, 1.5)
    options = PlanOptions(
        offset=offset,
        tool_diameter=2 * R_TOOL,
        lead_in=lead_in,
        depth=1.0,
        feed_mm_min=600,
        plunge_feed_mm_min=300,
        tolerance=TOL,
    )
    plan = plan_drawing(Drawing((square, hole)), options)
    points = _cutting_points(plan.program.moves)
    boundary = shapely.MultiLineString(
        [
            [(0, 0), (40, 0), (40, 40), (0, 40), (0, 0)],
            [(3.5 + 1.5 * math.cos(a), 20 + 1.5 * math.sin(a)) for a in np.linspace(0, math.tau)],
        ]
    )
    distance = shapely.distance(shapely.points(points), boundary)
    assert distance.min() >= R_TOOL - TOL - 1e-3
    shortened = [f for f in plan.report.findings if f.kind == "lead-in"]
    if offset == "inside":  # the hole's leads had to shrink, and the user is told
        assert shortened


def test_neighbouring_parts_keep_each_other_s_lead_arcs_off() -> None:
    # two squares 3 mm apart cut outside with a 2 mm tool: 1 mm of waste between the paths,
    # so a 4 mm lead of either reaches into the other part unless it shrinks
    options = PlanOptions(
        offset="outside",
        tool_diameter=2 * R_TOOL,
        lead_in=4.0,
        depth=1.0,
        feed_mm_min=600,
        plunge_feed_mm_min=300,
        tolerance=TOL,
    )
    left, right = _square(0, 0, 10, 10), _square(13, 0, 23, 10)
    plan = plan_drawing(Drawing((left, right)), options)
    points = _cutting_points(plan.program.moves)
    parts = shapely.union_all([shapely.box(0, 0, 10, 10), shapely.box(13, 0, 23, 10)])
    assert shapely.distance(shapely.points(points), parts).min() >= R_TOOL - TOL - 1e-3
