"""Closing gaps, tool compensation, exact offsets, fallback and findings, against analytic values.

The expected numbers are geometry, not thesis figures (STYLE 12: "a 10 mm circle offset by
1 mm has radius 6 mm"): an offset by the tool radius r moves every edge by r, turns convex
corners into arcs of radius r and keeps concave corners sharp.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from typing import Any

import numpy as np
import pytest

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Arc, Contour, Line
from camtool.toolpath import compensate as compensate_module
from camtool.toolpath import offset as offset_module
from camtool.toolpath.chain import close_gaps
from camtool.toolpath.compensate import compensate, shape_key, tight_corners
from camtool.toolpath.cuts import Stage
from camtool.toolpath.offset import offset_checked, offset_contour, offset_pieces
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting
from tests.shapes import segment_samples
from tests.toolpath.contours import (
    ccw,
    circle,
    dumbbell,
    l_shape,
    radius_of,
    rect,
    stadium,
    two_way_distance,
)

TOL = 0.001


def _run(contours: list[Contour], offset: str, diameter: float = 2.0, **kw: Any) -> Stage:
    options = PlanOptions(offset=offset, tool_diameter=diameter, feed_mm_min=100.0, **kw)
    return compensate(contours, nesting(contours), options)


def _kinds(stage: Stage) -> list[str]:
    return [f.kind for f in stage.findings]


# --- close_gaps ------------------------------------------------------------------------------


def _open_square(gap: float) -> Contour:
    """A 1 × 1 square drawn open: it ends ``gap`` mm short of its start."""
    pts = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, gap)]
    return Contour(tuple(Line(a, b) for a, b in itertools.pairwise(pts)), False)


def test_a_gap_within_the_default_is_closed_with_a_line_and_reported() -> None:
    contour = _open_square(0.01)
    (closed,), (finding,) = close_gaps([contour], 0.02, TOL)
    assert closed.closed and closed.segments[:4] == contour.segments  # drawn segments exact
    assert closed.segments[-1] == Line((0.0, 0.01), (0.0, 0.0))
    assert finding.kind == "closed-gap"
    assert finding.value == pytest.approx(0.01)
    assert finding.at == pytest.approx((0.0, 0.005))
    assert "0.01 mm" in finding.message and "--close-gap 0" in finding.message


@pytest.mark.parametrize("gap, max_gap", [(0.03, 0.02), (0.01, 0.0), (0.0005, 0.02)])
def test_gaps_outside_the_window_stay_open(gap: float, max_gap: float) -> None:
    contour = _open_square(gap)
    out, found = close_gaps([contour], max_gap, TOL)
    assert out == [contour] and found == []


def test_a_c_shape_is_not_closed() -> None:
    # A "C" of radius 0.02 mm over 300°: its 0.02 mm gap is 19 % of its 0.105 mm length.
    r = 0.02
    a, b = math.radians(30), math.radians(330)
    arc = Arc((r * math.cos(a), r * math.sin(a)), (r * math.cos(b), r * math.sin(b)), (0, 0), False)
    contour = Contour((arc,), False)
    out, found = close_gaps([contour], 0.02, TOL)
    assert out == [contour] and found == []


# --- exact offsets ---------------------------------------------------------------------------


@pytest.mark.parametrize("offset, radius", [("outside", 6.0), ("inside", 4.0)])
def test_circle_offset_by_the_tool_radius(offset: str, radius: float) -> None:
    (cut,) = _run([circle(0, 0, 5)], offset).cuts
    assert all(isinstance(s, Arc) and s.radius == pytest.approx(radius) for s in cut.path.segments)
    assert sum(abs(s.sweep) for s in cut.path.segments if isinstance(s, Arc)) == pytest.approx(
        2 * math.pi
    )


def test_rectangle_outside_has_corner_arcs_and_grows_by_the_diameter() -> None:
    (cut,) = _run([rect(0, 0, 10, 5)], "outside", 2.0).cuts
    arcs = [s for s in cut.path.segments if isinstance(s, Arc)]
    assert len(arcs) == 4 and all(a.radius == pytest.approx(1.0) for a in arcs)
    x0, y0, x1, y1 = cut.path.bbox()
    assert (x1 - x0, y1 - y0) == (pytest.approx(12.0), pytest.approx(7.0))
    # area of a rectangle grown by r: w·h + 2r(w + h) + π r²
    assert abs(cut.path.signed_area()) == pytest.approx(50 + 2 * 15 + math.pi, abs=1e-3)


def test_only_the_loop_around_an_outside_profile_frees_the_part() -> None:
    """A square ring with a 1 mm slit: the 3 mm tool cannot enter the slit, so the outward
    offset is a loop around the ring and one inside its 10 mm hole (1.5 mm in from its
    sides). Only the loop around cuts the part free: it alone
    is an outside profile (tabs, leads); the loop inside clears the hole."""
    pts = [(0, 0), (9.5, 0), (9.5, 5), (5, 5), (5, 15), (15, 15), (15, 5), (10.5, 5)]
    pts += [(10.5, 0), (20, 0), (20, 20), (0, 20), (0, 0)]
    ring = Contour(tuple(Line(a, b) for a, b in itertools.pairwise(pts)), True)
    cuts = _run([ring], "outside", 3.0).cuts
    boxes = {c.outside_profile: c.path.bbox() for c in cuts}
    assert len(cuts) == 2 and set(boxes) == {True, False}
    assert boxes[True] == pytest.approx((-1.5, -1.5, 21.5, 21.5))
    # over the slit's mouth the tool reaches down to 1.5 mm from its corners (9.5, 5) and
    # (10.5, 5): y = 5 + √(1.5² − 0.5²) = 5 + √2
    assert boxes[False] == pytest.approx((6.5, 5 + math.sqrt(2.0), 13.5, 13.5))


def test_rectangle_inside_shrinks_by_the_diameter_with_sharp_corners() -> None:
    (cut,) = _run([rect(0, 0, 10, 5)], "inside", 2.0).cuts
    assert all(isinstance(s, Line) for s in cut.path.segments)
    assert cut.path.bbox() == pytest.approx((1.0, 1.0, 9.0, 4.0))


@pytest.mark.parametrize("offset, r_end", [("outside", 4.0), ("inside", 2.0)])
def test_slot_offsets_keep_straight_sides_and_round_ends(offset: str, r_end: float) -> None:
    (cut,) = _run([stadium(0, 20, 0, 3)], offset, 2.0).cuts
    lines = [s for s in cut.path.segments if isinstance(s, Line)]
    arcs = [s for s in cut.path.segments if isinstance(s, Arc)]
    assert sorted(s.length for s in lines) == pytest.approx([20.0, 20.0])
    assert all(a.radius == pytest.approx(r_end) for a in arcs)
    assert sum(abs(a.sweep) for a in arcs) == pytest.approx(2 * math.pi)


def _part_with_hole(**kw: Any) -> Stage:
    return _run([rect(0, 0, 20, 10), circle(10, 5, 3)], "outside", 2.0, **kw)


def test_outer_grows_hole_shrinks_climb_runs_outer_cw_hole_ccw() -> None:
    outer, hole = _part_with_hole().cuts
    assert outer.path.bbox() == pytest.approx((-1, -1, 21, 11))
    assert {round(radius_of(s), 9) for s in hole.path.segments} == {2.0}
    assert not ccw(outer.path) and ccw(hole.path)
    assert (outer.material_side, hole.material_side) == ("right", "right")
    assert (outer.outside_profile, hole.outside_profile) == (True, False)
    assert not outer.may_reverse and outer.may_rotate and (outer.group, hole.group) == (0, 1)


def test_conventional_runs_the_other_way() -> None:
    outer, hole = _part_with_hole(direction="conventional").cuts
    assert ccw(outer.path) and not ccw(hole.path)
    assert (outer.material_side, hole.material_side) == ("left", "left")


def test_inside_swaps_the_sides() -> None:
    outer, hole = _run([rect(0, 0, 20, 10), circle(10, 5, 3)], "inside", 2.0).cuts
    assert outer.path.bbox() == pytest.approx((1, 1, 19, 9))
    assert {round(radius_of(s), 9) for s in hole.path.segments} == {4.0}
    # climb: material (outside the outer boundary, inside the hole) on the right
    assert ccw(outer.path) and not ccw(hole.path)
    assert not outer.outside_profile


def test_on_keeps_the_drawn_direction_unless_one_is_asked() -> None:
    drawn = [rect(0, 0, 20, 10), circle(10, 5, 3).reversed()]
    free = _run(drawn, "on", 0.0).cuts
    assert [c.path for c in free] == drawn
    assert all(c.may_reverse and c.material_side is None for c in free)
    climb = _run(drawn, "on", 0.0, direction="climb").cuts
    assert [ccw(c.path) for c in climb] == [False, True]  # as for outside
    assert all(not c.may_reverse and c.material_side == "right" for c in climb)


def test_open_contours_are_cut_on_the_line_only_with_offset_on() -> None:
    line = Contour((Line((30, 0), (40, 0)),), False, "CUT", "LINE #2A")
    stage = _run([rect(0, 0, 10, 10), line], "outside")
    # an open contour has no outside: cut on its line it would cut through the part
    assert [c.kind for c in stage.cuts] == ["profile"]
    (finding,) = [f for f in stage.findings if f.kind == "open-left-out"]
    assert finding.message.startswith("not cut: open contour LINE #2A at (30.0000, 0.0000) mm")
    assert "layer 'CUT'" in finding.message and "--offset outside" in finding.message
    assert finding.at == (30, 0) and finding.value == 10
    on = _run([rect(0, 0, 10, 10), line], "on", 0.0)
    cut = on.cuts[1]
    # drawn direction by default: an open path is never reversed by the ordering
    assert (cut.kind, cut.path, cut.may_rotate, cut.may_reverse) == ("open", line, False, False)
    assert _run([line], "on", 0.0, reverse_open=True).cuts[0].may_reverse
    assert "open-left-out" not in _kinds(on)


def test_only_open_contours_under_a_side_is_nothing_to_cut() -> None:
    line = Contour((Line((30, 0), (40, 0)),), False, "CUT")
    with pytest.raises(ToolpathError, match=r"the 1 contour is open \(on layer 'CUT'\)"):
        _run([line], "inside")


def test_many_open_contours_are_named_ten_then_counted() -> None:
    lines = [Contour((Line((30, k), (40, k)),), False) for k in range(13)]
    stage = _run([rect(0, 0, 10, 10), *lines], "outside")
    found = [f for f in stage.findings if f.kind == "open-left-out"]
    assert len(found) == 11
    assert found[-1].message.startswith("not cut: 3 more open contour(s)")


# --- split and vanished offsets --------------------------------------------------------------


def test_dumbbell_shrunk_past_its_waist_gives_two_pieces() -> None:
    # Waist 2 mm wide, shrunk by r = 1.2 mm: two 7.6 × 7.6 mm squares, each with a bump
    # toward the waist bounded by circles of r around the waist corners (10, 4) and (10, 6):
    # bump = 2·∫₀¹ (r − √(r² − t²)) dt.
    pieces = offset_pieces(dumbbell(), -1.2)
    assert len(pieces) == 2 and all(ccw(p) for p in pieces)
    r = 1.2
    segment = 0.5 * math.sqrt(r * r - 1) + r * r / 2 * math.asin(1 / r)  # ∫₀¹ √(r² − t²) dt
    for p in pieces:
        assert p.signed_area() == pytest.approx(7.6 * 7.6 + 2 * (r - segment), abs=1e-6)
    with pytest.raises(ToolpathError, match="splits into 2 pieces"):
        offset_contour(dumbbell(), -1.2)
    stage = _run([dumbbell()], "inside", 2.4)
    assert len(stage.cuts) == 2 and {c.group for c in stage.cuts} == {0}


def test_a_slot_narrower_than_the_tool_vanishes_with_its_location() -> None:
    slot = stadium(30, 40, 5, 1.0)  # 2 mm wide, a hole in the part, tool 3 mm
    stage = _run([rect(0, 0, 50, 10), slot], "outside", 3.0)
    assert [c.group for c in stage.cuts] == [0]  # the part is still cut
    (finding,) = [f for f in stage.findings if f.kind == "offset-vanished"]
    assert finding.at == pytest.approx((35.0, 5.0), abs=1e-6)
    assert finding.value == pytest.approx(2.0, abs=2 * TOL)
    assert "(35.0000, 5.0000)" in finding.message and "3 mm tool" in finding.message


def test_a_closed_contour_without_area_vanishes_without_a_crash() -> None:
    """A line drawn out and back (LibreCAD's ed119.dxf has two) encloses no area.

    Inside the part it is a hole no tool fits: an ``offset-vanished`` finding at its
    start with width 0, not GEOS's "Empty input" from the width measure.
    """
    out_and_back = (Line((20.0, 5.0), (30.0, 5.0)), Line((30.0, 5.0), (20.0, 5.0)))
    there_and_back = Contour(out_and_back, closed=True)
    stage = _run([rect(0, 0, 50, 10), there_and_back], "outside", 1.0)
    assert [c.group for c in stage.cuts] == [0]  # the part is still cut
    (finding,) = [f for f in stage.findings if f.kind == "offset-vanished"]
    assert finding.at == (20.0, 5.0) and finding.value == 0.0
    assert "(20.0000, 5.0000)" in finding.message and "1 mm tool" in finding.message


def test_an_arc_drawn_there_and_back_vanishes_as_a_line_does() -> None:
    """Two copies of one ARC chain into a closed contour of no area (LibreCAD's
    ``power_station/ed128.dxf`` draws its bottom half-circle twice). Its chords one way
    and the other differ by roundings: the slivers between them are no area either, not a
    region to cut round (as slots along the arc).
    """
    ccw = Arc((20.0, 5.0), (30.0, 5.0), (25.0, 5.0), False)
    there_and_back = Contour((ccw, Arc((30.0, 5.0), (20.0, 5.0), (25.0, 5.0), True)), True)
    for side in ("outside", "inside"):
        stage = _run([rect(0, 0, 50, 10), there_and_back], side, 1.0)
        assert [c.group for c in stage.cuts] == [0]  # the part is cut, nothing at the arc
        (finding,) = [f for f in stage.findings if f.kind == "offset-vanished"]
        assert finding.at == (20.0, 5.0) and finding.value == 0.0
        assert not [f for f in stage.findings if f.kind in ("self-crossing", "offset-fallback")]


def test_when_everything_vanishes_planning_stops_with_the_reason() -> None:
    with pytest.raises(ToolpathError, match=r"nothing left to cut.*narrower than the 3 mm tool"):
        _run([stadium(30, 40, 5, 1.0)], "inside", 3.0)


def test_only_open_contours_name_their_layers_as_a_user_reads_them() -> None:
    """QCAD's 181_polyline.dxf: one open polyline on layer 0, "(on layer '0')" not "(layers 0)"."""
    one = [Contour((Line((0.0, 0.0), (10.0, 0.0)),), False, layer="0")]
    with pytest.raises(ToolpathError) as caught:
        _run(one, "outside")
    assert "nothing to cut: the 1 contour is open (on layer '0')" in str(caught.value)
    assert "cut it on its lines" in str(caught.value)
    many = [
        Contour((Line((0.0, k), (10.0, k)),), False, layer=name) for k, name in enumerate("ABCDE")
    ]
    with pytest.raises(ToolpathError) as caught:
        _run(many, "inside")
    assert "all 5 contours are open (on layers 'A', 'B', 'C' and 2 more)" in str(caught.value)


def test_the_error_names_the_first_vanished_contours_and_counts_the_rest() -> None:
    """Twelve slots, 2 mm wide and one 1.6 mm, under a 3 mm tool: a line a user can read.

    Each slot's width is twice its end radius (analysis), so the narrowest is 1.6 mm.
    """
    slots = [stadium(30, 40, 5 + 5 * k, 0.8 if k == 7 else 1.0) for k in range(12)]
    with pytest.raises(ToolpathError) as caught:
        _run(slots, "inside", 3.0)
    message = str(caught.value)
    assert message.count("narrower than the 3 mm tool") == compensate_module.MAX_IN_ERROR == 3
    assert "and 9 more closed contour(s) the tool does not fit in" in message
    assert "(12 in all, the narrowest about 1.6 mm wide)" in message


# --- fallback --------------------------------------------------------------------------------


def _occt_fails(*args: Any) -> Any:
    raise RuntimeError("StdFail_NotDone")


@pytest.mark.parametrize(
    "contour, amount",
    [(circle(0, 0, 5), 1.0), (rect(0, 0, 10, 5), 0.5), (l_shape(), 1.0), (dumbbell(), -1.2)],
)
def test_fallback_is_within_tolerance_of_the_exact_offset(
    monkeypatch: pytest.MonkeyPatch, contour: Contour, amount: float
) -> None:
    exact = offset_pieces(contour, amount)
    monkeypatch.setattr(offset_module, "_occt_offset", _occt_fails)
    result = offset_checked(contour, amount, TOL)
    assert result.fallback is not None and "StdFail_NotDone" in result.fallback
    assert len(result.pieces) == len(exact)
    assert [ccw(p) for p in result.pieces] == [ccw(p) for p in exact]
    assert two_way_distance(result.pieces, exact) <= TOL
    assert any(isinstance(s, Arc) for p in result.pieces for s in p.segments)


def test_fallback_is_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(offset_module, "_occt_offset", _occt_fails)
    stage = _run([circle(0, 0, 5)], "outside", 2.0)
    (finding,) = stage.findings
    assert finding.kind == "offset-fallback" and finding.at == (5, 0)
    assert "OpenCASCADE could not offset it (" in finding.message
    assert "within 0.001 mm" in finding.message
    (cut,) = stage.cuts
    radii = np.hypot(*segment_samples(cut.path.segments).T)
    assert np.all(np.abs(radii - 6.0) <= TOL)  # the 10 mm circle grown by 1 mm


def test_an_offset_that_does_not_grow_is_replaced(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(offset_module, "offset_pieces", lambda c, a: [c])
    result = offset_checked(rect(0, 0, 10, 5), 0.5, TOL)
    assert result.fallback is not None and "area" in result.fallback
    assert abs(result.pieces[0].signed_area()) == pytest.approx(50 + 15 + math.pi / 4, abs=0.01)


# --- tight corners ---------------------------------------------------------------------------


def _notched() -> Contour:
    """A 10 × 10 square with a semicircular notch of radius 0.5 in its top edge."""
    segs = (
        Line((0, 0), (10, 0)),
        Line((10, 0), (10, 10)),
        Line((10, 10), (5.5, 10)),
        Arc((5.5, 10), (4.5, 10), (5, 10), True),  # dips into the square
        Line((4.5, 10), (0, 10)),
        Line((0, 10), (0, 0)),
    )
    return Contour(segs, True)


@pytest.mark.parametrize(
    "contours, offset, count",
    [
        ([l_shape()], "outside", 1),
        ([rect(0, 0, 20, 20), rect(5, 5, 10, 10)], "outside", 4),  # the tool is in the hole
        ([rect(0, 0, 10, 5)], "outside", 0),
        ([rect(0, 0, 30, 10), stadium(5, 15, 5, 2.0)], "outside", 0),  # ends r 2 > 1
        ([_notched()], "outside", 1),  # the notch's r 0.5 < 1
        ([rect(0, 0, 10, 5)], "inside", 4),
    ],
)
def test_tight_corners_are_counted_once_per_contour(
    contours: list[Contour], offset: str, count: int
) -> None:
    stage = _run(contours, offset, 2.0)
    found = [f for f in stage.findings if f.kind == "tight-corner"]
    assert sum(f.value or 0 for f in found) == count
    assert len(found) == (1 if count else 0)


def test_tight_corner_names_the_first_corner_and_the_radius() -> None:
    (finding,) = _run([l_shape()], "outside", 3.0).findings
    assert finding.at == (3, 3)
    assert "1 inside corner tighter than the 1.5 mm tool radius (first at (3.0000, 3.0000)" in (
        finding.message
    )
    assert tight_corners(l_shape(), inside=True, radius=1.5, tolerance=TOL) == [
        (0, 0), (10, 0), (10, 3), (3, 10), (0, 10)
    ]  # fmt: skip


# --- gouge -----------------------------------------------------------------------------------


def test_parts_closer_than_the_tool_are_gouged() -> None:
    # Two 10 mm squares 2 mm apart, tool 3 mm: each path sweeps 3 mm from its square, 1 mm
    # into the other one: a 1 × 10 mm band (10 mm²) on each side of the gap.
    stage = _run([rect(0, 0, 10, 10), rect(12, 0, 22, 10)], "outside", 3.0)
    gouges = sorted((f for f in stage.findings if f.kind == "gouge"), key=lambda f: f.at or ())
    assert [g.at for g in gouges] == [pytest.approx((9.5, 5)), pytest.approx((12.5, 5))]
    assert [g.value for g in gouges] == [pytest.approx(10, rel=1e-3)] * 2
    assert "cuts into the part around (9.5000, 5.0000)" in gouges[0].message


def test_a_wall_between_holes_thinner_than_the_tool_is_gouged_inside() -> None:
    # Holes 1 mm apart cut inside (holes grow): each 3 mm tool sweeps 2 mm into the other.
    holes = [rect(-20, -20, 40, 30), rect(0, 0, 10, 10), rect(11, 0, 21, 10)]
    stage = _run(holes, "inside", 3.0)
    areas = [f.value for f in stage.findings if f.kind == "gouge"]
    assert len(areas) == 2 and all(a == pytest.approx(20, rel=1e-3) for a in areas)


def test_correct_offsets_do_not_gouge() -> None:
    # walls and gaps of 3 mm or more, tool 2.5 mm
    l_part = l_shape().transformed(1.0, 30, 0)
    contours = [rect(0, 0, 10, 10), rect(14, 0, 24, 10), rect(3, 3, 7, 7), l_part]
    for offset in ("outside", "inside"):
        kinds = _kinds(_run(contours, offset, 2.5))
        assert "gouge" not in kinds and "offset-fallback" not in kinds


# --- panels: one offset per shape ------------------------------------------------------------


def _panel(copies: int) -> list[Contour]:
    """``copies`` stadium slots, 30 mm right and 15 mm up of each other, each with a hole,
    each on its own layer."""
    out: list[Contour] = []
    for k in range(copies):
        dx, dy = 30.0 * k, 15.0 * k
        for contour in (stadium(dx, dx + 20, dy, 4), circle(dx + 10, dy, 2)):
            out.append(dataclasses.replace(contour, layer=f"P{k}", source=f"#{k}"))
    return out


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Wrap compensate's ``offset_all``: the number of offsets asked for in each call."""
    calls: list[int] = []
    real = compensate_module.offset_all

    def counted(items: Any, **kw: Any) -> Any:
        calls.append(len(items))
        return real(items, **kw)

    monkeypatch.setattr(compensate_module, "offset_all", counted)
    return calls


def test_a_panel_offsets_each_shape_once_and_moves_it_onto_the_copies(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls = _counting(monkeypatch)
    stage = _run(_panel(4), "outside", 2.0)
    assert calls == [2]  # one slot and one hole, not eight contours
    assert len(stage.cuts) == 8
    for k in range(4):
        dx, dy = 30.0 * k, 15.0 * k
        slot, hole = (c for c in stage.cuts if c.path.layer == f"P{k}")
        # analytic: the slot grown by r = 1 and the hole shrunk by it
        assert slot.path.bbox() == pytest.approx((dx - 5, dy - 5, dx + 25, dy + 5))
        assert hole.path.bbox() == pytest.approx((dx + 9, dy - 1, dx + 11, dy + 1))
        assert slot.path.source == hole.path.source == f"#{k}"


def test_a_moved_offset_is_the_copys_own_offset() -> None:
    together = _run(_panel(3), "outside", 2.0).cuts
    for k in range(3):
        alone = _run(_panel(3)[2 * k : 2 * k + 2], "outside", 2.0).cuts
        mine = [c for c in together if c.path.layer == f"P{k}"]
        assert [ccw(c.path) for c in mine] == [ccw(c.path) for c in alone]
        assert two_way_distance([c.path for c in mine], [c.path for c in alone]) <= 1e-9


def test_a_fallback_is_moved_onto_the_copies_too(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(offset_module, "_occt_offset", _occt_fails)
    calls = _counting(monkeypatch)
    stage = _run(_panel(3), "outside", 2.0)
    assert calls == [2]
    assert sum(f.kind == "offset-fallback" for f in stage.findings) == 6  # one per contour
    for k in range(3):
        dx, dy = 30.0 * k, 15.0 * k
        _slot, hole = (c for c in stage.cuts if c.path.layer == f"P{k}")
        radii = np.hypot(*(segment_samples(hole.path.segments) - (dx + 10, dy)).T)
        assert np.all(np.abs(radii - 1.0) <= TOL)  # the hole of radius 2 shrunk by 1


def test_without_a_checked_offset_the_copies_are_offset_each(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls: list[int] = []
    real = compensate_module.offset_all

    def worker_died(items: Any, **kw: Any) -> Any:
        calls.append(len(items))
        if len(calls) == 1:
            return [ToolpathError("the offsets' worker died (SIGSEGV)")] * len(items)
        return real(items, **kw)

    monkeypatch.setattr(compensate_module, "offset_all", worker_died)
    stage = _run(_panel(3), "outside", 2.0)
    assert calls == [2, 4]  # the two shapes, then the four copies of theirs
    assert len(stage.cuts) == 6
    for k in range(3):
        dx, dy = 30.0 * k, 15.0 * k
        slot, hole = (c for c in stage.cuts if c.path.layer == f"P{k}")
        assert slot.path.bbox() == pytest.approx((dx - 5, dy - 5, dx + 25, dy + 5), abs=TOL)
        assert hole.path.bbox() == pytest.approx((dx + 9, dy - 1, dx + 11, dy + 1), abs=TOL)


def test_mirrored_or_shifted_shapes_are_not_one_shape() -> None:
    square = rect(0, 0, 10, 10)
    assert shape_key(square) == shape_key(square.transformed(1.0, 123.456, -7.0))
    assert shape_key(square) != shape_key(rect(0, 0, 10, 10.001))
    assert shape_key(square) != shape_key(square.reversed())
