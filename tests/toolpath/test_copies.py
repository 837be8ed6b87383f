"""A path drawn twice is cut once (camtool.toolpath.copies).

Expected values are from the drawings: every plunge is at a contour's start, so the number
of plunges to the depth is the number of paths cut.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import ezdxf
import pytest

from camtool.importers import read_drawing
from camtool.jobs.pipeline import post_drawing
from camtool.model.errors import ToolpathError
from camtool.model.program import ArcMove, Linear, segment_of
from camtool.model.shapes import Contour, Drawing, Line, make_arc
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from tests.shapes import kin47_arcs_dxf
from tests.toolpath.contours import circle, rect

# LibreOffice Impress's SVG export of an arrow shape (a CustomShape): the fill path, with the
# two zero-length subpaths LibreOffice adds at the shape's box corners, then the same outline
# as a stroke path, then the corners again as stroke paths of their own.
LIBREOFFICE = """<svg version="1.2" width="281mm" height="154mm" viewBox="0 0 38100 25400"
 preserveAspectRatio="xMidYMid" fill-rule="evenodd" stroke-width="28.222"
 xmlns="http://www.w3.org/2000/svg">
 <g class="com.sun.star.drawing.CustomShape"><g id="id3">
  <rect class="BoundingBox" stroke="none" fill="none" x="3212" y="18808" width="639" height="1866"/>
  <path fill="rgb(250,166,26)" stroke="none" d="M 3372,20671 L 3372,19274 3213,19274 3531,18809 \
3849,19274 3690,19274 3690,20671 3372,20671 Z M 3213,18809 L 3213,18809 Z \
M 3849,20672 L 3849,20672 Z"/>
  <path fill="none" stroke="rgb(52,101,164)" d="M 3372,20671 L 3372,19274 3213,19274 3531,18809 \
3849,19274 3690,19274 3690,20671 3372,20671 Z"/>
  <path fill="none" stroke="rgb(52,101,164)" d="M 3213,18809 L 3213,18809 Z"/>
  <path fill="none" stroke="rgb(52,101,164)" d="M 3849,20672 L 3849,20672 Z"/>
 </g></g>
