"""Pockets against analytic expectations (issue 4: "pocket area covered vs tool path",
"an island is never cut into (shapely check on the swept tool area)").

No thesis in reference/ pockets anything; every number here is worked out from the
geometry in the test itself (ring distances r + k·s, corner fillets r² − πr²/4).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely import LineString, Polygon, union_all
from shapely import Point as ShapelyPoint
from shapely.geometry.base import BaseGeometry

from camtool.model.errors import ToolpathError
from camtool.model.progress import Step
from camtool.model.shapes import Arc, Contour, Line, Segment
from camtool.toolpath.cuts import Cut, Stage
from camtool.toolpath.offset import offset_contour
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting
from camtool.toolpath.pocket import pocket
from tests.toolpath.contours import circle, polygon, rect

TOL = 0.001


def _plan(contours: Sequence[Contour], tool: float = 2.0, **kw: object) -> Stage:
    options = PlanOptions(
        offset="pocket", tool_diameter=tool, feed_mm_min=100.0, tolerance=TOL, **kw
    )  # type: ignore[arg-type]
    return pocket(contours, nesting(contours), options)


def _shape(contour: Contour) -> Polygon:
    return Polygon(contour.points(TOL / 4))


def _swept(cuts: Sequence[Cut], r: float) -> BaseGeometry:
    """The tool's swept area, computed here independently of the module."""
    return union_all([LineString(c.path.points(TOL / 4)).buffer(r, quad_segs=64) for c in cuts])


def _loops(path: Contour) -> tuple[list[list[Segment]], list[Line]]:
    """Split a linked concentric path into its closed rings and the links between them."""
    rings: list[list[Segment]] = []
    links: list[Line] = []
    current: list[Segment] = []
    for seg in path.segments:
        if not current and rings and isinstance(seg, Line) and len(links) < len(rings):
            links.append(seg)
            continue
        current.append(seg)
        if math.dist(seg.end, current[0].start) < 1e-9:
            rings.append(current)
            current = []
    assert not current, "the path ends inside a ring"
    return rings, links


def _signed_area(segs: Sequence[Segment]) -> float:
    return Contour(tuple(segs), True).signed_area()


FILLET = 1.0 - math.pi / 4  # r² − πr²/4 for r = 1: what a round tool leaves in a square corner


def test_rectangle_rings_distances_and_one_cut() -> None:
    # 20 × 10, 2 mm tool (r = 1), stepover 0.4 (s = 0.8): inradius 5, so rings at
    # d = 1, 1.8, 2.6, 3.4, 4.2 (the next, 5.0, reaches the middle line and is empty).
    r, s, inradius = 1.0, 0.8, 5.0
    expected = [r + k * s for k in range(10) if r + k * s < inradius - 1e-9]
    stage = _plan([rect(0, 0, 20, 10)])
    assert [c.kind for c in stage.cuts] == ["pocket"]  # linked: no retracts
    cut = stage.cuts[0]
    assert not cut.may_reverse and not cut.may_rotate
    rings, links = _loops(cut.path)
    assert len(rings) == len(expected) == 5
    assert len(links) == 4
    for ring, d in zip(rings, expected, strict=True):
        x0, y0, x1, y1 = Contour(tuple(ring), True).bbox()
        assert (x0, y0, x1, y1) == pytest.approx((d, d, 20 - d, 10 - d), abs=TOL)
    # the wall ring is the exact inside offset: four lines, the 18 × 8 box
    wall = rings[0]
    assert len(wall) == 4 and all(isinstance(seg, Line) for seg in wall)
    exact = offset_contour(rect(0, 0, 20, 10), -1.0)
    assert _signed_area(wall) == pytest.approx(abs(exact.signed_area()), abs=1e-9)
    # every link, swept by the tool, stays inside the pocket
    region = _shape(rect(0, 0, 20, 10)).buffer(TOL)
    for link in links:
        assert region.covers(LineString([link.start, link.end]).buffer(r))


