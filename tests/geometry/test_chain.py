"""Chaining keeps what it does not join (the same objects, a chain's first piece's style) and takes
the loops an open chain passes through out as closed contours."""

from __future__ import annotations

import itertools
import math

import pytest

from camtool.geometry.area import enclosed
from camtool.geometry.chain import chain, chain_members, with_end, with_start
from camtool.model.shapes import Arc, Contour, Line
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.plan import chained


def test_a_contour_that_joins_nothing_is_returned_as_it_was() -> None:
    """No copy of a lone open contour (a 200 000-LINE drawing kept one of each)."""
    lone = Contour((Line((0.0, 0.0), (1.0, 0.0)),), False, "A", "LINE #1", "#ff0000", "CENTER")
    far = Contour((Line((5.0, 5.0), (6.0, 5.0)),), False, "B", "LINE #2")
    out = chain([lone, far], 0.01)
    assert out[0] is lone and out[1] is far


def test_a_chain_keeps_its_first_piece_s_colour_and_linetype() -> None:
    a = Contour((Line((0.0, 0.0), (1.0, 0.0)),), False, "A", "LINE #1", "#ff0000", "DASHED")
    b = Contour((Line((1.0, 0.0), (1.0, 1.0)),), False, "B", "LINE #2", "#00ff00", "")
    (joined,) = chain([a, b], 0.01)
    assert len(joined.segments) == 2
    assert (joined.layer, joined.source, joined.colour, joined.linetype) == (
        "A",
        "LINE #1",
        "#ff0000",
        "DASHED",
    )


# -- an arc shorter than a joint: never turned into its whole circle ----------------------------


def _speck(sweep_deg: float, radius: float = 50.0) -> Arc:
    """A counter-clockwise arc of ``sweep_deg`` on a circle about (100, 100), from angle 0."""
    a = math.radians(sweep_deg)
    end = (100.0 + radius * math.cos(a), 100.0 + radius * math.sin(a))
    return Arc((100.0 + radius, 100.0), end, (100.0, 100.0), False)


def test_a_lone_speck_arc_within_the_joint_stays_open_and_short() -> None:
    # 0.005° of radius 50: 0.0044 mm long, its ends within the 0.01 mm joint. It is no
    # circle: closing it would move its end onto its start, a 100 mm circle (sweep 2π).
    speck = Contour((_speck(0.005),), False, "0", "ARC #1")
    (out,) = chain([speck], 0.01)
    assert not out.closed
    assert out.segments[0].length < 0.01


def test_a_near_full_arc_within_the_joint_is_a_closed_circle() -> None:
    near = Contour((_speck(360.0 - 0.005),), False, "0", "ARC #1")
    (out,) = chain([near], 0.01)
    assert out.closed
    assert out.segments[0].is_full_circle
    assert math.isclose(out.segments[0].length, 2 * math.pi * 50.0)


def test_a_speck_arc_whose_end_is_moved_back_past_its_start_becomes_a_line() -> None:
    # The speck runs from angle 0 to 0.005° (0.0044 mm); the end is moved to a point
    # 0.003 mm before its start on the circle: as an arc, nearly the whole circle.
    speck = _speck(0.005)
    back = (100.0 + 50.0 * math.cos(-6e-5), 100.0 + 50.0 * math.sin(-6e-5))
    moved = with_end(speck, back)
    assert moved == Line(speck.start, back)
    assert with_start(speck.reversed(), back) == Line(back, speck.start)


def test_an_arc_moved_within_its_length_keeps_its_centre() -> None:
    arc = _speck(30.0)
    end = (arc.end[0] + 0.004, arc.end[1])
    moved = with_end(arc, end)
    assert isinstance(moved, Arc) and moved.centre == arc.centre
    assert math.isclose(moved.sweep, arc.sweep, abs_tol=1e-3)


def test_a_speck_chain_closed_by_moving_its_arc_back_cuts_no_circle() -> None:
    # A 0.0026 mm LINE ends where the speck starts; the speck's end is 0.007 mm from the
    # line's start, within the joint: closing the chain moves it back past its own start.
    speck = _speck(0.005)
    a = (
        100.0 + 50.0 * math.cos(math.radians(-0.003)),
        100.0 + 50.0 * math.sin(math.radians(-0.003)),
    )
    out = chain([Contour((Line(a, speck.start),), False), Contour((speck,), False)], 0.01)
    assert len(out) == 1
    assert sum(s.length for s in out[0].segments) < 0.02


# -- a loop the chain passes through: taken out closed ------------------------------------------


