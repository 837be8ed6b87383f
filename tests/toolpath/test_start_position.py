"""The machine's XY when a program starts is unknown: XY is positioned before any plunge.

Regression: a contour starting at the drawing's origin was cut without any XY rapid (the
planner assumed the tool stood at X0 Y0), so the machine plunged wherever it stood.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main


@pytest.mark.parametrize(
    ("target", "origin", "first_xy"),
    [
        ("grbl", "drawing", "G0 X0.000 Y0.000"),
        ("grbl", "center", "G0 X-5.000 Y-5.000"),
        ("linuxcnc", "drawing", "G0 X0.000 Y0.000"),
        ("valcnc", "drawing", "G00X0Y0"),
    ],
)
def test_xy_is_positioned_before_the_tool_goes_down(
    target: str, origin: str, first_xy: str, tmp_path: Path
) -> None:
    points = tmp_path / "tri.csv"
    points.write_text("0,0\n10,0\n10,10\n")  # an open path that starts at X0 Y0
    out = tmp_path / "p.nc"
    assert main(["post", str(points), "-t", target, "--origin", origin, "-o", str(out)]) == 0
    blocks = [b for b in out.read_text().splitlines() if b.startswith("G")]
    moves = [b for b in blocks if b.startswith(("G0", "G1", "G00", "G01"))]
    # first a Z-only rise, then the XY positioning, and only then down
    assert "X" not in moves[0] and "Z" in moves[0]
    assert moves[1] == first_xy
    assert all("X" not in m and "Y" not in m for m in moves[2:4])  # down to safe Z, plunge


def test_a_drawing_too_small_to_cut_is_an_error_not_an_empty_program(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # regression: points 1e-300 mm apart posted an empty program with exit 0
    points = tmp_path / "tiny.csv"
    points.write_text("0,0\n1e-300,1e-300\n2e-300,0\n")
    out = tmp_path / "p.nc"
    assert main(["post", str(points), "-t", "valcnc", "-o", str(out)]) == 3
    # refused before planning, as too small for any tool (camtool/jobs/travel.py)
    assert "its cuts span only 2e-300 × 1e-300 mm" in capsys.readouterr().err
    assert not out.exists()
