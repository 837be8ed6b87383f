"""A G18/G19 arc is timed as one block, as GRBL's ``mc_arc`` and planner run it, like a G17 arc.

Expected values from the rest-to-rest trapezoid (``t = L/v + v/a`` once cruise is reached)
of the grbl timing model's defaults (a = 10 mm/s², max rate 500 mm/min): a half circle of
radius 0.8 mm at F100 is ``0.8 pi / (100/60) + (100/60) / 10`` s in any plane.
"""

from __future__ import annotations

import math
import re

import pytest

from camtool.post.registry import load_target
from camtool.verify.verifier import verify_code

HALF_CIRCLE = {
    "G17": "G21 G90 G17\nG0 X0 Y0 Z0\nG2 X1.6 Y0 I0.8 J0 F100\nM2\n",
    "G18": "G21 G90 G18\nG0 X0 Y0 Z0\nG2 X1.6 Z0 I0.8 K0 F100\nM2\n",
    "G19": "G21 G90 G19\nG0 X0 Y0 Z0\nG2 Y1.6 Z0 J0.8 K0 F100\nM2\n",
}


@pytest.mark.parametrize("plane", sorted(HALF_CIRCLE))
def test_a_half_circle_takes_the_same_time_in_every_plane(plane: str) -> None:
    v, a = 100.0 / 60.0, 10.0
    expected = 0.8 * math.pi / v + v / a
    verification = verify_code(HALF_CIRCLE[plane], load_target("grbl"), budget=False)
    assert verification.time_s == pytest.approx(expected, rel=2e-3)


def test_a_capped_arc_names_its_line_once() -> None:
    code = "G21 G90 G18\nG0 X0 Y0 Z0\nG2 X1.6 Z0 I0.8 K0 F100000\nG1 X5 F100000\nM2\n"
    verification = verify_code(code, load_target("grbl"), budget=False)
    capped = [w for w in verification.warnings if "over the maximum rate" in w]
    assert len(capped) == 1
    assert re.match(r"lines 3, 4: ", capped[0]), capped[0]