def test_rectangle_swept_area_leaves_only_the_corner_fillets() -> None:
    stage = _plan([rect(0, 0, 20, 10)])
    uncovered = _shape(rect(0, 0, 20, 10)).difference(_swept(stage.cuts, 1.0))
    assert uncovered.area == pytest.approx(4 * FILLET, abs=0.01)
    assert not [f for f in stage.findings if f.kind == "uncut"]
    (corners,) = [f for f in stage.findings if f.kind == "tight-corner"]
    assert corners.message.count("4 pocket corner(s)") == 1 and corners.value == 1.0


def test_circle_rings_are_concentric_arcs_and_the_centre_is_cut() -> None:
    # R = 10, r = 1, s = 0.8: ring radii R − r − k·s > 0: 9, 8.2, ..., 0.2 (12 rings).
    big_r, r, s = 10.0, 1.0, 0.8
    radii = [big_r - r - k * s for k in range(20) if big_r - r - k * s > 1e-9]
    stage = _plan([circle(0, 0, big_r)])
    assert len(stage.cuts) == 1
    rings, links = _loops(stage.cuts[0].path)
    assert len(rings) == len(radii) == 12
    for ring, radius in zip(rings, radii, strict=True):
        assert all(isinstance(seg, Arc) for seg in ring)
        for arc in ring:
            assert isinstance(arc, Arc)
            assert arc.radius == pytest.approx(radius, abs=TOL)
            assert math.dist(arc.centre, (0, 0)) < TOL
            assert not arc.clockwise  # climb along the outer wall: counter-clockwise
        assert sum(a.sweep for a in ring if isinstance(a, Arc)) == pytest.approx(math.tau)
    assert all(link.length == pytest.approx(s, abs=TOL) for link in links)  # radial links
    swept = _swept(stage.cuts, r)
    assert swept.covers(ShapelyPoint(0, 0))
    disc = _shape(circle(0, 0, big_r))
    assert disc.difference(swept).area < TOL * disc.length  # chords of the buffers only
    assert not stage.findings


def test_large_stepover_adds_a_ring_so_the_middle_is_cut() -> None:
    # s = 0.9·2 = 1.8: rings at radius 9, 7.2, 5.4, 3.6, 1.8; the middle lies 1.8 > r from
    # the last ring, so one more ring goes round it (r/2 inside the deepest point).
    stage = _plan([circle(0, 0, 10.0)], stepover=0.9)
    rings, _ = _loops(stage.cuts[0].path)
    assert len(rings) == 6
    last = rings[-1][0]
    assert isinstance(last, Arc) and last.radius < 1.0
    swept = _swept(stage.cuts, 1.0)
    assert swept.covers(ShapelyPoint(0, 0))
    disc = _shape(circle(0, 0, 10.0))
    assert disc.difference(swept).area < TOL * disc.length
    assert not stage.findings


@pytest.mark.parametrize("style", ["concentric", "zigzag"])
@pytest.mark.parametrize(
    "island",
    [circle(12, 10, 4), rect(8, 6, 16, 14), rect(6, 9.2, 24, 10.8)],
    ids=["circle", "square", "bar"],
)
def test_islands_and_outer_wall_are_never_cut_into(style: str, island: Contour) -> None:
    outer = rect(0, 0, 30, 20)
    stage = _plan([outer, island], pocket=style, pocket_angle_deg=30.0)
    assert stage.cuts and all(c.kind == "pocket" and c.group == 0 for c in stage.cuts)
    swept = _swept(stage.cuts, 1.0)
    hole = _shape(island)
    assert swept.intersection(hole).area < TOL * hole.length
    outside = swept.difference(_shape(outer))
    assert outside.area < TOL * _shape(outer).length
    # and the rest of the pocket is cleared: only corner fillets stay (4 outer corners,
    # plus none at an island: the tool rolls round its convex corners)
    region = _shape(outer).difference(hole)
    assert region.difference(swept).area < 4 * FILLET + 0.05
    assert not [f for f in stage.findings if f.kind == "uncut"]


