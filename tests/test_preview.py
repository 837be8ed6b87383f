"""The first preview: structure, colours, exact arcs, determinism."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

from camtool.preview import CUT_COLOUR, RAPID_COLOUR, program_svg
from camtool.program import ArcMove, Linear, Program, Rapid

NS = "{http://www.w3.org/2000/svg}"


def _program() -> Program:
    return Program(
        (
            Rapid(1, 1, contour=1),
            Linear(3, 1, 1.0, contour=1),
            ArcMove(1, 1, 2, 1, True, 1.0, contour=1),  # CW half circle back, over the top
            Rapid(5, 5, contour=2),
            ArcMove(5, 5, 6, 5, False, 1.0, contour=2),  # full CCW circle
        )
    )


def test_layers_colours_and_markers() -> None:
    root = ET.fromstring(program_svg(_program(), work_area=(0, 0, 10, 7), title="t"))
    paths = {p.get("id"): p for p in root.iter(f"{NS}path") if p.get("id")}
    assert paths["cuts"].get("stroke") == CUT_COLOUR
    assert paths["rapids"].get("stroke") == RAPID_COLOUR
    area = next(r for r in root.iter(f"{NS}rect") if r.get("id") == "work-area")
    assert (area.get("x"), area.get("y"), area.get("width"), area.get("height")) == (
        "0",
        "-7",
        "10",
        "7",
    )
    labels = [t.text for t in root.iter(f"{NS}text")]
    assert "1" in labels and "2" in labels and "t" in labels


def test_arcs_are_exact_svg_arcs_with_the_right_sweep() -> None:
    d = next(
        p.get("d")
        for p in ET.fromstring(program_svg(_program())).iter(f"{NS}path")
        if p.get("id") == "cuts"
    )
    arcs = re.findall(r"A([\d.]+) [\d.]+ 0 (\d) (\d)", d or "")
    # CW half circle: sweep-flag 1 on the page (Y down); the full circle is two CCW halves.
    assert arcs == [("1", "0", "1"), ("1", "0", "0"), ("1", "0", "0")]


def test_same_program_same_bytes() -> None:
    assert program_svg(_program(), title="x") == program_svg(_program(), title="x")
