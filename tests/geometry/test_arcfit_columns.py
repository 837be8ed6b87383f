"""The fitter's distance functions worked by column (issue 17): the same floats as before.

The references below are the functions as they were before the speed work (commit b3b77a5,
``einsum`` over ``(…, 2)`` arrays, ``np.clip``, ``np.column_stack``, ``np.linspace``); the
new ones must give every float bit for bit (compared as int64 views, so ``-0.0`` and NaN
count too) on many random inputs, degenerate ones included.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camtool.geometry import arcfit
from camtool.geometry.arcfit import (
    dist_arc,
    dist_line,
    distances,
)
from camtool.model.shapes import TAU, Arc, Line, Segment


def _old_dist_line(xy: np.ndarray, a: tuple[float, float], b: tuple[float, float]) -> np.ndarray:
    dx, dy = b[0] - a[0], b[1] - a[1]
    rx, ry = xy[:, 0] - a[0], xy[:, 1] - a[1]
    ll = dx * dx + dy * dy
    u = np.clip((rx * dx + ry * dy) / ll, 0.0, 1.0) if ll > 0 else np.zeros(len(xy))
    return np.hypot(rx - u * dx, ry - u * dy)


def _old_dist_arc(xy: np.ndarray, arc: Arc) -> np.ndarray:
    rx, ry = xy[:, 0] - arc.centre[0], xy[:, 1] - arc.centre[1]
    sweep = arc.sweep
    ang = np.arctan2(ry, rx) - arc.start_angle
    inside = np.mod(ang if sweep > 0 else -ang, TAU) <= abs(sweep)
    ends = np.minimum(
        np.hypot(xy[:, 0] - arc.start[0], xy[:, 1] - arc.start[1]),
        np.hypot(xy[:, 0] - arc.end[0], xy[:, 1] - arc.end[1]),
    )
    return np.where(inside, np.abs(np.hypot(rx, ry) - arc.radius), ends)


def _old_dist_segment(xy: np.ndarray, seg: Segment) -> np.ndarray:
    if isinstance(seg, Line):
        return _old_dist_line(xy, seg.start, seg.end)
    return _old_dist_arc(xy, seg)


def _old_distances(xy: np.ndarray, segments: list[Segment]) -> np.ndarray:
    return np.min([_old_dist_segment(xy, s) for s in segments], axis=0)


def _same(new: np.ndarray, old: np.ndarray) -> None:
    assert new.shape == old.shape
    assert np.array_equal(new.view(np.int64), old.view(np.int64))


def _points(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    pts = rng.normal(0.0, scale, (n, 2))
    if n > 4:
        pts[1] = pts[0]  # repeated points: zero-length edges
        pts[3, 0] = -0.0
    return pts


def _segments(rng: np.random.Generator, scale: float) -> list[Segment]:
    out: list[Segment] = []
    for _ in range(int(rng.integers(1, 4))):
        p, q, c = (tuple(v) for v in rng.normal(0.0, scale, (3, 2)).tolist())
        if rng.random() < 0.3:
            out.append(Line(p, q) if rng.random() < 0.8 else Line(p, p))  # type: ignore[arg-type]
        else:
            out.append(Arc(p, q if rng.random() < 0.9 else p, c, bool(rng.random() < 0.5)))  # type: ignore[arg-type]
    return out


@pytest.mark.parametrize("seed", range(4))
def test_distance_functions_equal_the_old_ones_bit_for_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(500):
        scale = 10.0 ** rng.uniform(-4, 4)
        xy = _points(rng, int(rng.integers(1, 70)), scale)
        segs = _segments(rng, scale)
        _same(distances(xy, segs), _old_distances(xy, segs))
        for seg in segs:
            if isinstance(seg, Arc):
                _same(dist_arc(xy, seg), _old_dist_arc(xy, seg))
            else:
                _same(dist_line(xy, seg.start, seg.end), _old_dist_line(xy, seg.start, seg.end))


def test_linspace_equals_numpy_bit_for_bit() -> None:
    rng = np.random.default_rng(17)
    pairs = [(0.0, 1.0), (0.0, 5e-324), (1.0, 1.0 + 2**-52), (-0.0, 0.0), (0.25, 0.5)]
    pairs += [tuple(sorted(rng.uniform(-3, 3, 2).tolist())) for _ in range(5000)]  # type: ignore[misc]
    pairs += [(a, a + 10.0 ** rng.uniform(-310, 0)) for a in rng.uniform(0, 1, 3000).tolist()]
    for ta, tb in pairs:
        got = arcfit._linspace(ta, tb)
        _same(got, np.linspace(ta, tb, 2 * arcfit._SAMPLES + 1))
    assert math.isfinite(float(arcfit._linspace(0.0, 1.0)[-1]))
