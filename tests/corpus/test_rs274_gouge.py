"""Where LinuxCNC's interpreter moves the tool, against the drawing: no gouge where none is warned.

``camtool post DRAWING -t linuxcnc --offset outside|pocket`` on LibreCAD's own library
drawings; the program is read by ``rs274`` (test_rs274.py), and every cutting move below the
top is sampled every 0.05 mm. The material is built from ezdxf's circles alone (shapely;
each circle inside another is its hole, even-odd), not from camtool's reading: the tool
centre must stay at least the tool radius from it (less 0.005 mm for the 3 decimals and the
arcs' chords), outside it for ``outside``, inside it for ``pocket``. ``kinetics/kin82.dxf``
and ``kin124.dxf`` draw holes touching their outline from inside: read as outlines of their
own, they would be cut on the wrong side, through the part.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely

from tests.corpus.conftest import CORPUS
from tests.corpus.test_rs274 import arc_points, canon_moves, needs_rs274, rs274

KINETICS = CORPUS / "pkg/librecad-data/usr/share/librecad/library/kinetics"
TOOL_MM = 1.0
SLACK_MM = 0.005
STEP_MM = 0.05


def _material(dxf: Path) -> shapely.Geometry:
    """The even-odd region of the drawing's circles (ezdxf's centres and radii)."""
    region = shapely.Polygon()
    for e in ezdxf.readfile(dxf).modelspace().query("CIRCLE"):
        x, y, _ = e.dxf.center
        region = region.symmetric_difference(shapely.Point(x, y).buffer(e.dxf.radius, 256))
    return region


def _cutting_points(stdout: str) -> np.ndarray:
    """Points every STEP_MM along rs274's feed moves whose both ends are below Z 0."""
    points: list[tuple[float, float]] = []
    x = y = z = 0.0
    for kind, v in canon_moves(stdout):
        ex, ey, ez = (v[0], v[1], v[5]) if kind == "arc" else v
        if kind != "rapid" and z < 0 and ez < 0:
            if kind == "arc":
                along = arc_points((x, y), (ex, ey), (v[2], v[3]), v[4], STEP_MM)
            else:
                n = int(math.hypot(ex - x, ey - y) / STEP_MM) + 1
                along = [(x + (ex - x) * t, y + (ey - y) * t) for t in np.linspace(0, 1, n + 1)]
            points += [(x, y), *along]
        x, y, z = ex, ey, ez
    return np.array(points)


@needs_rs274
@pytest.mark.parametrize("name", ["kin82.dxf", "kin124.dxf"])
@pytest.mark.parametrize("offset", ["outside", "pocket"])
def test_the_tool_keeps_off_the_part_where_rs274_moves_it(
    tmp_path: Path, name: str, offset: str
) -> None:
    dxf = KINETICS / name
    out = tmp_path / "part.ngc"
    options = ["--offset", offset, "--tool-diameter", str(TOOL_MM), "--depth", "1"]
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "camtool",
            "post",
            str(dxf),
            "-t",
            "linuxcnc",
            *options,
            "-o",
            str(out),
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "cuts into the part" not in done.stderr
    judged = rs274(out)
    assert judged.returncode == 0, judged.stderr
    points = _cutting_points(judged.stdout)
    assert len(points) > 100
    material = _material(dxf)
    inside = shapely.contains_xy(material, points[:, 0], points[:, 1])
    edge = shapely.distance(material.boundary, shapely.points(points))
    wrong_side = inside if offset == "outside" else ~inside
    assert not wrong_side.any()
    assert float(edge.min()) >= TOOL_MM / 2 - SLACK_MM
