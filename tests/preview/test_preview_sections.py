"""A job's preview: a colour per operation, a mark per tool change, a number per contour."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from camtool.model.program import Linear, Program, Rapid, ToolChange
from camtool.preview import render_preview
from camtool.preview.program_layers import SECTION_COLOURS, sections_of

NS = "{http://www.w3.org/2000/svg}"


def _groups(svg: bytes) -> dict[str, ET.Element]:
    root = ET.fromstring(svg)
    return {g.get("id", ""): g for g in root.iter() if g.get("id")}


def _square(x: float, contour: int, z: float) -> tuple[Rapid | Linear, ...]:
    return (
        Rapid(x, 0.0, contour=contour),
        Linear(x + 1, 0.0, 60.0, z, contour=contour),
        Linear(x + 1, 1.0, 60.0, contour=contour),
        Linear(x, 0.0, 60.0, contour=contour),
    )


def _two_tools() -> Program:
    # T2 cuts contour 1 in two passes (a rapid between them); then T1 cuts contour 2
    moves = (*_square(0.0, 1, -1.0), *_square(0.0, 1, -2.0), *_square(5.0, 2, -1.0))
    return Program(moves, commands=((0, ToolChange(2, "drill 3 mm")), (8, ToolChange(1))))


def test_sections_are_cut_at_the_tool_changes() -> None:
    assert sections_of(_two_tools()) == (("T2 drill 3 mm", 0, 8), ("T1", 8, 12))
    assert sections_of(Program(_square(0.0, 1, -1.0))) == ()


def test_each_tool_has_its_colour_and_each_change_a_mark() -> None:
    groups = _groups(render_preview(".svg", program=_two_tools()))
    strokes = [p.get("stroke") for p in groups["cuts"]]
    assert strokes == list(SECTION_COLOURS[:2])
    marks = list(groups["tool-changes"].iter(f"{NS}rect"))
    assert len(marks) == 1  # the first tool is loaded before any move: no mark
    box = marks[0]
    centre = (
        float(box.get("x", "")) + float(box.get("width", "")) / 2,
        -(float(box.get("y", "")) + float(box.get("height", "")) / 2),
    )
    assert centre == (0.0, 0.0)  # where T2's last move ended
    legend = "".join(t.text or "" for t in groups["legend"].iter(f"{NS}text"))
    assert "T2 drill 3 mm" in legend and "tool change" in legend


def test_passes_of_one_contour_carry_one_number() -> None:
    groups = _groups(render_preview(".svg", program=_two_tools()))
    assert [t.text for t in groups["order"]] == ["1", "2"]


def test_given_sections_name_the_operations() -> None:
    sections = [("operation 1 (drill 'holes')", 0, 8), ("operation 2 (profile)", 8, 12)]
    groups = _groups(render_preview(".svg", program=_two_tools(), sections=sections))
    legend = "".join(t.text or "" for t in groups["legend"].iter(f"{NS}text"))
    assert "operation 1 (drill 'holes')" in legend and "operation 2 (profile)" in legend
