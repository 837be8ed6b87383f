"""Helpers of the SVG importer tests: SVG files in tmp_path, the TRUE curve, two-sided errors.

Expected curves come from svgpathtools (an SVG library independent of svgelements, which the
importer uses), sampled densely; distances to lines and arcs are computed here, exactly.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import shapely
from svgpathtools import parse_path

from camtool.model.shapes import Arc, Contour, Drawing, Line

DATA = Path(__file__).resolve().parents[1] / "data"
INK = 'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'
Map = Callable[[np.ndarray], np.ndarray]  # (N, 2) user units -> (N, 2) mm


def svg(tmp_path: Path, body: str, root: str = 'width="100mm" height="100mm" viewBox="0 0 100 100"',
        name: str = "t.svg") -> Path:  # fmt: skip
    path = tmp_path / name
    path.write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" {INK} '
        f'xmlns:xlink="http://www.w3.org/1999/xlink" {root}>{body}</svg>',
        encoding="utf-8",
    )
    return path


def page(xy: np.ndarray) -> np.ndarray:
    """The default test page: 100 x 100 mm, viewBox 0 0 100 100, so (x, y) -> (x, 100 - y)."""
    return np.column_stack([xy[:, 0], 100.0 - xy[:, 1]])


def one(drawing: Drawing) -> Contour:
    assert len(drawing.contours) == 1, drawing.contours
    return drawing.contours[0]


def vertices(contour: Contour) -> list[tuple[float, float]]:
    return [contour.start, *(s.end for s in contour.segments)]


def assert_arc(seg: object, centre: tuple[float, float], radius: float, clockwise: bool) -> Arc:
    assert isinstance(seg, Arc), seg
    assert seg.centre == pytest.approx(centre, abs=1e-9)
    assert seg.radius == pytest.approx(radius, abs=1e-9)
    assert seg.clockwise is clockwise
    return seg


def true_curve(d: str, to_mm: Map, n: int = 4001) -> np.ndarray:
    """``(n, 2)`` points of the path ``d`` evaluated by svgpathtools, mapped to mm."""
    curve = parse_path(d)
    z = np.array([curve.point(t) for t in np.linspace(0.0, 1.0, n)])
    return to_mm(np.column_stack([z.real, z.imag]))


def seg_distance(xy: np.ndarray, seg: Line | Arc) -> np.ndarray:
    """Exact distance from each point ``(N, 2)`` to a line or arc, mm."""
    if isinstance(seg, Line):
        a, b = np.array(seg.start), np.array(seg.end)
        d = b - a
        u = np.clip((xy - a) @ d / float(d @ d), 0.0, 1.0)
        return np.linalg.norm(xy - a - u[:, None] * d, axis=1)
    rel = xy - np.array(seg.centre)
    ang = np.arctan2(rel[:, 1], rel[:, 0]) - seg.start_angle
    travelled = np.mod(ang if seg.sweep > 0 else -ang, 2 * math.pi)
    ends = np.minimum(
        np.linalg.norm(xy - np.array(seg.start), axis=1),
        np.linalg.norm(xy - np.array(seg.end), axis=1),
    )
    radial = np.abs(np.linalg.norm(rel, axis=1) - seg.radius)
    return np.where(travelled <= abs(seg.sweep), radial, ends)


def sample_segments(contours: list[Contour], n: int = 64) -> np.ndarray:
    u = np.linspace(0.0, 1.0, n + 1)
    out = []
    for seg in (s for c in contours for s in c.segments):
        if isinstance(seg, Line):
            a, b = np.array(seg.start), np.array(seg.end)
            out.append(a + u[:, None] * (b - a))
        else:
            out.append(np.array([seg.point_at(float(k)) for k in u]))
    return np.vstack(out)


def two_sided_error(contours: list[Contour], curve: np.ndarray) -> tuple[float, float]:
    """(max distance from curve samples to the contours, max distance back), mm.

    The first is exact per sample; the second measures fitted samples against the polyline
    through the curve samples, whose chord error is below 1e-6 mm at the sizes used here.
    """
    segs = [s for c in contours for s in c.segments]
    there = np.min([seg_distance(curve, s) for s in segs], axis=0)
    chords = shapely.STRtree(shapely.linestrings(np.stack([curve[:-1], curve[1:]], axis=1)))
    _, back = chords.query_nearest(shapely.points(sample_segments(contours)), return_distance=True)
    return float(np.max(there)), float(np.max(back))


def arc_only(drawing: Drawing) -> Arc:
    (seg,) = one(drawing).segments
    assert isinstance(seg, Arc)
    return seg


HALF = '<path d="M 10 50 A 20 20 0 0 1 50 50" fill="none" stroke="black"/>'
"""A half circle, clockwise, centre (30, 50), r 20, stroked (a fill would show it closed)."""
