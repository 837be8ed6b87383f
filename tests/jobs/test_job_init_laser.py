"""``camtool job init`` on parts drawn for a laser cutter, as boxes.py draws them.

boxes.py (florianfesti/boxes) draws a part's outline black and its inner cuts blue, on one
layer; on some parts the outline ends before its last corner's 0.1 mm rounding, 0.1·√2 ≈
0.1414 mm from its start (its ``examples/AgricolaInsert.svg``, ``BreadBox.svg``,
``FlexBook.svg``...), and a slot open at the part's edge is a blue rectangle poking
0.094 mm out of the outline (``AgricolaInsert.svg``'s ``path[106]``). The drawings here
keep those traits at sizes easy to check by hand.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.init import initial_job
from camtool.jobs.jobfile import job_from_dict
from camtool.jobs.run import run_job
from camtool.model.program import Linear
from camtool.post.registry import load_target
from tests.shapes import write_dxf

# a 100 × 60 mm page in mm, Y down: the outline from x 10 to 60, y 10 to 50, open at its
# corner (10, 10); a 10 × 10 mm hole inside; a slot at the right edge, 0.1 mm out of it
_PART = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" viewBox="0 0 100 60">'
    '<path d="M 10.1 10 H 60 V 50 H 10 V 10.1" stroke="rgb(0,0,0)" fill="none"/>'
    '<path d="M 30 20 H 40 V 30 H 30 Z" stroke="rgb(0,0,255)" fill="none"/>'
    '<path d="M 55 35 H 60.1 V 40 H 55 Z" stroke="rgb(0,0,255)" fill="none"/>'
    "</svg>"
)


def _ops(text: str) -> list[dict[str, object]]:
    return list(tomllib.loads(text)["operations"])


def test_an_outline_open_at_a_corner_is_closed_and_cut_with_its_holes_inside(
    tmp_path: Path,
) -> None:
    """The outline is a part (``close_gap`` closes it), so the blue shapes are its holes.

    Left open, the outline was an engraving to uncomment, the part was not cut, and the
    blue colour held "outermost" contours: cut on their outside, into the part. The slot
    poking 0.1 mm out of the edge is a hole too (nearly all of it lies in the part). Cut
    with the 3 mm end mill, the part's toolpath lies 1.5 mm outside its 50 × 40 mm
    outline and the hole's 1.5 mm inside its 10 mm square (work zero lower-left: the
    outline's toolpath starts at 0).
    """
    svg = tmp_path / "box.svg"
    svg.write_text(_PART)
    drawing = read_drawing(svg)
    text = initial_job(drawing, thickness_mm=3.0)
    assert tomllib.loads(text)["job"]["close_gap"] == 0.15
    assert "1 outline(s) end up to 0.1414 mm from their start" in text
    sides = [(op["colours"], op["side"]) for op in _ops(text)]
    assert sides == [(["#0000ff"], "inside"), (["#000000"], "outside")]
    job = job_from_dict(tomllib.loads(text), source="box.toml")
    done = run_job(drawing, load_target("grbl"), job)
    z, xs, ys = 0.0, [], []
    for m in done.program.moves:
        z = m.z if m.z is not None else z
        if isinstance(m, Linear) and z < 0:
            xs.append(m.x)
            ys.append(m.y)
    assert min(xs) == pytest.approx(0.0) and max(xs) == pytest.approx(53.0)
    assert min(ys) == pytest.approx(0.0) and max(ys) == pytest.approx(43.0)
    # the hole: x 30..40 in the drawing, 21.5..31.5 from work zero; its toolpath 23..30
    hole = [x for x in xs if 20.0 < x < 33.0]
    assert hole and min(hole) == pytest.approx(23.0) and max(hole) == pytest.approx(30.0)
    assert any("closed a 0.1414 mm gap" in w for w in done.program.warnings)


def _outline_and_c(c_gap: float) -> object:
    """An 80 × 40 mm outline open 0.1414 mm at a corner, and a "C" open ``c_gap`` mm.

    The C (about 10 mm long) is drawn open on purpose: its gap is over 1 % of its length.
    """

    def build(msp: object) -> None:
        msp.add_lwpolyline([(0.1, 0), (80, 0), (80, 40), (0, 40), (0, 0.1)])  # type: ignore[attr-defined]
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(100 + c_gap, 0), (102.5, 0), (102.5, 2.5), (100, 2.5), (100, 0)]
        )

    return build


def test_close_gap_stops_short_of_a_shape_drawn_open(tmp_path: Path) -> None:
    """``close_gap`` is set just above the outline's gap and under the C's (0.3 mm)."""
    drawing = read_drawing(write_dxf(tmp_path / "c.dxf", _outline_and_c(0.3)))
    text = initial_job(drawing)
    assert tomllib.loads(text)["job"]["close_gap"] == 0.15
    assert [op["side"] for op in _ops(text)] == ["outside"]
    assert '# type = "engrave"  # 1 open contour(s)' in text  # the C


def test_no_close_gap_when_it_would_close_a_shape_drawn_open(tmp_path: Path) -> None:
    """A C open 0.12 mm (1.2 % of its length) is under the 0.15 mm the outline needs.

    ``close_gap = 0.15`` would close the C too (post closes a gap under a tenth of its
    contour's length), so none is set: both stay open, and a drawing of open lines only
    is engraved.
    """
    drawing = read_drawing(write_dxf(tmp_path / "c.dxf", _outline_and_c(0.12)))
    text = initial_job(drawing)
    assert "close_gap" not in tomllib.loads(text)["job"]
    assert [(op["type"], op["closed"]) for op in _ops(text)] == [("engrave", False)]


def test_holes_of_another_colour_s_part_in_an_outside_colour_are_named(tmp_path: Path) -> None:
    """A colour holding a part's hole and a shape of its own says the hole is cut into the part.

    boxes.py's ``Gears.svg``: blue holds two gears' shaft holes and two circles drawn
    apart. One profile per colour cannot cut both right: the blue one is cut outside (its
    circles are outermost), and its comment says that its contours inside the black part
    are cut outside too, into it, and what to do.
    """
    svg = tmp_path / "gear.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" viewBox="0 0 100 60">'
        '<path d="M 10 10 H 50 V 50 H 10 Z" stroke="rgb(0,0,0)" fill="none"/>'
        '<path d="M 25 25 H 35 V 35 H 25 Z" stroke="rgb(0,0,255)" fill="none"/>'
        '<circle cx="80" cy="30" r="8" stroke="rgb(0,0,255)" fill="none"/>'
        "</svg>"
    )
    text = initial_job(read_drawing(svg))
    blue = next(
        line for line in text.splitlines() if line.startswith('side = "outside"  # colour #0000ff')
    )
    assert blue.endswith(
        "; but 1 of its contours lie inside colour #000000's parts and are cut outside too, "
        "into them: give those a layer or colour of their own, cut inside"
    )
    black = next(line for line in text.splitlines() if "colour #000000 holds" in line)
    assert "but" not in black


def test_a_colour_mostly_of_another_colour_s_holes_is_cut_inside(tmp_path: Path) -> None:
    """Three blue holes in the black part and one blue square apart: blue is cut inside.

    boxes.py's ``Lamp.svg`` draws 605 blue holes in black parts and 2 blue squares whose
    black parts are drawn open (not chained closed): cut outside, as its 2 "outermost"
    contours would ask, the 605 holes would be a tool diameter too wide. The side of most
    of the contours wins, and the comment names the others. With the 3 mm end mill, each
    10 mm hole's toolpath lies 1.5 mm inside it: work zero is the lower-left of the part's
    toolpath, 1.5 mm outside its outline at x 10, so the holes at x 15..25, 35..45 and
    55..65 in the drawing are cut from x 16.5 - 8.5 = 8 to 63.5 - 8.5 = 55 mm.
    """
    svg = tmp_path / "lamp.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="120mm" height="60mm" viewBox="0 0 120 60">'
        '<path d="M 10 10 H 70 V 50 H 10 Z" stroke="rgb(0,0,0)" fill="none"/>'
        '<path d="M 15 25 H 25 V 35 H 15 Z" stroke="rgb(0,0,255)" fill="none"/>'
        '<path d="M 35 25 H 45 V 35 H 35 Z" stroke="rgb(0,0,255)" fill="none"/>'
        '<path d="M 55 25 H 65 V 35 H 55 Z" stroke="rgb(0,0,255)" fill="none"/>'
        '<path d="M 90 25 H 100 V 35 H 90 Z" stroke="rgb(0,0,255)" fill="none"/>'
        "</svg>"
    )
    drawing = read_drawing(svg)
    text = initial_job(drawing, thickness_mm=3.0)
    sides = [(op["colours"], op["side"]) for op in _ops(text)]
    assert sides == [(["#0000ff"], "inside"), (["#000000"], "outside")]
    blue = next(line for line in text.splitlines() if line.startswith('side = "inside"'))
    assert blue.endswith(
        "# colour #0000ff holds 3 holes of colour #000000's parts: cut on their inside; but 1 "
        "of its contours lie inside no part and are cut inside too: if those are parts, give "
        "them a layer or colour of their own, cut outside"
    )
    job = job_from_dict(tomllib.loads(text), source="lamp.toml")
    done = run_job(drawing, load_target("grbl"), job)
    z, holes = 0.0, []
    for m in done.program.moves:
        z = m.z if m.z is not None else z
        if isinstance(m, Linear) and z < 0 and 1.0 < m.x < 60.0 and 10.0 < m.y < 33.0:
            holes.append(m.x)
    assert min(holes) == pytest.approx(8.0) and max(holes) == pytest.approx(55.0)


def test_a_notch_drawn_across_a_part_s_edge_is_cut_inside(tmp_path: Path) -> None:
    """A blue square two thirds outside the black outline is a notch: cut on its inside.

    boxes.py's ``OttoBody.svg`` draws a 3.8 mm notch 2.4 mm past a part's edge (37 % of
    it inside); as the only blue shape outside every black one it made the blue colour
    "hold an outermost contour", cut outside, into the part around it.
    """
    svg = tmp_path / "notch.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" viewBox="0 0 100 60">'
        '<path d="M 10 10 H 50 V 50 H 10 Z" stroke="rgb(0,0,0)" fill="none"/>'
        '<path d="M 48.6 28 H 52.4 V 31.8 H 48.6 Z" stroke="rgb(0,0,255)" fill="none"/>'
        "</svg>"
    )
    text = initial_job(read_drawing(svg))
    sides = [(op["colours"], op["side"]) for op in _ops(text)]
    assert sides == [(["#0000ff"], "inside"), (["#000000"], "outside")]


def _two_parts(gap: float) -> str:
    """Two 20 × 20 mm parts side by side, ``gap`` mm apart (an SVG page in mm)."""
    x = 30.0 + gap
    return (
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" viewBox="0 0 100 60">'
        '<path d="M 10 10 H 30 V 30 H 10 Z" stroke="rgb(0,0,0)" fill="none"/>'
        f'<path d="M {x} 10 H {x + 20} V 30 H {x} Z" stroke="rgb(0,0,0)" fill="none"/>'
        "</svg>"
    )


@pytest.mark.parametrize(("gap", "mill"), [(1.5, 1.0), (2.2, 2.0), (3.0, 3.0), (8.0, 3.0)])
def test_parts_closer_than_the_tool_get_an_end_mill_that_fits_between_them(
    tmp_path: Path, gap: float, mill: float
) -> None:
    """boxes.py spaces parts half a stock thickness apart (1.5 mm for 3 mm), for a laser.

    A 3 mm end mill's cut, 3 mm wide outside each part, would take 1.5 mm of the
    neighbour (``post`` warns, but only once the job is written). The largest common end
    mill within 95 % of the gap is proposed instead: 1 mm for 1.5 mm (1.425 mm at most),
    2 mm for 2.2 mm; a gap of the tool's width or more keeps the 3 mm one. The job's
    program then cuts into neither part.
    """
    svg = tmp_path / "parts.svg"
    svg.write_text(_two_parts(gap))
    drawing = read_drawing(svg)
    text = initial_job(drawing, thickness_mm=3.0)
    job = tomllib.loads(text)
    assert [t["diameter"] for t in job["tools"]] == [mill]
    tool_line = next(line for line in text.splitlines() if line.startswith("tool = "))
    if mill < 3.0:
        # across the gap between the facing edges (y 30..50 with Y up), at one of them
        at = re.search(rf"parts {gap:g} mm apart at \((\S+), (\S+)\) mm", tool_line)
        assert at, tool_line
        assert float(at[1]) == pytest.approx(30 + gap / 2) and 30.0 <= float(at[2]) <= 50.0
        assert f"a {mill:g} mm one fits" in tool_line
    else:
        assert "#" not in tool_line
    done = run_job(drawing, load_target("grbl"), job_from_dict(job, source="parts.toml"))
    assert not [w for w in done.program.warnings if "cuts into the part" in w]