</svg>
"""


def test_a_libreoffice_shape_exported_as_fill_and_outline_is_cut_once(tmp_path: Path) -> None:
    path = tmp_path / "arrow.svg"
    path.write_text(LIBREOFFICE)
    drawing = read_drawing(path)
    job = post_drawing(drawing, load_target("linuxcnc"), PlanOptions(depth=1.0))
    plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
    assert len(plunges) == 1
    (note,) = [w for w in job.warnings if "repeats" in w]
    assert note.endswith("on its path (a fill and its outline, or a copy on top of it): cut once")
    for options in ({"offset": "outside"}, {"offset": "pocket"}):
        job = post_drawing(
            drawing, load_target("linuxcnc"), PlanOptions(depth=1.0, tool_diameter=0.5, **options)
        )
        assert not any("overlap" in w for w in job.warnings)  # the pocket: one outline, not two


def test_stacked_dxf_shapes_are_cut_once_whatever_their_start_and_direction(
    tmp_path: Path,
) -> None:
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_circle((20, 20), 3)
    msp.add_circle((20, 20), 3)
    msp.add_lwpolyline([(30, 0), (40, 0), (40, 10), (30, 10)], close=True)
    msp.add_lwpolyline([(40, 10), (40, 0), (30, 0), (30, 10)], close=True)  # reversed, rotated
    path = tmp_path / "stacked.dxf"
    doc.saveas(path)
    job = post_drawing(read_drawing(path), load_target("linuxcnc"), PlanOptions(depth=1.0))
    cuts = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
    assert len(cuts) == 2  # the circle, the square
    assert sum("repeats" in w for w in job.warnings) == 2


@pytest.mark.parametrize("shift", [0.0, 0.02])
def test_only_a_contour_on_the_same_path_is_a_copy(shift: float) -> None:
    # A square sharing one edge with the first is not a copy of it; a circle and a half
    # circle on the same centre are not copies either. A square 0.02 mm off is not one
    # even when --tolerance allows more (it is the arc fit's tolerance, not the drawing's),
    # nor is it within the 0.01 mm of an outline drawn twice a little off.
    square, near, beside = rect(0, 0, 10, 10), rect(shift, 0, 10 + shift, 10), rect(10, 0, 20, 10)
    half = Contour((make_arc((35, 5), (25, 5), (30, 5), False),), False)
    job = post_drawing(
        Drawing((square, near, beside, circle(30, 5, 5), half)),
        load_target("linuxcnc"),
        PlanOptions(depth=1.0, tolerance=0.05),
    )
    cuts = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
    assert len(cuts) == (4 if shift == 0.0 else 5)


def test_a_thin_ring_is_two_circles_whatever_the_tolerance(tmp_path: Path) -> None:
    # Two circles 0.3 mm apart on one centre: a ring's walls, both cut at --tolerance 0.5.
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_circle((20, 20), 10)
    doc.modelspace().add_circle((20, 20), 10.3)
    path = tmp_path / "ring.dxf"
    doc.saveas(path)
    options = PlanOptions(depth=1.0, tolerance=0.5)
    job = post_drawing(read_drawing(path), load_target("linuxcnc"), options)
    cuts = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
    assert len(cuts) == 2
    assert not any("repeats" in w for w in job.warnings)


def _feed_length(moves: list[object]) -> float:
    """The XY length fed at Z -1, mm (lines only)."""
    total, here = 0.0, None
    for move in moves:
        xy = (move.x, move.y)  # type: ignore[attr-defined]
        if isinstance(move, Linear) and move.z in (None, -1.0) and here is not None:
            total += math.dist(here, xy)
        here = xy
    return total


@pytest.mark.parametrize(
    "second",
    [
        [(0, 0), (30, 0), (30, 20)],  # the polyline drawn again the same way
        [(30, 20), (30, 0), (0, 0)],  # and back the other way
    ],
)
def test_a_line_drawn_twice_end_to_end_is_cut_one_way(tmp_path: Path, second: list) -> None:
    # Stacked copies of an open polyline chain end to end into a contour that runs out and
    # back on one path: cut out only, 30 + 20 mm of feed.
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(0, 0), (30, 0), (30, 20)])
    doc.modelspace().add_lwpolyline(second)
    path = tmp_path / "twice.dxf"
    doc.saveas(path)
    job = post_drawing(read_drawing(path), load_target("linuxcnc"), PlanOptions(depth=1.0))
    assert math.isclose(_feed_length(list(job.program.moves)), 50.0)
    assert sum("runs back on its own path" in w for w in job.warnings) == 1
    # with a side, it stays the region of no area it was drawn as, and is said so
    outside = PlanOptions(depth=1.0, offset="outside", tool_diameter=3.0)
    with pytest.raises(ToolpathError, match="is about 0 mm wide"):
        post_drawing(read_drawing(path), load_target("linuxcnc"), outside)


def test_a_closed_outline_through_a_line_drawn_twice_keeps_both() -> None:
    # Two triangles sharing their middle edge, that edge drawn once for each: one closed
    # contour runs through both copies (out along the edge and back), not a retrace of
    # itself, and is cut whole.
    a, b, c, d = (0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (20.0, 0.0)
    lines = [Line(a, b), Line(b, c), Line(c, a), Line(b, c), Line(c, d), Line(d, b)]
    drawing = Drawing(tuple(Contour((seg,), False) for seg in lines))
    job = post_drawing(drawing, load_target("linuxcnc"), PlanOptions(depth=1.0))
    assert math.isclose(_feed_length(list(job.program.moves)), sum(s.length for s in lines))
    assert not any("runs back" in w for w in job.warnings)


def test_two_copies_of_a_circle_drawn_as_an_arc_short_of_360_are_one_closed_circle(
    tmp_path: Path,
) -> None:
    # LibreCAD's kinetics/kin47.dxf: ARCs from 270° to 269.99999427° (a gap of 0.25 µm),
    # each drawn twice. Chained out and back they are one circle: cut once, and closed, so
    # a side cuts it (an open arc would be left out).
    drawing = read_drawing(kin47_arcs_dxf(tmp_path / "arcs.dxf", (20.0, 20.0)))
    outside = PlanOptions(depth=1.0, offset="outside", tool_diameter=1.0)
    job = post_drawing(drawing, load_target("linuxcnc"), outside)
    assert sum("runs back on its own path" in w for w in job.warnings) == 1
    # one lap of the tool centre, on a circle of radius 2.5 + 0.5 mm
    arcs = [m for m in job.program.moves if isinstance(m, ArcMove) and m.z in (None, -1.0)]
    lap = sum(
        segment_of((p.x, p.y), m).length
        for p, m in itertools.pairwise(job.program.moves)
        if m in arcs
    )
    assert math.isclose(lap, 2 * math.pi * 3.0, rel_tol=1e-6)


def _arc_radii(job: object) -> list[float]:
    """The radius of each arc of the program, from its end and centre (the offset's side)."""
    return sorted(
        round(math.hypot(m.x - m.cx, m.y - m.cy), 6)
        for m in job.program.moves  # type: ignore[attr-defined]
        if isinstance(m, ArcMove)
    )


def test_a_copy_split_differently_is_cut_once_and_its_hole_stays_a_hole(tmp_path: Path) -> None:
    """A polyline square and the same square as LINEs from another corner, one edge split.

    Were the copy not found, the circle would lie inside two squares: the outside profile
    would take the hole for a part and cut round it outside, a 10 mm hole 13 mm wide.
    Expected from the drawing: one square; the hole cut inside, on radius 5 - 1.5 mm.
    """
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
    for a, b in [((40, 30), (0, 30)), ((0, 30), (0, 0)), ((0, 0), (25, 0)), ((25, 0), (40, 0))]:
        msp.add_line(a, b)
    msp.add_line((40, 0), (40, 30))
    msp.add_circle((20, 15), 5)
    path = tmp_path / "square-twice.dxf"
    doc.saveas(path)
    options = PlanOptions(depth=3.0, offset="outside", tool_diameter=3.0)
    job = post_drawing(read_drawing(path), load_target("linuxcnc"), options)
    plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -3.0]
    assert len(plunges) == 2  # the hole, the square once
    assert _arc_radii(job) == [1.5] * 4 + [3.5] * 2  # the square's corners, the hole
    assert sum("repeats" in w for w in job.warnings) == 1