@pytest.mark.parametrize("angle", [0.0, 45.0])
def test_zigzag_lines_follow_the_angle_at_the_stepover(angle: float) -> None:
    stage = _plan([rect(0, 0, 20, 10)], pocket="zigzag", pocket_angle_deg=angle)
    first = stage.cuts[0]
    rings, _ = _loops(Contour(first.path.segments[:4], True))
    assert len(rings) == 1  # the wall ring comes first
    ux, uy = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    rows = set()
    count = 0
    for cut in stage.cuts:
        segs = cut.path.segments[4:] if cut is first else cut.path.segments
        for seg in segs:
            assert isinstance(seg, Line)
            dx, dy = seg.end[0] - seg.start[0], seg.end[1] - seg.start[1]
            if abs(dx * uy - dy * ux) < 1e-9 * max(1.0, seg.length) and seg.length > 0.9:
                count += 1
                rows.add(round(-uy * seg.start[0] + ux * seg.start[1], 6))
    offsets = sorted(rows)
    assert count >= len(offsets) >= 8
    gaps = [b - a for a, b in itertools.pairwise(offsets)]
    assert gaps == pytest.approx([0.8] * len(gaps), abs=1e-6)
    uncovered = _shape(rect(0, 0, 20, 10)).difference(_swept(stage.cuts, 1.0))
    assert uncovered.area < 4 * FILLET + 0.05
    assert not [f for f in stage.findings if f.kind == "uncut"]


def test_zigzag_rows_alternate_direction() -> None:
    stage = _plan([rect(0, 0, 20, 10)], pocket="zigzag")
    assert len(stage.cuts) == 1  # every row linked to the next along the wall
    rows = [s for s in stage.cuts[0].path.segments[4:] if isinstance(s, Line) and s.length > 5]
    directions = [math.copysign(1.0, s.end[0] - s.start[0]) for s in rows]
    assert all(a == -b for a, b in itertools.pairwise(directions))


def test_slot_narrower_than_the_tool_is_reported_where_it_is() -> None:
    # A 20 × 10 pocket with a 1 mm wide, 6 mm long arm to the right; 2 mm tool.
    outline = [(0, 0), (20, 0), (20, 4.5), (26, 4.5), (26, 5.5), (20, 5.5), (20, 10), (0, 10)]
    stage = _plan([polygon(outline)])
    uncut = [f for f in stage.findings if f.kind == "uncut"]
    assert len(uncut) == 1
    (finding,) = uncut
    assert finding.at is not None
    assert Polygon([(20, 4.5), (26, 4.5), (26, 5.5), (20, 5.5)]).contains(ShapelyPoint(finding.at))
    assert finding.value is not None and 4.0 < finding.value < 6.0  # most of the 6 mm² arm
    assert "narrower than the 2 mm tool" in finding.message
    assert "use a smaller tool" in finding.message


def test_stepover_too_large_for_square_corners_is_reported_between_passes() -> None:
    # 20 × 20, r = 1, stepover 1.0 (s = 2r): rings at d = 1, 3, 5, 7, 9 meet along the
    # sides but leave a cusp at each corner between two rings: the square r × r beyond both
    # sweeps minus the quarter disc of the inner ring's corner, r² − πr²/4. 4 gaps × 4
    # corners, less the corner each diagonal link sweeps: 12 cusps.
    stage = _plan([rect(0, 0, 20, 20)], stepover=1.0)
    uncut = [f for f in stage.findings if f.kind == "uncut"]
    single, more = uncut[:5], uncut[5:]
    assert len(single) == 5 and len(more) == 1
    for f in single:
        assert "between passes" in f.message and "reduce --stepover" in f.message
        assert f.at is not None
        assert abs(abs(f.at[0] - 10) - abs(f.at[1] - 10)) < 0.5  # on a diagonal
        assert f.value == pytest.approx(FILLET, abs=0.01)
    assert more[0].message.count("and 7 more") == 1
    assert more[0].value == pytest.approx(7 * FILLET, abs=0.05)


