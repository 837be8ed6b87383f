"""Property tests: offsets of random simple polygons lie exactly the tool radius away.

The issue's property "the ``outside`` offset contains the original by exactly the tool radius,
within tolerance" is checked as what defines an exact offset: every point of the tool path is
at distance r (± tolerance) from the drawn polygon, the path encloses the polygon, and it runs
along the boundary of the polygon grown by r (shapely's buffer: nothing is missing). The
symmetric Hausdorff distance between path and polygon is not r in general: at a concave
vertex of the polygon the path keeps a sharp corner r/sin(β/2) away (β the wedge angle).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Contour
from camtool.toolpath.compensate import compensate
from camtool.toolpath.cuts import Stage
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting
from tests.shapes import segment_samples
from tests.toolpath.contours import polygon

TOL = 0.001


@st.composite
def star_polygons(draw: st.DrawFn) -> Contour:
    """Star-shaped simple polygons: 3–12 vertices at sorted angles, scaled 5–50 mm."""
    n = draw(st.integers(3, 12))
    unit = st.floats(0.3, 1.0)
    weights = np.array(draw(st.lists(unit, min_size=n, max_size=n)))
    radii = draw(st.lists(unit, min_size=n, max_size=n))
    scale = draw(st.floats(5.0, 50.0))
    turn = draw(st.floats(0.0, 2 * math.pi))
    angles = turn + 2 * math.pi * np.cumsum(weights) / weights.sum()
    pts = [
        (scale * r * math.cos(a), scale * r * math.sin(a))
        for r, a in zip(radii, angles, strict=True)
    ]
    return polygon(pts)


def _stage(contour: Contour, offset: str, r: float) -> Stage:
    options = PlanOptions(offset=offset, tool_diameter=2 * r, feed_mm_min=100.0, tolerance=TOL)
    return compensate([contour], nesting([contour]), options)


def _path_points(stage: Stage) -> np.ndarray:
    return np.vstack([segment_samples(c.path.segments, 32) for c in stage.cuts])


@settings(max_examples=50, deadline=None)
@given(star_polygons(), st.floats(0.05, 2.0))
def test_outside_offset_encloses_the_polygon_exactly_r_away(contour: Contour, r: float) -> None:
    drawn = shapely.Polygon(contour.points(TOL))
    stage = _stage(contour, "outside", r)
    assert stage.cuts
    # every point of the path is r from the polygon (directed Hausdorff distance = r)
    dist = shapely.distance(shapely.points(_path_points(stage)), drawn)
    assert np.all(np.abs(dist - r) <= TOL)
    # the path encloses the polygon
    outer = max((shapely.Polygon(c.path.points(TOL / 4)) for c in stage.cuts), key=lambda p: p.area)
    assert outer.buffer(TOL).contains(drawn)
    # and follows the whole boundary of the polygon grown by r (within tolerance + chords)
    grown = drawn.buffer(r, quad_segs=256).exterior
    lines = shapely.MultiLineString([c.path.points(TOL / 4) for c in stage.cuts])
    assert shapely.hausdorff_distance(grown, lines) <= 1.5 * TOL


@settings(max_examples=50, deadline=None)
@given(star_polygons(), st.floats(0.05, 2.0))
def test_inside_offset_stays_r_inside_the_polygon(contour: Contour, r: float) -> None:
    drawn = shapely.Polygon(contour.points(TOL))
    try:
        stage = _stage(contour, "inside", r)
    except ToolpathError as exc:  # everything vanished: only when nothing is wider than the tool
        assert shapely.maximum_inscribed_circle(drawn, TOL).length <= r + TOL, exc
        return
    pts = shapely.points(_path_points(stage))
    assert np.all(shapely.contains(drawn, pts))
    dist = shapely.distance(pts, drawn.exterior)
    assert np.all(np.abs(dist - r) <= TOL)
