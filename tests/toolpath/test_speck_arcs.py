"""An arc shorter than the few µm its ends move by is cut as the speck it is.

A joint snapped within ``--chain-tolerance``, or a pass that ends on the circle of an arc's
snapped start, can put an arc's start past its end: the controller then runs nearly the
whole circle. Expectation: the drawing's own extent, and the arc blocks as a controller
runs them (an end on the start is a full turn; GRBL ``mc_arc``, LinuxCNC ``pmCircleInit``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from tests.shapes import write_dxf


def _speck_joint(msp: Any) -> None:
    """A random drawing whose two ARC specks join two LINEs at ``--chain-tolerance 0.05``.

    The ARC of radius 60.5 is 0.000012 mm long; the ARC of radius 135.5 ends 0.0022 mm from
    it and starts 0.00095 mm from a LINE. A pass ends on the circle of the larger arc's
    snapped start, 0.0008 mm off its end: the speck, cut as an arc from there, would run
    the other way round its circle, 121 mm across.
    """
    msp.add_arc((94.1453791711659, 51.87974357394093), 6.17279495989217,
                112.7004938640265, 112.70067849223605)  # fmt: skip
    msp.add_lwpolyline([(57.794208903575026, 9.125766858025186, 1.3798144979030977e-06),
                        (57.79404242316959, 9.126046002125639, 0.0),
                        (57.6553984418966, 9.121446248658689, 0.909702116405235),
                        (57.676625963090046, 9.136903197935196, 0.6823751316569964),
                        (57.6739554101165, 9.19059287244975, 1.9850214563443762),
                        (57.00216795328197, 6.172088392366975, 0.6932787649942433),
                        (56.88221668834508, 6.085265484786288, 0.0)], format="xyb")  # fmt: skip
    msp.add_lwpolyline([(3.3460334305481343, 94.64392124116627, 0.0),
                        (3.3442109001903435, 94.64369274016302, 0.0),
                        (3.344992579207731, 94.64239625453753, 0.0),
                        (3.2735504432194595, 94.68238134031053, 0.0)], format="xyb")  # fmt: skip
    msp.add_arc((103.14779836582335, 18.15445067065628), 60.525435577837364,
                132.66428286853844, 132.664294533089)  # fmt: skip
    msp.add_arc((26.711791230608185, 193.46063987714848), 135.51057332781994,
                285.1521045524639, 285.1527452810048)  # fmt: skip
    msp.add_line((62.13428443775977, 62.661443026510966), (62.58863309025391, 64.74811066914309))
    msp.add_line((62.58863309025391, 64.74811066914309), (62.13076150153385, 62.66105527255331))
    msp.add_line((77.68726933126995, 27.328456239021758), (77.67727258455903, 27.334208236213072))
    msp.add_line((77.6772798604707, 27.334208236213072), (77.69498564206992, 27.335974133757894))


def _arc_extent(start: tuple[float, float], words: dict[str, float], cw: bool) -> tuple[float, ...]:
    """The box of a written G2/G3 block as a controller runs it (end on start: a full turn)."""
    cx, cy = start[0] + words["I"], start[1] + words["J"]
    r = math.hypot(start[0] - cx, start[1] - cy)
    a0 = math.atan2(start[1] - cy, start[0] - cx)
    a1 = math.atan2(words["Y"] - cy, words["X"] - cx)
    sweep = (a0 - a1) % math.tau if cw else (a1 - a0) % math.tau
    sweep = sweep or math.tau
    xs, ys = [start[0], words["X"]], [start[1], words["Y"]]
    for q in range(4):
        angle = q * math.pi / 2
        if ((a0 - angle) % math.tau if cw else (angle - a0) % math.tau) <= sweep:
            xs.append(cx + r * math.cos(angle))
            ys.append(cy + r * math.sin(angle))
    return min(xs), min(ys), max(xs), max(ys)


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_speck_arc_after_a_snapped_joint_is_cut_within_the_drawing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str
) -> None:
    path = write_dxf(tmp_path / "joint.dxf", _speck_joint)
    out = tmp_path / "joint.nc"
    argv = ["post", str(path), "-t", target, "-o", str(out), "--chain-tolerance", "0.05"]
    assert main(argv) == 0
    capsys.readouterr()
    here = (0.0, 0.0)
    for line in out.read_text().splitlines():
        words = {k: float(v) for k, v in re.findall(r"([XYIJ])(-?[0-9.]+)", line)}
        end = (words.get("X", here[0]), words.get("Y", here[1]))
        if re.match(r"G[23] ", line):
            box = _arc_extent(here, {**words, "X": end[0], "Y": end[1]}, line.startswith("G2"))
            # the drawing spans X 3.27..91.77, Y 6.08..94.69; the speck's circle Y -42..79
            assert box[0] > 3.2 and box[1] > 6.0 and box[2] < 91.8 and box[3] < 94.7, line
        here = end
