"""A closed contour touching another's edge from inside is inside it (a hole, by even-odd).

LibreCAD's library drawing ``kinetics/kin82.dxf`` has a ø5 mm circle inside a ø15 mm
circle, touching it at one point. Nesting compares the circles' chord polygons, and where
they meet the answer depends on the last bits of two cosines; read as an outline of its
own, the hole would be cut 1 mm too large under ``--offset outside`` (through the part)
and on its wrong side under ``--offset inside``.

Expected values by analysis: a hole of radius 2.5 cut outside the material by a 1 mm tool
is cut at radius 2.0 about its centre, the outline of radius 7.5 at 8.0.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import pytest

from camtool.importers import read_drawing
from camtool.model.program import ArcMove, Linear
from camtool.model.shapes import Contour
from camtool.toolpath import order
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.plan import plan_drawing
from tests.corpus.conftest import CORPUS

BIG = ((0.0, 9.5), 7.5)
SMALL = ((0.0, 4.5), 2.5)  # touches BIG at (0, 2) from inside
KIN82 = CORPUS / "pkg/librecad-data/usr/share/librecad/library/kinetics/kin82.dxf"


def _drawing(tmp_path: Path, circles: list[tuple[tuple[float, float], float]]) -> Path:
    doc = ezdxf.new("R2000")
    doc.header["$INSUNITS"] = 4  # mm
    for centre, radius in circles:
        doc.modelspace().add_circle(centre, radius)
    path = tmp_path / "touch.dxf"
    doc.saveas(path)
    return path


def _circles(path: Path) -> tuple[list[Contour], int, int]:
    """The drawing's closed contours, and the indices of the big and the small circle."""
    contours = [c for c in read_drawing(path).contours if c.closed]
    radii = [c.bbox()[2] - c.bbox()[0] for c in contours]
    return contours, radii.index(max(radii)), radii.index(min(radii))


def test_a_circle_touching_its_outline_from_inside_is_its_hole(tmp_path: Path) -> None:
    contours, big, small = _circles(_drawing(tmp_path, [BIG, SMALL]))
    for nest in (order.nesting(contours), order._nesting_one_by_one(contours)):
        assert nest.parents[small] == (big,)
        assert nest.parents[big] == ()


@pytest.mark.parametrize(
    "circle",
    [
        ((0.0, 4.499), 2.5),  # leaves the outline by 1 µm: it crosses it
        ((0.0, -0.5), 2.5),  # touches it from outside
    ],
)
def test_a_circle_past_the_edge_is_not_inside(
    tmp_path: Path, circle: tuple[tuple[float, float], float]
) -> None:
    contours, _, small = _circles(_drawing(tmp_path, [BIG, circle]))
    for nest in (order.nesting(contours), order._nesting_one_by_one(contours)):
        assert nest.parents[small] == ()


def _cut_radii(path: Path, offset: str) -> tuple[list[float], list[float], list[str]]:
    """Distances of the cutting moves' ends from the small and the big circle's centres."""
    planned = plan_drawing(
        read_drawing(path),
        PlanOptions(offset=offset, tool_diameter=1.0, depth=1.0, feed_mm_min=600.0),
    )
    ends, z = [], 0.0
    for m in planned.program.moves:
        z = z if m.z is None else m.z
        if isinstance(m, Linear | ArcMove) and z < 0:
            ends.append((m.x, m.y))
    near_small = [math.dist(p, SMALL[0]) for p in ends if math.dist(p, SMALL[0]) < 4.0]
    near_big = [math.dist(p, BIG[0]) for p in ends if math.dist(p, SMALL[0]) >= 4.0]
    kinds = [f.kind for f in planned.report.findings]
    return near_small, near_big, kinds


def test_outside_cuts_the_touching_hole_inside_it_without_a_gouge(tmp_path: Path) -> None:
    near_small, near_big, kinds = _cut_radii(_drawing(tmp_path, [BIG, SMALL]), "outside")
    assert near_small and all(abs(r - 2.0) < 1e-3 for r in near_small)
    assert near_big and all(abs(r - 8.0) < 1e-3 for r in near_big)
    assert "gouge" not in kinds


@pytest.mark.skipif(not KIN82.is_file(), reason="the corpus is not fetched")
def test_librecads_kin82_outside_cuts_its_hole_inside_it() -> None:
    """The real drawing: its two circles are BIG and SMALL (with centre lines, not cut)."""
    near_small, near_big, kinds = _cut_radii(KIN82, "outside")
    assert near_small and all(abs(r - 2.0) < 1e-3 for r in near_small)
    assert near_big and all(abs(r - 8.0) < 1e-3 for r in near_big)
    assert "gouge" not in kinds