def test_pocket_entirely_narrower_than_the_tool_is_a_finding() -> None:
    stage = _plan([rect(0, 0, 20, 10), rect(30, 0, 40, 1.5)])
    assert {c.group for c in stage.cuts} == {0}
    (finding,) = [f for f in stage.findings if f.kind == "uncut"]
    assert finding.value == pytest.approx(15.0, rel=1e-6)
    assert finding.at is not None and 30 < finding.at[0] < 40
    assert "narrower than the 2 mm tool" in finding.message


def test_nothing_to_pocket_raises() -> None:
    with pytest.raises(ToolpathError, match="narrower than the 2 mm tool"):
        _plan([rect(0, 0, 10, 1)])
    with pytest.raises(ToolpathError, match="needs closed contours"):
        _plan([Contour((Line((0, 0), (5, 0)),), False)])


def test_direction_climb_and_conventional_are_opposite() -> None:
    contours = [rect(0, 0, 30, 20), circle(15, 10, 3)]
    orientations = {}
    for direction in ("climb", "conventional"):
        stage = _plan(contours, direction=direction)
        rings, _ = _loops(stage.cuts[0].path)
        orientations[direction] = [math.copysign(1, _signed_area(ring)) for ring in rings]
        side = stage.cuts[0].material_side
        assert side == ("right" if direction == "climb" else "left")
    climb, conventional = orientations["climb"], orientations["conventional"]
    assert climb == [-o for o in conventional]
    assert climb[:2] == [1, -1]  # outer wall counter-clockwise, around the island clockwise
    assert _plan(contours).cuts[0].path == _plan(contours, direction="climb").cuts[0].path


def test_island_inside_an_island_is_a_new_pocket() -> None:
    # depth 0 pocket, depth 1 island, depth 2 pocket inside the island
    contours = [rect(0, 0, 40, 30), rect(10, 5, 30, 25), rect(15, 10, 25, 20)]
    stage = _plan(contours)
    assert {c.group for c in stage.cuts} == {0, 2}
    inner = _swept([c for c in stage.cuts if c.group == 2], 1.0)
    assert inner.difference(_shape(contours[2])).area < TOL * 40


def test_overlapping_pocket_outlines_are_said_with_their_common_area() -> None:
    """Two rectangles overlapping 20 × 30 mm and a circle inside both (analysis: 600 mm²)."""
    contours = [rect(0, 0, 40, 30), rect(20, 0, 60, 30), circle(30, 15, 4)]
    stage = _plan(contours)
    (finding,) = [f for f in stage.findings if f.kind == "overlap"]
    assert finding.value == pytest.approx(600.0, rel=1e-9)
    assert finding.at is not None and 20 < finding.at[0] < 40 and 0 < finding.at[1] < 30
    assert "1 contour inside both is cleared as a pocket, not kept as an island" in finding.message
    assert "at (0.0000, 0.0000) mm and contour at (20.0000, 0.0000) mm" in finding.message
    # each outline is cleared whole: both groups reach into the common area
    common = rect(22, 2, 38, 28)
    for group in (0, 1):
        swept = _swept([c for c in stage.cuts if c.group == group], 1.0)
        assert swept.intersection(_shape(common)).area > 0.9 * _shape(common).area


@pytest.mark.parametrize(
    "contours",
    [
        [rect(0, 0, 40, 30), rect(10, 5, 30, 25)],  # an island
        [rect(0, 0, 20, 30), rect(20, 0, 40, 30)],  # a shared edge
        [rect(0, 0, 20, 30), rect(30, 0, 40, 30)],  # apart
        [rect(0, 0, 40, 30), rect(10, 5, 30, 25), rect(15, 10, 25, 20)],  # nested three deep
    ],
)
def test_outlines_that_only_nest_or_touch_are_no_overlap(contours: list[Contour]) -> None:
    assert not [f for f in _plan(contours).findings if f.kind == "overlap"]


