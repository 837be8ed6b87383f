"""dxf2gcode's LinuxCNC program of spline letters: arcs that end off their circles.

tests/data/dxf2gcode-spiral-arcs.ngc (its origin: tests/data/README.md) fits splines with
arcs written in inches with 3 decimals, so each arc's end lies up to 0.00104 in (0.0265 mm,
0.13 % of its radius) off the circle of its start radius. LinuxCNC 2.9's ``rs274`` runs it
(tests/corpus/test_rs274.py); GRBL refuses such an arc (error 33: over 0.005 mm and 0.1 %).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from camtool.importers.gcode import read_gcode
from camtool.jobs.pipeline import post_program
from camtool.jobs.run import OutputOptions
from camtool.model.program import ArcMove
from camtool.post.registry import load_target
from camtool.post.wordaddress_read import ControllerRefusal
from camtool.verify.verifier import verify_code

DXF2GCODE = Path(__file__).resolve().parents[1] / "data" / "dxf2gcode-spiral-arcs.ngc"


def test_its_arcs_are_read_as_written() -> None:
    program = read_gcode(DXF2GCODE)
    arcs = [m for m in program.moves if isinstance(m, ArcMove)]
    assert len(arcs) == 9
    # line 28, from the end of line 27 (0.954, 1.700) in: G2 X1.332 Y1.657 I0.105 J-0.779
    line28 = next(a for a in arcs if a.x == pytest.approx(1.332 * 25.4))
    assert (line28.y, line28.cx, line28.cy) == pytest.approx(
        (1.657 * 25.4, (0.954 + 0.105) * 25.4, (1.700 - 0.779) * 25.4), abs=1e-9
    )
    r_start = math.hypot(0.105, -0.779) * 25.4
    r_end = math.hypot(1.332 - 1.059, 1.657 - 0.921) * 25.4
    assert r_start - r_end == pytest.approx(0.02653, abs=1e-5)  # within LinuxCNC's 0.0283 mm


def test_linuxcnc_verifies_it_and_grbl_refuses_it_at_its_line() -> None:
    text = DXF2GCODE.read_text()
    v = verify_code(text, load_target("linuxcnc"), source="d.ngc", budget=False)
    assert v.deviation.points > 0
    with pytest.raises(
        ControllerRefusal, match=r"^d\.ngc:28: grbl refuses this arc: grbl error 33"
    ):
        verify_code(text, load_target("grbl"), source="d.ngc", budget=False)


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_re_posted_its_arcs_are_ones_the_controller_takes(target: str) -> None:
    """``verify_code`` reads the output with the target's reader and its controller's arc check."""
    out = post_program(read_gcode(DXF2GCODE), load_target(target), OutputOptions())
    code = out.result.code
    assert isinstance(code, str) and re.search(r"^G[23] ", code, re.M)  # arcs kept as arcs
    v = verify_code(code, load_target(target), source="re.nc", budget=False)
    assert v.deviation.points > 0


def test_its_arcs_off_their_circles_are_noted_once_with_their_count() -> None:
    """The note counts the arcs whose radii differ by over 0.005 mm, from the file's numbers."""
    here, off = None, []
    for number, line in enumerate(DXF2GCODE.read_text().splitlines(), start=1):
        words = dict(re.findall(r"([XYIJ])\s*(-?[\d.]+)", line.split("(")[0]))
        if line.startswith("G2") and here is not None:
            cx, cy = here[0] + float(words["I"]), here[1] + float(words["J"])
            end = (float(words["X"]), float(words["Y"]))
            gap = abs(math.dist(here, (cx, cy)) - math.dist(end, (cx, cy))) * 25.4  # in → mm
            if gap > 0.005:
                off.append((number, gap))
        if "X" in words and "Y" in words:
            here = (float(words["X"]), float(words["Y"]))
    notes = [w for w in read_gcode(DXF2GCODE).warnings if "off its circle" in w]
    first, gap = off[0]
    assert notes == [
        f"{DXF2GCODE}:{first}: G2 ends {gap:.4f} mm off its circle, read as written (LinuxCNC "
        "cuts it as a spiral; verify cuts it on its start's circle, then a chord to its end: "
        f"the offset shows in its deviation) ({len(off)} times)"
    ]
    assert read_gcode(DXF2GCODE).moves  # read, not refused