def _lines(ends: list[tuple[tuple[float, float], tuple[float, float]]]) -> list[Contour]:
    return [Contour((Line(a, b),), False, "0", f"LINE #{k}") for k, (a, b) in enumerate(ends, 1)]


def _continuous(contour: Contour) -> bool:
    segs = contour.segments
    inner = all(a.end == b.start for a, b in itertools.pairwise(segs))
    return inner and (not contour.closed or segs[-1].end == segs[0].start)


TAIL_AND_THREE_SIDES = [
    ((-1.0, 0.0), (0.0, 0.0)),
    ((0.0, 0.0), (1.0, 0.0)),
    ((1.0, 0.0), (1.0, 1.0)),
    ((1.0, 1.0), (0.0, 1.0)),
]
"""A 1 mm tail ending at (0, 0), then a unit square's sides from there, all but the last."""


def test_a_square_with_a_tail_at_its_corner_is_a_closed_square_and_an_open_tail() -> None:
    # The tail comes first, so the chain starts on it, runs round the square back to (0, 0)
    # and ends there: one open chain with the square inside, which a side offset left out.
    pieces = _lines([*TAIL_AND_THREE_SIDES, ((0.0, 1.0), (0.0, 0.0))])
    joined, members = chain_members(pieces, 0.01)
    assert [c.closed for c in joined] == [False, True]
    assert members[0] == (0,) and sorted(members[1]) == [1, 2, 3, 4]
    tail, square = joined
    assert tail.source == "LINE #1" and square.source == "LINE #2"  # its lowest piece
    assert len(square.segments) == 4 and _continuous(square)
    assert abs(enclosed(square.points(0.01)).area - 1.0) < 1e-12


def test_a_loop_closing_a_joint_off_its_start_is_closed_exactly_and_the_rest_joins_on() -> None:
    # The square's last side ends 0.6 µm short of (0, 0), within LOOP_JOINT_MM (1 µm);
    # a line then leaves from there: the line must start where the rest of the chain ends.
    pieces = _lines(
        [*TAIL_AND_THREE_SIDES, ((0.0, 1.0), (0.0, 0.0006)), ((0.0, 0.0006), (0.0, -2.0))]
    )
    joined, members = chain_members(pieces, 0.01)
    assert [c.closed for c in joined] == [False, True]
    rest, square = joined
    assert sorted(members[0]) == [0, 5] and sorted(members[1]) == [1, 2, 3, 4]
    assert _continuous(rest) and _continuous(square)
    assert [s.start for s in rest.segments] == [(-1.0, 0.0), (0.0, 0.0)]
    assert rest.end == (0.0, -2.0) and square.start == (0.0, 0.0)


def test_three_bands_drawn_as_lines_give_two_closed_bands_and_the_middle_s_open_sides() -> None:
    # A DIP-8 footprint's silkscreen (fritzing-parts' svg/core/pcb/sparkfun-digitalic_dil08_
    # pcb.svg, in its SVG units, Y down): a 10.16 mm square cut into three bands by two
    # lines across, its left side notched by a semicircle. The top band comes first and
    # closes; the chain from the bottom band's first line runs round the bottom band and,
    # at its corner (10.2616, 7.6962), on up the middle band's right side: the bottom band
    # was buried in an open chain, which a side offset leaves out.
    x0, x1, ys = 0.1016, 10.2616, (0.0762, 2.6162, 7.6962, 10.2362)
    ends = [
        ((x1, ys[0]), (x0, ys[0])),
        ((x0, ys[3]), (x1, ys[3])),
        ((x1, ys[0]), (x1, ys[1])),
        ((x0, ys[0]), (x0, ys[1])),
        ((x0, ys[3]), (x0, ys[2])),
        ((x0, ys[1]), (x1, ys[1])),
        ((x0, ys[1]), (x0, 4.1402)),
        ((x1, ys[1]), (x1, ys[2])),
        ((x0, ys[2]), (x1, ys[2])),
        ((x0, ys[2]), (x0, 6.1722)),
        ((x1, ys[2]), (x1, ys[3])),
    ]
    pieces = _lines(ends)
    notch = Arc((x0, 6.1722), (x0, 4.1402), (x0, 5.1562), True)
    pieces.insert(5, Contour((notch,), False, "0", "path[1]"))
    joined = chain(pieces, 0.01)
    closed = sorted(c.bbox() for c in joined if c.closed)
    band = pytest.approx
    assert closed == [band((x0, ys[0], x1, ys[1])), band((x0, ys[2], x1, ys[3]))]
    assert all(_continuous(c) for c in joined)
    sides = {frozenset((c.start, c.end)): c for c in joined if not c.closed}
    right, left = frozenset({(x1, ys[1]), (x1, ys[2])}), frozenset({(x0, ys[1]), (x0, ys[2])})
    assert set(sides) == {right, left}
    assert len(sides[right].segments) == 1 and len(sides[left].segments) == 3
    assert sum(len(c.segments) for c in joined) == len(pieces)
    # what --offset outside leaves out: the middle band's sides (the notch is piece 5)
    left_out = chained(pieces, PlanOptions(offset="outside", tool_diameter=0.2))[2]
    assert left_out == {5, 7, 8, 10}