def test_many_overlaps_are_named_up_to_the_limit_then_counted() -> None:
    from camtool.toolpath.cuts import MAX_LISTED

    contours = [rect(10.0 * k, 0, 10.0 * k + 15, 10) for k in range(MAX_LISTED + 4)]
    found = [f for f in _plan(contours).findings if f.kind == "overlap"]
    assert len(found) == MAX_LISTED + 1
    assert all(f.value == pytest.approx(50.0) for f in found[:MAX_LISTED])
    assert found[-1].message.startswith("3 more pairs of pocket outlines overlap")
    assert found[-1].value == pytest.approx(150.0)


def test_open_contours_are_not_cut_by_a_pocket() -> None:
    line = Contour((Line((50, 0), (60, 0)),), False)
    stage = _plan([rect(0, 0, 20, 10), line])
    assert not [c for c in stage.cuts if c.kind == "open"]
    (finding,) = [f for f in stage.findings if f.kind == "open-left-out"]
    assert finding.message.startswith("not cut: open contour at (50.0000, 0.0000) mm")
    assert "--offset pocket needs a closed contour" in finding.message


@settings(max_examples=15, deadline=None)
@given(
    radii=st.lists(st.floats(8.0, 20.0), min_size=3, max_size=9),
    island=st.floats(0.5, 4.0),
    style=st.sampled_from(["concentric", "zigzag"]),
    angle=st.floats(0.0, 180.0),
)
def test_random_star_pockets_never_gouge(
    radii: list[float], island: float, style: str, angle: float
) -> None:
    # a star-shaped polygon around (0, 0) with a round island in the middle
    n = len(radii)
    points = [
        (rho * math.cos(math.tau * k / n), rho * math.sin(math.tau * k / n))
        for k, rho in enumerate(radii)
    ]
    outer, hole = polygon(points), circle(0.0, 0.0, island)
    stage = _plan([outer, hole], pocket=style, pocket_angle_deg=angle)
    region = _shape(outer).difference(_shape(hole))
    swept = _swept(stage.cuts, 1.0)
    assert swept.difference(region).area < TOL * region.boundary.length


def test_a_large_pocket_with_two_islands_keeps_off_them() -> None:
    # its planning time is measured in tests/benchmarks/bench_planning.py, not here
    contours = [rect(0, 0, 100, 60), circle(30, 30, 10), rect(60, 20, 80, 40)]
    for style in ("concentric", "zigzag"):
        stage = _plan(contours, tool=3.0, pocket=style)
        swept = _swept(stage.cuts, 1.5)
        for island in contours[1:]:
            assert swept.intersection(_shape(island)).area < TOL * _shape(island).length


def test_clearing_pockets_tells_its_progress_region_by_region() -> None:
    """Two separate pockets: the ``pocketing`` stage at 0, 1 and 2 of 2 regions."""
    contours = [rect(0, 0, 10, 10), rect(20, 0, 30, 10)]
    options = PlanOptions(offset="pocket", tool_diameter=2.0, feed_mm_min=100.0, tolerance=TOL)
    steps: list[Step] = []
    pocket(contours, nesting(contours), options, progress=steps.append)
    assert steps == [Step("pocketing", n, 2) for n in range(3)]


