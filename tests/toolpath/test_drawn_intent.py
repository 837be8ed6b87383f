"""The drawing means what the user drew (issue 13 §3).

Open contours are cut in their drawn direction, near-misses between ends are reported
with the option value that joins them, and options without effect are named.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from camtool.model.shapes import Contour, Drawing, Line
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.plan import plan_drawing
from tests.shapes import GOLDEN_CENTRE, GOLDEN_END, write_dxf

GOLDEN_BLOCK = "G02X02969.00Y03400.00I03012.00J03040.00F08;"  # UNAM-GMM L1731


def _golden_arc_from(path: Path, start_deg: float) -> Path:
    """A clockwise LWPOLYLINE arc on the golden circle from ``start_deg`` to the golden end."""
    cx, cy = GOLDEN_CENTRE
    ex, ey = GOLDEN_END
    r = math.hypot(ex - cx, ey - cy)
    a0 = math.radians(start_deg)
    start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
    sweep = (math.atan2(ey - cy, ex - cx) - a0) % (2 * math.pi) - 2 * math.pi  # clockwise
    bulge = math.tan(sweep / 4)

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(*start, bulge), (ex, ey, 0.0)], format="xyb")

    return write_dxf(path, build)


@pytest.mark.parametrize("start_deg", [180.0, 0.0, 45.0])
def test_golden_arc_comes_out_as_drawn_whichever_end_is_nearer(
    start_deg: float, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _golden_arc_from(tmp_path / "arc.dxf", start_deg)
    cx, cy = GOLDEN_CENTRE
    r = math.hypot(GOLDEN_END[0] - cx, GOLDEN_END[1] - cy)
    start = (cx + r * math.cos(math.radians(start_deg)), cy + r * math.sin(math.radians(start_deg)))
    # at 0° and 45° the start lies further from the origin than the end: a nearest-end
    # ordering would cut it backwards as a G03 to the start
    assert (math.hypot(*start) > math.hypot(*GOLDEN_END)) == (start_deg != 180.0)
    code = main(["post", str(path), "-t", "pic-mmh", "--feed", "0.8"])
    out = capsys.readouterr().out
    assert code == 0
    assert GOLDEN_BLOCK in out.splitlines()


def test_reverse_open_lets_the_order_flip_an_open_path() -> None:
    far, near = (10.0, 0.0), (1.0, 0.0)
    line = Contour((Line(far, near),), False)
    drawing = Drawing((line,))
    drawn = plan_drawing(drawing, PlanOptions(feed_mm_min=100.0)).program
    flipped = plan_drawing(drawing, PlanOptions(feed_mm_min=100.0, reverse_open=True)).program
    assert (drawn.moves[-1].x, drawn.moves[-1].y) == near  # cut from far to near as drawn
    assert (flipped.moves[-1].x, flipped.moves[-1].y) == far  # nearest end first


@pytest.mark.parametrize("order", ["travel", "reversals"])
def test_reverse_open_flips_the_second_of_two_lines_in_every_search_order(order: str) -> None:
    # (0,0)->(10,0) then (0,1)->(10,1): the second cut back from (10, 1) saves 9.05 mm
    # of rapids and, for reversals, one X reversal (2/0 drawn, 1/0 flipped)
    a = Contour((Line((0.0, 0.0), (10.0, 0.0)),), False)
    b = Contour((Line((0.0, 1.0), (10.0, 1.0)),), False)
    for reverse_open, second in ((False, (0.0, 1.0)), (True, (10.0, 1.0))):
        opts = PlanOptions(feed_mm_min=100.0, order=order, reverse_open=reverse_open)
        ordering = plan_drawing(Drawing((a, b)), opts).report.ordering
        first, then = ordering.cuts
        assert first.path.start == (0.0, 0.0) and then.path.start == second, reverse_open
        got, drawn = ordering.reversals["planned"], ordering.reversals["drawn"]
        assert got == ((1, 0) if reverse_open else (2, 0)) and sum(got) <= sum(drawn)


def test_cad_gap_of_two_microns_is_joined_by_default() -> None:
    # 0.002 mm between entities that should meet is common in real files
    a = Contour((Line((0.0, 0.0), (10.0, 0.0)),), False)
    b = Contour((Line((10.002, 0.0), (10.0, 10.0)),), False)
    c = Contour((Line((10.0, 10.0), (0.0, 0.0)),), False)
    plan = plan_drawing(Drawing((a, b, c)), PlanOptions(feed_mm_min=100.0))
    assert plan.report.contours == 1
    assert not [f for f in plan.report.findings if f.kind == "open-gap"]


def test_a_gap_that_stays_open_is_reported_with_the_option_that_joins_it() -> None:
    a = Contour((Line((0.0, 0.0), (10.0, 0.0)),), False)
    b = Contour((Line((10.05, 0.0), (10.05, 10.0)),), False)
    plan = plan_drawing(Drawing((a, b)), PlanOptions(feed_mm_min=100.0))
    (gap,) = [f for f in plan.report.findings if f.kind == "open-gap"]
    assert gap.value == pytest.approx(0.05)
    assert "0.0500 mm" in gap.message and "--chain-tolerance 0.051" in gap.message
    # the remedy works as written
    joined = plan_drawing(Drawing((a, b)), PlanOptions(feed_mm_min=100.0, chain_tolerance=0.051))
    assert joined.report.contours == 1
    assert not [f for f in joined.report.findings if f.kind == "open-gap"]


def test_ends_far_apart_are_not_reported() -> None:
    a = Contour((Line((0.0, 0.0), (10.0, 0.0)),), False)
    b = Contour((Line((12.0, 0.0), (20.0, 0.0)),), False)
    plan = plan_drawing(Drawing((a, b)), PlanOptions(feed_mm_min=100.0))
    assert not [f for f in plan.report.findings if f.kind == "open-gap"]


@pytest.mark.parametrize(
    ("options", "names"),
    [
        ({"tool_diameter": 3.0}, ["--tool-diameter"]),
        ({"stepover": 0.5, "pocket": "zigzag"}, ["--stepover", "--pocket"]),
        ({"tab_width": 4.0}, ["--tab-width"]),
        ({"offset": "outside", "tool_diameter": 3.0}, []),
        ({"offset": "pocket", "tool_diameter": 3.0, "stepover": 0.5}, []),
    ],
)
def test_options_without_effect_are_named(options: dict[str, Any], names: list[str]) -> None:
    notes = PlanOptions(feed_mm_min=100.0, **options).ineffective()
    text = " ".join(f.message for f in notes)
    assert all(name in text for name in names)
    assert bool(notes) == bool(names)


def test_units_on_a_dxf_that_declares_its_own_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _golden_arc_from(tmp_path / "arc.dxf", 180.0)  # $INSUNITS = 4, mm
    code = main(["post", str(path), "-t", "pic-mmh", "--units", "in", "-o", str(tmp_path / "a")])
    err = capsys.readouterr().err
    assert code == 2
    assert "--units in: " in err and "declares its unit, mm ($INSUNITS = 4)" in err
    assert not (tmp_path / "a").exists()


def test_a_lead_in_shortened_to_fit_is_named() -> None:
    from camtool.model.shapes import Arc

    # a ø4 mm hole cut inside with a 3 mm tool: the tool centre runs on a 0.5 mm radius
    # circle, far too small for 2 mm lead arcs on the waste side (the hole's middle)
    hole = Contour((Arc((2.0, 0.0), (2.0, 0.0), (0.0, 0.0), False),), True)
    options = PlanOptions(feed_mm_min=100.0, offset="inside", tool_diameter=3.0, lead_in=2.0)
    plan = plan_drawing(Drawing((hole,)), options)
    (lead,) = [f for f in plan.report.findings if f.kind == "lead-in"]
    assert lead.value is not None and lead.value < 2.0
    assert "--lead-in 2" in lead.message
    assert lead.message in plan.program.warnings


def test_many_near_gaps_are_reported_nearest_first_and_counted(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """30 lines, each 0.05 + k·0.001 mm short of the next (29 gaps): 10 reported, nearest
    first, the rest counted; only the 10 reported are written out (100 000 loose lines
    made 240 000 messages)."""
    from camtool.toolpath import gaps

    lines, x = [], 0.0
    for k in range(30):
        lines.append(Contour((Line((x, 0.0), (x + 1.0, 0.0)),), False))
        x += 1.0 + 0.05 + k * 0.001
    written: list[float] = []
    finding = gaps._finding

    def counted(contours: Any, a: Any, b: Any, gap: float, options: Any) -> Any:
        written.append(gap)
        return finding(contours, a, b, gap, options)

    monkeypatch.setattr(gaps, "_finding", counted)
    found = gaps.open_gaps(lines, PlanOptions(feed_mm_min=100.0))
    assert len(found) == gaps.MAX_REPORTED + 1 == len(written) + 1
    assert [f.value for f in found[:-1]] == pytest.approx([0.05 + k * 0.001 for k in range(10)])
    assert found[-1].message.startswith("19 more open end(s) lie near another (gaps up to 0.0780")
    assert found[-1].value == pytest.approx(0.078)  # 29 gaps between 30 lines
