"""Random DXFs of every curve, in mirrored planes and scaled, mirrored, nested blocks.

What other CAD programs write and LibreCAD's library seldom does: ARCs, CIRCLEs, bulged
polylines and ELLIPSEs with the extrusion (0, 0, -1) (a part drawn from below, as
SolidWorks and Fusion 360 export), SPLINEs by control points and by fit points, and block
references scaled non-uniformly (a circle becomes an ellipse), mirrored (-1 scales),
rotated, in a mirrored plane and nested. Each is posted as a new user posts it
(``camtool post FILE -t linuxcnc -o OUT``), LinuxCNC's ``rs274`` reads the program, and
its feed moves are compared both ways with the drawing sampled from the DXF definitions
(tests/corpus/dxf_exact.py, not camtool's reader): every fed point lies on the drawing and
every drawn point is cut, within test_rs274_drawing.py's :data:`LIMIT_MM` (the fit's
tolerance, chords of an arc the controller's check refuses, the 3 decimals, a closed gap).
A mirrored plane read as unmirrored, a lost block transform or a dropped entity moves
points by millimetres.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from scipy.spatial import cKDTree

from camtool.cli.main import main
from tests.corpus.dxf_exact import densified, drawn_pieces
from tests.corpus.test_rs274 import needs_rs274, rs274
from tests.corpus.test_rs274_drawing import LIMIT_MM, STEP_MM, fed_points

SEEDS = range(12)
KINDS = ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE", "ELLIPSE", "SPLINE")


def _entities(layout: object, rng: random.Random) -> None:
    """One to four random entities in ``layout``, some in the mirrored plane."""
    add = layout  # a BaseLayout: model space or a block
    for _ in range(rng.randint(1, 4)):
        kind = rng.choice(KINDS)
        mirrored = {"extrusion": (0, 0, -1)} if rng.random() < 0.4 else {}
        cx, cy = rng.uniform(-40, 40), rng.uniform(-40, 40)
        if kind == "LINE":
            add.add_line((cx, cy), (cx + rng.uniform(-20, 20), cy + rng.uniform(-20, 20)))
        elif kind == "ARC":
            r, a0, a1 = rng.uniform(1, 15), rng.uniform(0, 360), rng.uniform(0, 360)
            add.add_arc((cx, cy), r, a0, a1, dxfattribs=mirrored)
        elif kind == "CIRCLE":
            add.add_circle((cx, cy), rng.uniform(1, 15), dxfattribs=mirrored)
        elif kind == "LWPOLYLINE":
            points = [
                (cx + rng.uniform(-15, 15), cy + rng.uniform(-15, 15), 0, 0, rng.uniform(-1.5, 1.5))
                for _ in range(rng.randint(2, 6))
            ]
            closed = rng.random() < 0.5
            add.add_lwpolyline(points, format="xyseb", close=closed, dxfattribs=mirrored)
        elif kind == "POLYLINE":
            points = [(cx + rng.uniform(-15, 15), cy + rng.uniform(-15, 15)) for _ in range(4)]
            line = add.add_polyline2d(points, close=rng.random() < 0.5, dxfattribs=mirrored)
            for vertex in line.vertices:
                vertex.dxf.bulge = rng.uniform(-1.2, 1.2) if rng.random() < 0.4 else 0.0
        elif kind == "ELLIPSE":
            a, turn, start = rng.uniform(2, 15), rng.uniform(0, math.tau), rng.uniform(0, 6)
            end = start + rng.choice([math.tau, rng.uniform(0.3, 6)])
            add.add_ellipse(
                (cx, cy),
                major_axis=(a * math.cos(turn), a * math.sin(turn), 0),
                ratio=rng.uniform(0.2, 1.0),
                start_param=start,
                end_param=end,
                dxfattribs=mirrored,
            )
        else:
            points = [(cx + rng.uniform(-15, 15), cy + rng.uniform(-15, 15)) for _ in range(5)]
            if rng.random() < 0.5:
                add.add_spline(points)  # by fit points
            else:
                add.add_open_spline(points, degree=rng.choice([2, 3]))


def drawing(seed: int, path: Path) -> None:
    """The seed's DXF: entities in model space and up to two blocks, placed as above."""
    rng = random.Random(seed)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4  # mm
    msp = doc.modelspace()
    _entities(msp, rng)
    for b in range(rng.randint(1, 2)):
        block = doc.blocks.new(f"B{b}", base_point=(rng.uniform(-5, 5), rng.uniform(-5, 5)))
        _entities(block, rng)
        if b and rng.random() < 0.7:  # nested, rotated
            block.add_blockref("B0", (rng.uniform(-9, 9), rng.uniform(-9, 9)), {"rotation": 30})
        for _ in range(rng.randint(1, 2)):
            sx = rng.choice([1, -1, 2, 0.5])
            attribs = {
                "xscale": sx,
                "yscale": rng.choice([1, -1, sx, 0.7]),
                "rotation": rng.uniform(0, 360),
            }
            if rng.random() < 0.3:
                attribs["extrusion"] = (0, 0, -1)
            msp.add_blockref(f"B{b}", (rng.uniform(-40, 40), rng.uniform(-40, 40)), attribs)
    doc.saveas(path)


@needs_rs274
@pytest.mark.parametrize("seed", SEEDS)
def test_rs274_cuts_the_random_drawing_and_nothing_else(tmp_path: Path, seed: int) -> None:
    source = tmp_path / f"random-{seed}.dxf"
    drawing(seed, source)
    out = tmp_path / "out.ngc"
    command = ["post", str(source), "-t", "linuxcnc", "-o", str(out)]
    assert main(command) == 0, f"camtool {' '.join(command)}"
    done = rs274(out)
    assert done.returncode == 0, done.stderr
    fed = fed_points(done.stdout)
    drawn = np.concatenate(
        [densified(points, STEP_MM) for _, points in drawn_pieces(ezdxf.readfile(source))]
    )
    off, _ = cKDTree(drawn).query(fed)
    missed, _ = cKDTree(fed).query(drawn)
    assert off.max() <= LIMIT_MM, f"seed {seed}: a feed passes {fed[off.argmax()]}, off the drawing"
    assert missed.max() <= LIMIT_MM, f"seed {seed}: {drawn[missed.argmax()]} is drawn, never cut"