def test_a_circle_of_two_arcs_is_a_copy_of_a_circle() -> None:
    halves = Contour(
        (make_arc((30, 10), (30, 0), (30, 5), True), make_arc((30, 0), (30, 10), (30, 5), True)),
        True,
    )
    job = post_drawing(
        Drawing((circle(30, 5, 5), halves)), load_target("linuxcnc"), PlanOptions(depth=1.0)
    )
    plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
    assert len(plunges) == 1


@pytest.mark.parametrize("bow", [0.002, 0.05])
def test_lines_joined_only_where_every_vertex_is_on_the_line(bow: float) -> None:
    """A bottom edge of 40 short lines bowed ``bow`` mm at its middle, against a straight one.

    Each vertex is within 1 µm of the line through its neighbours' ends (the bend at each
    is tiny), but not of the edge: they are not copies. (Bowed 2 µm, the planner then
    cuts them once as an outline drawn twice a little off: the test after the next.)
    """
    from camtool.toolpath.copies import drop_copies

    n = 40
    points = [(40.0 * k / n, bow * math.sin(math.pi * k / n)) for k in range(n + 1)]
    bowed = [Line(points[k], points[k + 1]) for k in range(n)]
    bowed += [Line((40, 0), (40, 30)), Line((40, 30), (0, 30)), Line((0, 30), (0, 0))]
    kept, found, _ = drop_copies([rect(0, 0, 40, 30), Contour(tuple(bowed), True)])
    assert len(kept) == 2 and not found


