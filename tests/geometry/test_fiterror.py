"""The fit's distances (``camtool/geometry/fiterror.py``) against shapely on dense polylines.

Arcs of every kind the fit meets and more (sweeps under and over 180°, half circles, both
directions) and lines, with points inside and outside their sweeps: each distance equals
shapely's distance to the segment sampled at 20 000 points, within that polyline's chord
error. The samples lie on the segment, evenly spaced.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from camtool.geometry import fiterror
from camtool.model.shapes import Arc, Line


def _dense_arc(arc: Arc, n: int = 20000) -> np.ndarray:
    a0 = math.atan2(arc.start[1] - arc.centre[1], arc.start[0] - arc.centre[0])
    t = a0 + arc.sweep * np.linspace(0.0, 1.0, n + 1)
    return np.column_stack(
        [arc.centre[0] + arc.radius * np.cos(t), arc.centre[1] + arc.radius * np.sin(t)]
    )


def _arcs(rng: np.random.Generator) -> list[Arc]:
    out = []
    for _ in range(40):
        c = tuple(rng.normal(0.0, 10.0, 2).tolist())
        r = float(10.0 ** rng.uniform(-1, 1.5))
        a0 = float(rng.uniform(-math.pi, math.pi))
        sweep = float(rng.choice([rng.uniform(0.05, 3.1), rng.uniform(3.2, 6.2), math.pi]))
        cw = bool(rng.random() < 0.5)
        a1 = a0 - sweep if cw else a0 + sweep
        start = (c[0] + r * math.cos(a0), c[1] + r * math.sin(a0))
        end = (c[0] + r * math.cos(a1), c[1] + r * math.sin(a1))
        out.append(Arc(start, end, c, cw))  # type: ignore[arg-type]
    return out


@pytest.mark.parametrize("seed", range(3))
def test_arc_distances_equal_shapely_on_a_dense_arc(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for arc in _arcs(rng):
        dense = _dense_arc(arc)
        chord_error = arc.radius * (1 - math.cos(abs(arc.sweep) / 40000))
        xy = np.vstack([rng.normal(arc.centre, 2 * arc.radius, (200, 2)), dense[::997]])
        want = shapely.distance(shapely.points(xy), shapely.LineString(dense))
        got = fiterror.dist_arc(xy, arc)
        assert np.allclose(got, want, rtol=0, atol=chord_error + 1e-9 * arc.radius), arc


def test_line_distances_equal_shapely() -> None:
    rng = np.random.default_rng(9)
    for _ in range(50):
        a, b = (tuple(v) for v in rng.normal(0.0, 10.0, (2, 2)).tolist())
        xy = rng.normal(0.0, 15.0, (100, 2))
        want = shapely.distance(shapely.points(xy), shapely.LineString([a, b]))
        assert np.allclose(fiterror.dist_line(xy, a, b), want, rtol=0, atol=1e-12)  # type: ignore[arg-type]
    assert fiterror.dist_line(np.array([[3.0, 4.0]]), (0.0, 0.0), (0.0, 0.0))[0] == 5.0


def test_samples_lie_on_the_segment_evenly() -> None:
    arc = Arc((1.0, 0.0), (0.0, -1.0), (0.0, 0.0), False)  # 270° counter-clockwise
    pts = fiterror.sample(arc, 6)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 1.0, atol=1e-15)
    angles = np.unwrap(np.arctan2(pts[:, 1], pts[:, 0]))
    assert np.allclose(np.diff(angles), 1.5 * math.pi / 6, atol=1e-12)
    assert tuple(pts[0]) == arc.start and np.allclose(pts[-1], arc.end, atol=1e-15)
    line = fiterror.sample(Line((0.0, 0.0), (4.0, 2.0)), 4)
    assert line.tolist() == [[0.0, 0.0], [1.0, 0.5], [2.0, 1.0], [3.0, 1.5], [4.0, 2.0]]