def test_a_chain_that_closes_through_a_point_it_passes_stays_one_figure_of_eight() -> None:
    # two triangles tip to tip drawn as one run of six lines, as LibreCAD's Gunn diode
    tip = (0.0, 20.0)
    corners = [tip, (-5.0, 10.0), (5.0, 10.0), tip, (-5.0, 30.0), (5.0, 30.0), tip]
    pieces = _lines(list(itertools.pairwise(corners)))
    ((joined,), members) = chain_members(pieces, 0.01)
    assert joined.closed and len(joined.segments) == 6 and sorted(members[0]) == list(range(6))


def test_a_long_tail_s_loop_is_found_among_many_joints() -> None:
    # 15 lines of zigzag, then a unit square at its end: 20 joints, more than are
    # compared pair by pair, so the loop is first found by binning them in grids
    zig = [(float(k), float(k % 2)) for k in range(16)]
    x, y = zig[-1]
    corners = [(x, y), (x + 1.0, y), (x + 1.0, y + 1.0), (x, y + 1.0), (x, y)]
    ends = list(itertools.pairwise(zig)) + list(itertools.pairwise(corners))
    joined, members = chain_members(_lines(ends), 0.001)
    assert [c.closed for c in joined] == [False, True]
    assert members[0] == tuple(range(15)) and sorted(members[1]) == [15, 16, 17, 18]
    assert joined[1].bbox() == (x, y, x + 1.0, y + 1.0)


def test_a_wide_chaining_tolerance_makes_no_loop_of_details_smaller_than_it() -> None:
    # An open 270° arc of radius 2.5 drawn as 60 LINEs of 0.196 mm (2.5 × 2 sin 2.25°),
    # chained at 0.5 mm (a value the gap warnings suggest): every other joint lies within
    # 0.5 mm of the one before, but no piece meets there. One open chain, as drawn.
    corners = [
        (10.0 + 2.5 * math.cos(math.radians(4.5 * k)), 10.0 + 2.5 * math.sin(math.radians(4.5 * k)))
        for k in range(61)
    ]
    joined, members = chain_members(_lines(list(itertools.pairwise(corners))), 0.5)
    assert [c.closed for c in joined] == [False] and members[0] == tuple(range(60))
    assert [s.start for s in joined[0].segments] == corners[:-1]


def test_a_wide_chain_tolerance_does_not_snap_a_line_onto_another_lengths_away() -> None:
    # Two 10 mm lines 50 mm apart at a 100 mm tolerance: snapped end to end they would
    # make a line there and back (one of them never cut). A gap of more than half of
    # a piece's length is no joint; the lines stay as drawn, each open.
    lines = _lines([((0.0, 0.0), (10.0, 0.0)), ((60.0, 0.0), (70.0, 0.0))])
    out = chain(lines, 100.0)
    assert [(c.closed, c.start, c.end) for c in out] == [
        (False, (0.0, 0.0), (10.0, 0.0)),
        (False, (60.0, 0.0), (70.0, 0.0)),
    ]
    # a square drawn open by 0.5 mm at one corner (40 mm round) still closes at 0.6 mm,
    # and pieces 10 mm long still join across 0.5 mm gaps
    sides = [((0.5, 0.0), (10.0, 0.0)), ((10.0, 0.0), (10.0, 10.0)), ((10.0, 10.0), (0.0, 10.0))]
    square = _lines([*sides, ((0.0, 10.0), (0.0, 0.0))])
    assert [c.closed for c in chain(square, 0.6)] == [True]
    apart = _lines([((0.0, 0.0), (10.0, 0.0)), ((10.5, 0.0), (20.0, 0.0))])
    joined = chain(apart, 0.6)
    assert len(joined) == 1
    assert (joined[0].start, joined[0].end) == ((0.0, 0.0), (20.0, 0.0))
    # but a chain shorter than twice its closing gap does not close
    corner = _lines([((0.0, 0.0), (1.0, 0.0)), ((1.0, 0.0), (1.0, 1.0))])
    assert [c.closed for c in chain(corner, 2.0)] == [False]
