"""Zigzag pocket lines: parallel lines clipped to an area, ordered boustrophedon.

Used by :mod:`camtool.toolpath.pocket` for ``--pocket zigzag``: after the wall ring,
the area the tool centre may reach (the region shrunk by the tool radius and a small
margin) is crossed by lines at the step-over spacing and the ``--pocket-angle``.
Lines that an island interrupts become separate pieces; the pieces are ordered
greedily, each starting at its end nearest the tool (which gives the back-and-forth
of a zigzag row after row, and finishes one side of an island before the other).

Conventions: mm, Y up; angles in degrees counter-clockwise from +X.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from shapely import affinity
from shapely.geometry.base import BaseGeometry

from camtool.model.shapes import Line, Point

__all__ = ["order_lines", "zigzag_lines"]


def zigzag_lines(area: BaseGeometry, spacing: float, angle_deg: float) -> list[Line]:
    """Lines at ``angle_deg`` and ``spacing`` mm apart, clipped to ``area``.

    The lines are centred across the area (the outermost ones at most ``spacing / 2``
    from its edge). Each returned line runs in the direction of ``angle_deg``.

    Args:
        area: where the tool centre may go (polygon or multipolygon), mm.
        spacing: distance between neighbouring lines, mm (> 0).
        angle_deg: line direction, degrees CCW from +X.

    Returns:
        The pieces, row by row; empty when ``area`` is empty.
    """
    if area.is_empty:
        return []
    flat = affinity.rotate(area, -angle_deg, origin=(0.0, 0.0))
    x0, y0, x1, y1 = flat.bounds
    height = y1 - y0
    count = max(1, math.ceil(height / spacing - 1e-9))
    first = y0 + 0.5 * (height - (count - 1) * spacing)
    ys = first + spacing * np.arange(count)
    rows = shapely.linestrings(
        np.stack(
            [
                np.column_stack([np.full(count, x0 - 1.0), ys]),
                np.column_stack([np.full(count, x1 + 1.0), ys]),
            ],
            axis=1,
        )
    )
    cos_a, sin_a = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))

    def back(x: float, y: float) -> Point:
        return (x * cos_a - y * sin_a, x * sin_a + y * cos_a)

    out: list[Line] = []
    for row, y in zip(shapely.intersection(rows, flat), ys, strict=True):
        spans = sorted(
            (min(p[0] for p in g.coords), max(p[0] for p in g.coords)) for g in _lines_of(row)
        )
        out.extend(Line(back(a, float(y)), back(b, float(y))) for a, b in spans if b > a)
    return out


def _lines_of(geom: BaseGeometry) -> list[BaseGeometry]:
    if geom.is_empty:
        return []
    if geom.geom_type == "LineString":
        return [geom]
    return [g for part in getattr(geom, "geoms", ()) for g in _lines_of(part)]


def order_lines(lines: Sequence[Line], start: Point) -> list[Line]:
    """Greedy nearest-end order: each line starts at its end nearest the previous end.

    Args:
        lines: the line pieces, mm.
        start: the tool position before the first line, mm.

    Returns:
        The lines in cutting order, each possibly reversed.
    """
    if not lines:
        return []
    ends = np.array([[*ln.start, *ln.end] for ln in lines], dtype=np.float64)
    left = np.ones(len(lines), dtype=bool)
    out: list[Line] = []
    here = np.array(start, dtype=np.float64)
    for _ in range(len(lines)):
        d_start = np.hypot(ends[:, 0] - here[0], ends[:, 1] - here[1])
        d_end = np.hypot(ends[:, 2] - here[0], ends[:, 3] - here[1])
        d_start[~left] = np.inf
        d_end[~left] = np.inf
        k_start, k_end = int(np.argmin(d_start)), int(np.argmin(d_end))
        if d_end[k_end] < d_start[k_start]:
            line = lines[k_end].reversed()
            left[k_end] = False
        else:
            line = lines[k_start]
            left[k_start] = False
        out.append(line)
        here = np.array(line.end, dtype=np.float64)
    return out
