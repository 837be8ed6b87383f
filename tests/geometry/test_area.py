"""The area a closed contour encloses when it crosses itself: both lobes of a bow-tie.

Before, every stage took that area as shapely's ``buffer(0)`` of the contour's polygon,
which keeps only the loops turning the way of the first one GEOS meets: a bow-tie drawn as
one closed polyline lost a lobe, and ``--offset pocket`` cleared half of it, the outside
offset went around half of it, with exit 0 (the plan said "the pocket clears the whole
area it encloses"). Expected values are from the geometry (triangle areas, winding
numbers counted by hand), not from camtool.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from shapely import Point as ShapelyPoint
from shapely import Polygon

from camtool.geometry.area import NODING_GRID_MM, enclosed, winding
from camtool.geometry.chain import chain
from camtool.importers.dxf import read_dxf
from camtool.jobs.pipeline import post_drawing
from camtool.model.program import ArcMove, Linear
from camtool.model.shapes import Contour, Drawing, Line, Point
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting

BOWTIE = [(0.0, 0.0), (40.0, 30.0), (40.0, 0.0), (0.0, 30.0)]
"""Crosses itself at (20, 15): lobes (0,0) (20,15) (0,30) and (40,0) (20,15) (40,30), each
½ · 30 · 20 = 300 mm², the left one anticlockwise, the right one clockwise."""


def closed(points: list[Point]) -> Contour:
    pairs = zip(points, [*points[1:], points[0]], strict=True)
    return Contour(tuple(Line(a, b) for a, b in pairs), True, source="LWPOLYLINE #1")


def ring(points: list[Point]) -> np.ndarray:
    return np.array([*points, points[0]], dtype=float)


def test_winding_counts_turns_around_a_point() -> None:
    square = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
    assert winding(ring(square), (5.0, 5.0)) == 1
    assert winding(ring(square[::-1]), (5.0, 5.0)) == -1
    assert winding(ring(square), (15.0, 5.0)) == 0
    twice = ring(square + square)  # around it twice
    assert winding(twice, (5.0, 5.0)) == 2
    assert winding(ring(BOWTIE), (5.0, 15.0)) == 1  # (0,0) (20,15) (0,30): anticlockwise
    assert winding(ring(BOWTIE), (35.0, 15.0)) == -1


def test_a_bow_tie_encloses_both_lobes() -> None:
    area = enclosed(BOWTIE)
    assert area.area == pytest.approx(600.0)
    assert area.contains(ShapelyPoint(5.0, 15.0)) and area.contains(ShapelyPoint(35.0, 15.0))
    assert Polygon(BOWTIE).buffer(0).area == pytest.approx(300.0)  # the repair it replaces


def test_a_star_drawn_as_one_line_encloses_its_centre() -> None:
    # a pentagram: its centre is wound around twice (nonzero: inside), its points once
    star = [
        (
            10 * math.cos(math.pi / 2 + k * 4 * math.pi / 5),
            10 * math.sin(math.pi / 2 + k * 4 * math.pi / 5),
        )
        for k in range(5)
    ]
    area = enclosed(star)
    assert winding(ring(star), (0.0, 0.0)) in (2, -2)
    assert area.contains(ShapelyPoint(0.0, 0.0))
    assert area.contains(ShapelyPoint(0.0, 9.0))  # in the top point


def test_no_area_and_plain_polygons() -> None:
    assert enclosed([(0.0, 0.0), (10.0, 0.0), (0.0, 0.0), (10.0, 0.0)]).is_empty
    square = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
    assert enclosed(square).equals_exact(Polygon(square).buffer(0), 0.0)
    # forward round the square, then back round it: wound once each way, no area
    there_and_back = [*square, (0.0, 0.0), (0.0, 10.0), (10.0, 10.0), (10.0, 0.0)]
    assert enclosed(there_and_back).area == pytest.approx(0.0)


def cut_points(job: object) -> list[Point]:
    program = job.program  # type: ignore[attr-defined]
    return [(m.x, m.y) for m in program.moves if isinstance(m, Linear | ArcMove)]


def test_a_bow_tie_pocket_clears_both_lobes() -> None:
    # 3 mm tool: each lobe's inradius is 300 / ((30 + 25 + 25) / 2) = 7.5 mm, room for rings
    job = post_drawing(
        Drawing((closed(BOWTIE),)),
        load_target("grbl"),
        PlanOptions(offset="pocket", tool_diameter=3.0),
    )
    xs = [x for x, _ in cut_points(job)]
    assert min(xs) < 5.0 and max(xs) > 35.0  # before: the right lobe only (x ≥ 20)
    assert job.plan is not None
    assert any(f.kind == "self-crossing" for f in job.plan.findings)


def test_a_bow_tie_outside_offset_goes_around_both_lobes() -> None:
    r = 1.5
    job = post_drawing(
        Drawing((closed(BOWTIE),)),
        load_target("grbl"),
        PlanOptions(offset="outside", tool_diameter=2 * r),
    )
    path = Polygon(cut_points(job))  # its arcs as chords: inside the path itself
    for corner in BOWTIE:  # every corner of the drawing inside it (before: the right lobe's)
        assert path.contains(ShapelyPoint(corner))
    # the straight sides are the drawing's offset by r: x = -r and x = 40 + r
    xs = [x for x, _ in cut_points(job)]
    assert min(xs) == pytest.approx(-r) and max(xs) == pytest.approx(40 + r)


def test_an_island_in_either_lobe_nests_in_the_bow_tie() -> None:
    island = [(3.0, 13.0), (5.0, 13.0), (5.0, 17.0), (3.0, 17.0)]  # in the left lobe
    nest = nesting([closed(BOWTIE), closed(island)])
    assert nest.parents[1] == (0,)


GUNN = (
    Path(os.environ.get("CAMTOOL_CORPUS_DIR", Path(__file__).resolve().parents[2] / ".corpus"))
    / "pkg/librecad-data/usr/share/librecad/library/elektro/diode-iso/Diode-Gunn.dxf"
)
"""LibreCAD's Gunn diode symbol (Debian's librecad-data): its body is one chain of six LINEs,
two triangles tip to tip at (0, 20), (0,20) (-5,10) (5,10) anticlockwise and (0,20) (-5,30)
(5,30) clockwise, 50 mm² each."""


def test_a_real_symbol_of_two_triangles_tip_to_tip_is_pocketed_whole() -> None:
    if not GUNN.exists():
        pytest.skip(f"no {GUNN}: run `make corpus`")
    drawing = read_dxf(GUNN)
    (body,) = [c for c in chain(drawing.contours, 0.01) if c.closed]
    assert enclosed(body.points(0.01)).area == pytest.approx(100.0)
    job = post_drawing(
        drawing, load_target("grbl"), PlanOptions(offset="pocket", tool_diameter=1.0)
    )
    ys = [y for _, y in cut_points(job)]
    assert min(ys) < 14.0 and max(ys) > 26.0  # before: one triangle only


RETRACED_TIP = [
    (130.00136529105552, 20.93346321190394),
    (130.00034190242886, 20.941703473916743),
    (130.0, 20.94999999999999),
    (130.00038053019082, 20.94128442572522),
    (130.00038053019082, 20.941284425725225),
    (130.0, 20.94999999999999),
]
"""The end of a 0.1 mm corner arc drawn there and back, as boxes.py (its PaperBox example)
draws a part's outline: GEOS's noder does not converge on it ("Iterated noding failed to
converge"), which stopped ``camtool post`` with an internal error."""


def test_a_corner_arc_drawn_there_and_back_is_noded_and_its_outline_enclosed() -> None:
    import shapely

    outline = [*RETRACED_TIP, (130.0, 21.0), (131.0, 21.0), (131.0, 20.0), (130.0, 20.0)]
    with pytest.raises(shapely.errors.GEOSException):  # what the fallback is for
        shapely.node(shapely.LineString([*outline, outline[0]]))
    # the tip's way back encloses no area: the outline is the polygon without it
    simple = Polygon([*RETRACED_TIP[:3], *outline[6:]])
    assert simple.is_valid
    area = enclosed(outline)
    # snap-rounding moves each vertex by at most half a diagonal of the grid
    slack = simple.length * NODING_GRID_MM
    assert area.area == pytest.approx(simple.area, abs=slack)
    assert area.symmetric_difference(simple).area < slack
