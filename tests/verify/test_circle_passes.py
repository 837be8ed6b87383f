"""A circle cut in depth passes is still measured as a circle (regression).

Z programs plunge inside each contour's run (a Z-only move of no XY length) and cut a
circle once per pass; the circle fit must see through both.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from tests.shapes import write_dxf


def test_a_circle_in_three_passes_has_its_diameter_measured(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def build(msp: Any) -> None:
        msp.add_circle((20.0, 20.0), 5.0)

    path = write_dxf(tmp_path / "c.dxf", build)
    argv = ["post", str(path), "-t", "grbl", "--depth", "3", "--step-down", "1", "--verify"]
    assert main([*argv, "-o", str(tmp_path / "c.gcode")]) == 0
    err = capsys.readouterr().err
    # one circle of 10 mm, cut on the line (GRBL's 4 µm steps: within a few µm)
    assert "nominal 10.0000" in err
    fitted = re.search(r"diameter (\d+\.\d+) mm \(nominal 10\.0000\)", err)
    assert fitted is not None, err
    assert abs(float(fitted[1]) - 10.0) < 0.01  # mm (9.9973 today: 2.7 µm)
