"""Random jobs (inside profiles, a pocket, an outside profile with tabs) where rs274 moves the tool.

Each seed draws a plate (a star-shaped outline of lines and bulged arcs on layer OUTLINE),
up to four holes (circles on HOLES) and up to two pockets (bulged outlines on POCKET),
writes the job a machinist would (holes cut inside, pockets cleared concentric or zigzag,
the outline cut outside with or without tabs, one end mill of 1-3.175 mm) and posts it to
linuxcnc in-process. LinuxCNC's ``rs274`` reads the program; its moves are judged against
the drawing sampled from its DXF definitions (tests/corpus/dxf_exact.py) with shapely:

- **no gouge**: every cutting point (below Z 0) keeps the tool centre at least the tool
  radius, less :data:`SLACK_MM`, from the material left at its depth (the plate less its
  holes; above the pocket floor, less the pockets too);
- **every edge cut**: the outline's and the holes' offsets by the tool radius (the tool
  centre's path around a round tool, corners rounded) are followed within
  :data:`FOLLOW_MM` at full depth (at the tabs' height where there are tabs), and every point
  of a pocket the tool fits in is within the radius of a centre on its floor;
- **no rapid at cutting height**: no G0 moves sideways below the top or down into the part.

:data:`SLACK_MM`: 0.001 mm fit tolerance, 0.0007 mm of three decimals, 0.002 mm of chords
where the controller's arc check refuses an arc, 0.002 mm for the reference's own chords.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import ezdxf
import numpy as np
import pytest
import shapely
from scipy.spatial import cKDTree

from camtool.cli.main import main
from tests.corpus.dxf_exact import primitive_points
from tests.corpus.test_rs274 import arc_points, canon_moves, needs_rs274, rs274

SEEDS = range(14)
SLACK_MM = 0.006
FOLLOW_MM = 0.04
"""Largest gap between a point of an offset and the nearest tool centre sampled every
:data:`STEP_MM` (half a step, plus the slack)."""
STEP_MM = 0.05
DEPTH, POCKET_DEPTH, TAB_HEIGHT = 3.0, 1.0, 1.0


def _star(rng: random.Random, centre: tuple[float, float], r0: float, r1: float) -> list:
    angles = sorted(rng.uniform(0, math.tau) for _ in range(rng.randint(4, 8)))
    out = []
    for a in angles:
        r = rng.uniform(r0, r1)
        bulge = rng.uniform(-0.45, 0.45) if rng.random() < 0.5 else 0.0
        out.append((centre[0] + r * math.cos(a), centre[1] + r * math.sin(a), 0, 0, bulge))
    return out


def _region(entities: list) -> shapely.Geometry:
    polygons = [shapely.Polygon(primitive_points(e)[:, :2]) for e in entities]
    return shapely.union_all(polygons) if polygons else shapely.Polygon()


def job(seed: int, folder: Path) -> tuple[Path, Path, float, int]:
    """The seed's drawing and job file; the tool diameter and the number of tabs."""
    rng = random.Random(seed)
    tool, tabs = rng.choice([1.0, 2.0, 3.0, 3.175]), rng.choice([0, 3])
    while True:  # an outline that does not cross itself
        doc = ezdxf.new("R2010")
        doc.header["$INSUNITS"] = 4
        msp = doc.modelspace()
        for name in ("OUTLINE", "HOLES", "POCKET"):
            doc.layers.add(name)
        plate = msp.add_lwpolyline(
            _star(rng, (50, 40), 25, 40),
            format="xyseb",
            close=True,
            dxfattribs={"layer": "OUTLINE"},
        )
        part = _region([plate])
        if part.is_valid:
            break
    inner, taken = part.buffer(-4), []
    x0, y0, x1, y1 = inner.bounds
    holes, pockets = rng.randint(1, 4), rng.randint(1, 2)
    for _ in range(60):  # tries: the holes first, then the pockets, none overlapping
        at = (rng.uniform(x0, x1), rng.uniform(y0, y1))
        if holes:
            r = rng.uniform(2.5, 6)
            e = msp.add_circle(at, r, dxfattribs={"layer": "HOLES"})
        elif pockets:
            e = msp.add_lwpolyline(
                _star(rng, at, 5, 9), format="xyseb", close=True, dxfattribs={"layer": "POCKET"}
            )
        else:
            break
        shape = _region([e])
        room = shape.buffer(2)
        fits = shape.is_valid and not shape.buffer(-tool).is_empty  # the tool clears some
        if fits and inner.contains(room) and not any(room.intersects(t) for t in taken):
            taken.append(room)
            holes, pockets = (holes - 1, pockets) if holes else (holes, pockets - 1)
        else:
            msp.delete_entity(e)
    layers = {e.dxf.layer for e in msp}
    ops = []
    if "HOLES" in layers:
        ops.append(f'type = "profile"\nlayers = ["HOLES"]\nside = "inside"\ndepth = {DEPTH}')
    if "POCKET" in layers:
        pattern = rng.choice(["concentric", "zigzag"])
        ops.append(f'type = "pocket"\nlayers = ["POCKET"]\ndepth = {POCKET_DEPTH}\n'
                   f'pocket = "{pattern}"')  # fmt: skip
    outline = f'type = "profile"\nlayers = ["OUTLINE"]\nside = "outside"\ndepth = {DEPTH}'
    if tabs:
        outline += f"\ntabs = {tabs}\ntab_height = {TAB_HEIGHT}"
    ops.append(outline)
    text = (
        '[job]\norigin = "drawing"\nclearance_z = 8.0\nsafe_z = 2.0\n'
        f'[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = {tool}\nfeed = 500\n'
    )
    for k, op in enumerate(ops, start=1):
        text += f'[[operations]]\nname = "op{k}"\ntool = 1\nstep_down = 1.5\n{op}\n'
    drawing, job_file = folder / "part.dxf", folder / "part.toml"
    doc.saveas(drawing)
    job_file.write_text(text)
    return drawing, job_file, tool, tabs


