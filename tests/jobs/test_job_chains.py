"""A job cuts the closed contours its selection chained, not the planner's own re-chaining.

Where more than two ends meet, how a chain goes on depends on what else ends there. The
drawing here is a 100 mm square part with a diamond hole (diagonals 20 mm) whose lower tip
touches the part's lower edge at (50, 0), and a centre line from that point down: five
ends meet there. Chained as the whole layer (as ``job init`` and the selection chain it),
the square and the diamond are two loops; chained again without the open line, in the
order of this file, they would be one figure that passes (50, 0) twice, whose outside
offset leaves the diamond uncut.

Expected values come from the geometry: a 3 mm tool inside the diamond runs on the diamond
shrunk by 1.5 mm on each side, whose vertices lie 10 − 1.5·√2 mm from its centre (50, 10)
along its diagonals; outside the square, 1.5 mm off each side.
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from tests.shapes import write_dxf

_LINES = {
    "O0": ((0, 0), (50, 0)),
    "O1": ((50, 0), (100, 0)),
    "O2": ((100, 0), (100, 100)),
    "O3": ((100, 100), (0, 100)),
    "O4": ((0, 100), (0, 0)),
    "H0": ((50, 0), (60, 10)),
    "H1": ((60, 10), (50, 20)),
    "H2": ((50, 20), (40, 10)),
    "H3": ((40, 10), (50, 0)),
    "X": ((50, 0), (50, -10)),
}
_ORDER = ("H0", "X", "O3", "O4", "H1", "H2", "O2", "H3", "O1", "O0")
"""An entity order in which the pieces of the two loops alone chain into one figure."""

_JOB = """
[job]
origin = "drawing"

[[tools]]
id = 1
type = "end-mill"
diameter = 3

[[operations]]
type = "profile"
tool = 1
layers = ["0"]
closed = true
side = "outside"
depth = 1
"""


def _points(program: str) -> set[tuple[float, float]]:
    """The X/Y of every feed move's end (G1 blocks with both words)."""
    found = set()
    for line in program.splitlines():
        m = re.match(r"G1 X(-?[\d.]+) Y(-?[\d.]+)", line)
        if m:
            found.add((float(m.group(1)), float(m.group(2))))
    return found


def test_the_hole_touching_its_part_where_a_line_ends_is_cut_inside(tmp_path: Path) -> None:
    drawing = write_dxf(
        tmp_path / "diamond.dxf", lambda msp: [msp.add_line(*_LINES[k]) for k in _ORDER]
    )
    job = tmp_path / "job.toml"
    job.write_text(_JOB)
    out = tmp_path / "diamond.ngc"
    assert main(["post", str(drawing), "-t", "linuxcnc", "--job", str(job), "-o", str(out)]) == 0
    points = _points(out.read_text())
    reach = 10 - 1.5 * math.sqrt(2)
    tips = ((50 + reach, 10), (50, 10 + reach), (50 - reach, 10), (50, 10 - reach))
    diamond = {(round(x, 3), round(y, 3)) for x, y in tips}
    assert diamond <= points
    assert {(-1.5, 100.0), (101.5, 0.0)} <= points  # the square's sides, offset outside


def test_a_circle_drawn_as_two_arcs_and_drilled_is_not_called_uncut(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the drill cuts the circle the selection chained of the two ARCs; neither ARC is left
    # over for the job's "not cut" note
    def build(msp: Any) -> None:
        msp.add_arc((10, 10), 3, 0, 180)
        msp.add_arc((10, 10), 3, 180, 360)

    drawing = write_dxf(tmp_path / "hole.dxf", build)
    job = tmp_path / "job.toml"
    job.write_text(
        '[job]\norigin = "drawing"\n[[tools]]\nid = 1\ntype = "drill"\ndiameter = 6\n'
        '[[operations]]\ntype = "drill"\ntool = 1\ndiameter = 6\ndepth = 3\n'
    )
    out = tmp_path / "hole.ngc"
    assert main(["post", str(drawing), "-t", "linuxcnc", "--job", str(job), "-o", str(out)]) == 0
    assert "not cut" not in capsys.readouterr().err
    assert "G0 X10.000 Y10.000" in out.read_text()