def _square_twice_and_a_hole(tmp_path: Path, off: float) -> Path:
    """A 40 mm square, the same square ``off`` mm up and right, a 10 mm hole inside both."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (40, 0), (40, 40), (0, 40)], close=True)
    corners = [(0, 0), (40, 0), (40, 40), (0, 40)]
    msp.add_lwpolyline([(x + off, y + off) for x, y in corners], close=True)
    msp.add_circle((20, 20), 5)
    path = tmp_path / "near.dxf"
    doc.saveas(path)
    return path


def test_an_outline_drawn_twice_a_little_off_is_cut_once_and_its_hole_stays_a_hole(
    tmp_path: Path,
) -> None:
    """Two squares 5 µm apart cross each other: were both cut, the circle would lie two
    outlines deep and the outside profile would cut round it, a 10 mm hole 13 mm wide.
    Expected from the drawing: the hole on radius 5 - 1.5 mm, one square (corners 1.5)."""
    options = PlanOptions(depth=3.0, offset="outside", tool_diameter=3.0)
    job = post_drawing(
        read_drawing(_square_twice_and_a_hole(tmp_path, 0.005)), load_target("linuxcnc"), options
    )
    plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -3.0]
    assert len(plunges) == 2
    assert _arc_radii(job) == [1.5] * 4 + [3.5] * 2
    said = [w for w in job.warnings if "all along" in w]
    assert len(said) == 1 and "runs within 0.0071 mm of contour LWPOLYLINE" in said[0]


def test_outlines_further_apart_than_10_um_are_both_cut(tmp_path: Path) -> None:
    """15 µm apart (21 µm at the corners) they are two outlines, as drawn; the nesting then
    says the tool cuts into the part, as before."""
    options = PlanOptions(depth=3.0, offset="outside", tool_diameter=3.0)
    job = post_drawing(
        read_drawing(_square_twice_and_a_hole(tmp_path, 0.015)), load_target("linuxcnc"), options
    )
    plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -3.0]
    assert len(plunges) == 3
    assert not any("all along" in w for w in job.warnings)


def test_a_circle_drawn_over_its_polygon_is_cut_once_as_the_circle() -> None:
    """A 72-gon on a 5 mm circle lies within 5 (1 - cos 2.5°) = 4.8 µm of it: the circle,
    of fewer segments, is kept, whichever was drawn first."""
    ring = [
        (30 + 5 * math.cos(k * math.pi / 36), 5 + 5 * math.sin(k * math.pi / 36)) for k in range(72)
    ]
    gon = Contour(tuple(Line(a, b) for a, b in itertools.pairwise([*ring, ring[0]])), True)
    for drawn in [(gon, circle(30, 5, 5)), (circle(30, 5, 5), gon)]:
        job = post_drawing(Drawing(drawn), load_target("linuxcnc"), PlanOptions(depth=1.0))
        plunges = [m for m in job.program.moves if isinstance(m, Linear) and m.z == -1.0]
        assert len(plunges) == 1
        assert sum(isinstance(m, ArcMove) for m in job.program.moves) >= 1
        assert not any(isinstance(m, Linear) and m.z is None for m in job.program.moves)


def test_the_nesting_without_a_contour_is_the_nesting_of_the_others() -> None:
    from camtool.toolpath.order import nesting

    contours = [rect(0, 0, 40, 40), rect(0.005, 0.005, 40.005, 40.005), circle(20, 20, 5)]
    contours.append(rect(18, 18, 22, 22))
    whole = nesting(contours)
    assert whole.near[0][:2] == (0, 1) and whole.near[0][2] == pytest.approx(0.005 * 2**0.5)
    for left in range(4):
        kept = [c for k, c in enumerate(contours) if k != left]
        assert whole.without({left}).parents == nesting(kept).parents
