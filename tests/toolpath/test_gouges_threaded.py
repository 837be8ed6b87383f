"""The gouge check's GEOS work on every core: the findings of each cut checked alone.

:func:`camtool.toolpath.compensate.gouges` sweeps every profile cut and intersects the
sweeps with the material in parts on threads (:func:`camtool.accel.pool.parts_threaded`).
The reference here is the check written the plain way, one cut after the other with
shapely's own objects (``LineString.buffer``, ``STRtree.query`` of the one sweep,
``Polygon.intersection``): the same findings, in the same order, to the last bit.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
import shapely
from shapely import LineString, STRtree

from camtool.accel.pool import parts_threaded
from camtool.model.shapes import Contour
from camtool.toolpath import compensate as compensate_module
from camtool.toolpath.compensate import GEOS_PART, _finding, gouges, material, quad_segs
from camtool.toolpath.cuts import Finding
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting
from tests.toolpath.contours import rect


def _plain_gouges(contours: list[Contour], options: PlanOptions, cuts: Any) -> list[Finding]:
    """The gouge check one cut at a time, with shapely's objects (the reference)."""
    tol = options.tolerance / 4
    nest = nesting(contours)
    regions = material(contours, nest, options.offset, tol)
    tree = STRtree(regions)
    segs = quad_segs(options.radius, tol)
    out = []
    for cut in cuts:
        if cut.kind != "profile":
            continue
        swept = LineString(cut.path.points(tol)).buffer(options.radius, quad_segs=segs)
        for k in tree.query(swept, predicate="intersects"):
            overlap = swept.intersection(regions[k])
            for part in getattr(overlap, "geoms", [overlap]):
                if (
                    part.geom_type == "Polygon"
                    and 2.0 * part.area > options.tolerance * part.length
                ):
                    out.append(_finding(contours[cut.group], part, options))
    return out


def _plate(rows: int, columns: int, gap: float) -> list[Contour]:
    """A grid of 10 mm squares ``gap`` mm apart, every third with a 4 mm hole in it."""
    out = []
    for i in range(rows):
        for j in range(columns):
            x, y = j * (10.0 + gap), i * (10.0 + gap)
            out.append(rect(x, y, x + 10.0, y + 10.0))
            if (i + j) % 3 == 0:
                out.append(rect(x + 3.0, y + 3.0, x + 7.0, y + 7.0))
    return out


@pytest.mark.parametrize(("side", "diameter"), [("outside", 3.0), ("inside", 4.5)])
@pytest.mark.parametrize("batch", [7, 128])
def test_the_threaded_check_finds_what_each_cut_checked_alone_finds(
    side: str, diameter: float, batch: int, accel: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 9 × 9 squares 2 mm apart: a 3 mm tool outside sweeps 1 mm into each neighbour (four
    # gouges a square inside the grid); inside, a 4.5 mm tool in the 4 mm holes cuts the
    # walls around them. Over GEOS_PART cuts and pairs: several parts, on threads.
    monkeypatch.setattr(compensate_module, "GOUGE_BATCH", batch)  # cuts held at once
    contours = _plate(9, 9, 2.0)
    options = PlanOptions(offset=side, tool_diameter=diameter, feed_mm_min=100.0)
    nest = nesting(contours)
    stage = compensate_module.compensate(contours, nest, options)
    cuts = stage.cuts
    assert len(cuts) > 2 * GEOS_PART
    got = gouges(contours, nest, cuts, options)
    want = _plain_gouges(contours, options, cuts)
    assert len(want) > GEOS_PART
    assert [(f.kind, f.message, f.at, f.value) for f in got] == [
        (f.kind, f.message, f.at, f.value) for f in want
    ]


def test_parts_threaded_gives_one_call_s_array() -> None:
    rng = np.random.default_rng(7)
    centres = rng.uniform(0, 100, size=(5 * GEOS_PART + 3, 2))
    points = shapely.points(centres)
    whole = shapely.buffer(points, 2.5, quad_segs=7)
    parted = parts_threaded(
        lambda part: shapely.buffer(points[part], 2.5, quad_segs=7), len(points), 32
    )
    assert parted.shape == whole.shape
    assert all(shapely.to_wkb(a) == shapely.to_wkb(b) for a, b in zip(parted, whole, strict=True))
    assert len(parts_threaded(lambda part: shapely.buffer(points[part], 1.0), 0, 32)) == 0
