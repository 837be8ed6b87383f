"""Chaining, offsets and ordering, against analytic expectations."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from camtool.geometry.chain import chain
from camtool.importers.dxf import read_dxf
from camtool.model.errors import ToolpathError, UsageError
from camtool.model.program import ArcMove, Rapid
from camtool.model.shapes import Arc, Contour, Drawing, Line
from camtool.toolpath.compensate import compensate
from camtool.toolpath.offset import offset_contour
from camtool.toolpath.order import nesting, order_cuts
from camtool.toolpath.plan import PlanOptions, plan
from tests.shapes import rectangle_dxf, write_dxf
from tests.toolpath.contours import circle, rect


def test_rectangle_outside_1mm_tool(tmp_path: Path) -> None:
    # Issue 2 §6: 10 × 5 rectangle, 1 mm tool outside → four r = 0.5 corner arcs, 11 × 6 box.
    out = offset_contour(rect(0, 0, 10, 5), 0.5)
    arcs = [s for s in out.segments if isinstance(s, Arc)]
    assert len(arcs) == 4 and len(out.segments) == 8
    assert all(a.radius == pytest.approx(0.5) for a in arcs)
    x0, y0, x1, y1 = out.bbox()
    assert (x1 - x0, y1 - y0) == (pytest.approx(11.0), pytest.approx(6.0))


def test_rectangle_inside_1mm_tool() -> None:
    out = offset_contour(rect(0, 0, 10, 5), -0.5)
    assert all(isinstance(s, Line) for s in out.segments)
    x0, y0, x1, y1 = out.bbox()
    assert (x1 - x0, y1 - y0) == (pytest.approx(9.0), pytest.approx(4.0))


def test_offset_keeps_orientation_and_start() -> None:
    cw = rect(0, 0, 10, 5).reversed()
    out = offset_contour(cw, 0.5)
    assert out.signed_area() < 0
    assert math.dist(out.start, cw.start) <= 0.5 + 1e-9


def test_circle_offsets_stay_exact_arcs() -> None:
    # A 10 mm circle offset by 1 mm has radius 6 mm (STYLE 12), and 4 mm inside.
    for amount, radius in ((1.0, 6.0), (-1.0, 4.0)):
        out = offset_contour(circle(0, 0, 5), amount)
        assert all(isinstance(s, Arc) and s.radius == pytest.approx(radius) for s in out.segments)
        assert sum(abs(s.sweep) for s in out.segments if isinstance(s, Arc)) == pytest.approx(
            2 * math.pi
        )


def test_offset_too_deep_is_reported_with_location() -> None:
    with pytest.raises(ToolpathError, match=r"starting at \(0.0000, 0.0000\)"):
        offset_contour(rect(0, 0, 1, 1), -0.6)


def test_chain_joins_lines_within_tolerance_and_closes() -> None:
    gap = 0.0005
    pieces = [
        Contour((Line((0, 0), (1, 0)),), False),
        Contour((Line((1, 1), (1 + gap, 0)),), False),  # drawn backwards, end meets with a gap
        Contour((Line((1, 1), (0, 0 + gap)),), False),
    ]
    (c,) = chain(pieces, 0.001)
    assert c.closed and len(c.segments) == 3
    for a, b in zip(c.segments, c.segments[1:] + c.segments[:1], strict=True):
        assert a.end == b.start  # snapped exactly


def test_chain_leaves_far_ends_apart() -> None:
    pieces = [Contour((Line((0, 0), (1, 0)),), False), Contour((Line((1.01, 0), (2, 0)),), False)]
    assert len(chain(pieces, 0.001)) == 2


def test_inside_contours_are_cut_first() -> None:
    outer, hole, other = rect(0, 0, 10, 10), circle(5, 5, 1), rect(20, 0, 21, 1)
    contours = [outer, hole, other]
    nest = nesting(contours)
    assert nest.parents == ((), (0,), ())
    options = PlanOptions(feed_mm_min=1.0)
    ordering = order_cuts(compensate(contours, nest, options).cuts, nest, options, (0.0, 0.0))
    groups = [cut.group for cut in ordering.cuts]
    assert groups.index(1) < groups.index(0)


def test_outside_compensates_holes_inwards(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(1, 1), (9, 1), (9, 6), (1, 6)], close=True)
        msp.add_circle((5, 3.5), 1.0)

    drawing = read_dxf(write_dxf(tmp_path / "h.dxf", build))
    program = plan(drawing, PlanOptions(offset="outside", tool_diameter=0.4, feed_mm_min=1.0))
    radii = {
        round(math.dist((m.x, m.y), (m.cx, m.cy)), 6)
        for m in program.moves
        if isinstance(m, ArcMove) and m.contour == 1
    }
    assert radii == {0.8}  # the hole (cut first) shrinks by the tool radius
    x0, y0, x1, y1 = program.bbox(cutting_only=True)
    assert (x0, y0, x1, y1) == pytest.approx((0.8, 0.8, 9.2, 6.2))


def test_plan_one_rapid_per_contour(tmp_path: Path) -> None:
    drawing = read_dxf(rectangle_dxf(tmp_path / "r.dxf"))
    program = plan(drawing, PlanOptions(feed_mm_min=1.0))
    assert [type(m) for m in program.moves].count(Rapid) == 1
    assert program.cut_length() == pytest.approx(30.0)


def test_open_contours_with_a_side_are_left_out_with_a_warning(tmp_path: Path) -> None:
    options = PlanOptions(offset="outside", tool_diameter=1.0, feed_mm_min=1.0)
    drawing = Drawing((rect(0, 0, 10, 10), Contour((Line((0, 0), (1, 0)),), False)))
    program = plan(drawing, options)
    assert any(w.startswith("not cut: open contour") for w in program.warnings)
    # the line from (0, 0) to (1, 0) lies on the square's edge: only the offset square is cut
    assert min(m.y for m in program.moves) == pytest.approx(-0.5)
    with pytest.raises(ToolpathError, match=r"the 1 contour is open \(on layer .0.\)"):
        plan(Drawing(drawing.contours[1:]), options)


@pytest.mark.parametrize(
    "kwargs",
    [{"offset": "outside"}, {"offset": "sideways"}, {"feed_mm_min": 0.0}, {"tolerance": 0.0}],
)
def test_plan_options_validated(kwargs: dict[str, Any]) -> None:
    base: dict[str, Any] = {"feed_mm_min": 1.0}
    with pytest.raises(UsageError):
        PlanOptions(**(base | kwargs))


def test_fit_scales_uniformly_about_the_lower_left_corner(tmp_path: Path) -> None:
    drawing = read_dxf(rectangle_dxf(tmp_path / "r.dxf", 10, 5))  # (1,1)–(11,6)
    program = plan(drawing, PlanOptions(feed_mm_min=1.0, fit=(4.0, 4.0)))
    assert program.bbox(cutting_only=True) == pytest.approx(
        (1.0, 1.0, 5.0, 3.0)
    )  # limited by the width


def test_fit_scales_what_is_cut_not_the_centre_lines_past_it(tmp_path: Path) -> None:
    """A 40 × 30 plate whose centre lines run 5 mm past it, and a border on its own layer.

    ``--fit 100 100`` fits the plate: 100 × 75 mm (factor 2.5, from its width), not the
    sheet's 297 mm border nor the 50 mm span of the centre lines (factor 2.0, 80 × 60).
    """
    import ezdxf

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.linetypes.add("CENTER", pattern=[2.0, 1.25, -0.25, 0.25, -0.25])
    msp = doc.modelspace()
    msp.add_lwpolyline([(10, 10), (50, 10), (50, 40), (10, 40)], close=True)
    msp.add_circle((30, 25), 5)
    msp.add_line((5, 25), (55, 25), dxfattribs={"linetype": "CENTER"})
    msp.add_line((30, 5), (30, 45), dxfattribs={"linetype": "CENTER"})
    doc.layers.add("Sheet Border")
    msp.add_lwpolyline(
        [(-100, -100), (197, -100), (197, 110), (-100, 110)],
        close=True,
        dxfattribs={"layer": "Sheet Border"},
    )
    path = tmp_path / "plate.dxf"
    doc.saveas(path)
    from camtool.jobs.pipeline import post_drawing
    from camtool.post.registry import load_target

    job = post_drawing(read_dxf(path), load_target("linuxcnc"), PlanOptions(fit=(100.0, 100.0)))
    assert job.program.bbox(cutting_only=True) == pytest.approx((10.0, 10.0, 110.0, 85.0))


def test_scale_about_the_origin(tmp_path: Path) -> None:
    drawing = read_dxf(rectangle_dxf(tmp_path / "r.dxf", 10, 5))
    program = plan(drawing, PlanOptions(feed_mm_min=1.0, scale=0.5))
    assert program.bbox(cutting_only=True) == pytest.approx((0.5, 0.5, 5.5, 3.0))


def test_scale_and_fit_exclude_each_other() -> None:
    with pytest.raises(UsageError, match="either --scale or --fit"):
        PlanOptions(feed_mm_min=1.0, scale=2.0, fit=(1.0, 1.0))


def test_a_single_arc_whose_ends_meet_is_closed() -> None:
    # Regression: an ARC drawn from 0° to 360° (or an OCCT full-circle edge) was left open.
    # Counter-clockwise from (2, 0) round to 0.0004 mm short of it: nearly the whole circle
    # (ending at (2, +0.0004) it would be a speck, which stays open: tests/geometry/test_chain.py).
    almost = Arc((2.0, 0.0), (2.0, -0.0004), (0.0, 0.0), False)
    (c,) = chain([Contour((almost,), False)], 0.001)
    assert c.closed
    assert isinstance(c.segments[0], Arc) and c.segments[0].is_full_circle


def test_nesting_of_open_contours_and_duplicates() -> None:
    square, twin = rect(0, 0, 4, 4), rect(0, 0, 4, 4)
    slot = Contour((Line((1, 1), (3, 1)),), False)
    outside = Contour((Line((5, 1), (6, 1)),), False)
    nest = nesting([square, twin, slot, outside])
    assert nest.parents == ((), (), (0, 1), ())  # duplicates never contain each other
    assert [nest.depth(i) for i in range(4)] == [0, 0, 2, 0]


def test_plan_without_a_feed_is_refused_before_any_work(tmp_path: Path) -> None:
    # feed_mm_min None means "the target's": only camtool.jobs.pipeline.plan_options knows it.
    drawing = read_dxf(rectangle_dxf(tmp_path / "r.dxf"))
    with pytest.raises(UsageError, match="no cutting feed: give --feed"):
        plan(drawing, PlanOptions())


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"origin": "center"}, r"origin = 'center': give two numbers .* placement='center'"),
        ({"depth": "3"}, r"depth = '3': give a number \(--depth\)"),
        ({"tabs": 2.5}, r"tabs = 2.5: give a whole number"),
        ({"fit": (10.0,)}, r"fit = \(10.0,\): give two numbers"),
        ({"reverse_open": "yes"}, r"reverse_open = 'yes': give True or False"),
    ],
)
def test_plan_options_of_the_wrong_kind_are_refused_when_made(
    kwargs: dict[str, Any], message: str
) -> None:
    with pytest.raises(UsageError, match=message):
        PlanOptions(**kwargs)
    assert PlanOptions(translate=[1.0, 2.0]).translate == (1.0, 2.0)  # type: ignore[arg-type]