def _samples(stdout: str) -> tuple[np.ndarray, list[str]]:
    """``(N, 3)`` points along rs274's feeds, every STEP_MM; and its faulty rapids."""
    here, points, faults = None, [], []
    for kind, v in canon_moves(stdout):
        end = (v[0], v[1], v[5] if kind == "arc" else v[2])
        if here is not None and kind == "rapid":
            sideways = math.dist(here[:2], end[:2]) > 1e-6
            if sideways and min(here[2], end[2]) < 0.0:
                faults.append(f"rapid at Z {min(here[2], end[2])} to {end[:2]}")
            if end[2] < min(here[2], 0.0):
                faults.append(f"rapid down into the part to Z {end[2]}")
        elif here is not None and kind == "arc":
            points += [
                (x, y, end[2]) for x, y in arc_points(here[:2], end[:2], v[2:4], v[4], STEP_MM)
            ]
        elif here is not None:
            n = max(1, int(math.dist(here, end) / STEP_MM))
            points += [
                tuple(np.add(here, np.subtract(end, here) * t)) for t in np.linspace(0, 1, n + 1)
            ]
        here = end
    return np.array(points).reshape(-1, 3), faults


@needs_rs274
@pytest.mark.parametrize("seed", SEEDS)
def test_rs274_cuts_the_random_job_without_gouging(tmp_path: Path, seed: int) -> None:
    drawing, job_file, tool, tabs = job(seed, tmp_path)
    out = tmp_path / "part.ngc"
    command = ["post", str(drawing), "-t", "linuxcnc", "--job", str(job_file), "-o", str(out)]
    assert main(command) == 0, f"camtool {' '.join(command)}"
    done = rs274(out)
    assert done.returncode == 0, done.stderr
    points, faults = _samples(done.stdout)
    assert not faults, faults[:3]
    msp = ezdxf.readfile(drawing).modelspace()
    part, holes, pockets = (
        _region([e for e in msp if e.dxf.layer == n]) for n in ("OUTLINE", "HOLES", "POCKET")
    )
    radius = tool / 2
    cutting = points[points[:, 2] < -1e-6]
    floor = -POCKET_DEPTH - 1e-6
    for material, at in (
        (part.difference(holes).difference(pockets), cutting[cutting[:, 2] >= floor]),
        (part.difference(holes), cutting[cutting[:, 2] < floor]),
    ):
        distance = shapely.distance(material, shapely.points(at[:, :2]))
        distance[shapely.contains_xy(material, at[:, 0], at[:, 1])] *= -1
        worst = int(np.argmin(distance))
        assert distance[worst] >= radius - SLACK_MM, f"seed {seed}: gouge at {at[worst]}"
    full = cutting[cutting[:, 2] <= -(DEPTH - (TAB_HEIGHT if tabs else 0.0)) + 1e-6]
    centres = cKDTree(full[:, :2])
    for edge in (part.buffer(radius, quad_segs=64), holes.buffer(-radius, quad_segs=64)):
        if not edge.is_empty:
            ring = shapely.get_coordinates(shapely.segmentize(edge.boundary, 0.1))
            gap, _ = centres.query(ring)
            assert gap.max() <= FOLLOW_MM, f"seed {seed}: {ring[gap.argmax()]} not followed"
    if not pockets.is_empty:
        reach = pockets.buffer(-radius, quad_segs=64).buffer(radius - 0.05, quad_segs=64)
        x0, y0, x1, y1 = pockets.bounds
        xs, ys = np.meshgrid(np.arange(x0, x1, 0.2), np.arange(y0, y1, 0.2))
        inside = shapely.contains_xy(reach, xs.ravel(), ys.ravel())
        grid = np.c_[xs.ravel()[inside], ys.ravel()[inside]]
        on_floor = cutting[np.abs(cutting[:, 2] + POCKET_DEPTH) < 1e-6]
        gap, _ = cKDTree(on_floor[:, :2]).query(grid)
        assert gap.max() <= radius + 0.02, f"seed {seed}: {grid[gap.argmax()]} left in a pocket"