@pytest.mark.parametrize("piece", [4096, 64, 2])
def test_swept_area_of_a_long_path_is_the_buffer_of_the_whole_path(piece: int) -> None:
    # A spiral of 3 turns 0.5 mm apart as ~12 000 chords (three pieces of SWEEP_PIECE
    # points, or ~190 of the smallest, or one per chord), swept by r = 0.2: the pieces'
    # union must be GEOS's buffer of the whole line, computed here at once, and (the turns
    # 2r apart) a band 2r wide along the line with a disc at its ends.
    from camtool.toolpath.pocket_uncut import SWEEP_PIECE, quad_segs, swept_area

    n = 3 * SWEEP_PIECE
    pts = [
        (
            (10 - 0.5 * 3 * k / n) * math.cos(math.tau * 3 * k / n),
            (10 - 0.5 * 3 * k / n) * math.sin(math.tau * 3 * k / n),
        )
        for k in range(n + 1)
    ]
    path = Contour(tuple(Line(a, b) for a, b in itertools.pairwise(pts)), False)
    r = 0.2
    whole = LineString(pts).buffer(r, quad_segs=quad_segs(r, TOL))
    swept = swept_area([path], r, TOL, piece=piece)
    if piece == SWEEP_PIECE:
        assert swept.area == pytest.approx(whole.area, rel=1e-9)
        assert swept.symmetric_difference(whole).area < 1e-6  # float noise of the cuts, mm²
    else:
        # each join between pieces is two round caps' chords instead of the one line's
        # join: both within TOL / 4 of the true circle (quad_segs), so the areas differ by
        # at most a band TOL / 4 thick along the outline
        assert swept.symmetric_difference(whole).area <= TOL / 4 * whole.length
    assert swept.area == pytest.approx(2 * r * LineString(pts).length + math.pi * r * r, rel=1e-3)


def test_a_small_stepover_sweeps_its_pocket_in_pieces_that_hold_few_passes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # At a step-over of 0.3 % of a 3 mm tool, ~110 passes lie within the tool's width of
    # each other; a rectangle's rings are 4-8 points each, so a piece of SWEEP_PIECE points
    # would hold hundreds of passes over one another, which GEOS buffers far more slowly
    # than many short pieces. The uncut check must cut its path into pieces of at most
    # MIN_SWEEP_PIECE points there, and of SWEEP_PIECE at the default step-over.
    import shapely

    from camtool.toolpath import pocket_uncut
    from camtool.toolpath.pocket_uncut import MIN_SWEEP_PIECE, SWEEP_PIECE

    biggest: list[int] = []
    real = shapely.buffer

    def spy(geometry: object, *args: object, **kw: object) -> object:
        sizes = shapely.get_num_coordinates(geometry)
        biggest.append(int(sizes.max()) if hasattr(sizes, "max") else int(sizes))
        return real(geometry, *args, **kw)

    monkeypatch.setattr(pocket_uncut.shapely, "buffer", spy)
    stage = _plan([rect(0, 0, 12, 8)], 3.0, stepover=0.003)
    assert biggest and max(biggest) <= MIN_SWEEP_PIECE
    passes = sum(len(c.path.segments) for c in stage.cuts)
    assert passes > 10 * MIN_SWEEP_PIECE  # the path is far longer than one piece
    assert not [f for f in stage.findings if f.kind == "uncut"]  # nothing left between passes
    biggest.clear()
    _plan([rect(0, 0, 12, 8)], 3.0)
    assert 2 < max(biggest) <= SWEEP_PIECE
    assert pocket_uncut.sweep_piece(0.4) == SWEEP_PIECE
    assert pocket_uncut.sweep_piece(0.1) == SWEEP_PIECE // 4
    assert pocket_uncut.sweep_piece(1e-6) == MIN_SWEEP_PIECE


def test_an_arc_drawn_there_and_back_is_a_pocket_of_no_area_not_one_that_crosses_itself() -> None:
    # two copies of one ARC chained: no area to clear, said once (not also "crosses itself",
    # which the chords one way and back, a rounding apart, made it look as if it did)
    ccw = Arc((20.0, 5.0), (30.0, 5.0), (25.0, 5.0), False)
    there_and_back = Contour((ccw, Arc((30.0, 5.0), (20.0, 5.0), (25.0, 5.0), True)), True)
    stage = _plan([rect(0, 20, 50, 30), there_and_back], 1.0)
    kinds = [f.kind for f in stage.findings if f.at == (20.0, 5.0)]
    assert kinds == ["offset-vanished"]
    assert not [f for f in stage.findings if f.kind == "self-crossing"]
