"""nearest_distances against shapely's own distance (an independent evaluator), point by point."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from camtool.verify.metrics import NEAREST_TOLERANCE_MM, nearest_distances


def _shapely(samples: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    return np.array([shapely.distance(lines, shapely.Point(p)).min() for p in samples])


@pytest.mark.parametrize(
    ("step_mm", "reach_mm"),
    [(0.004, 0.01), (0.004, 1.5), (0.0005, 0.002), (5.0, 0.5), (0.05, 3.0)],
    ids=["steps-near", "steps-tool-radius", "fine", "long-segments", "mixed"],
)
def test_equals_the_distance_to_the_nearest_segment(step_mm: float, reach_mm: float) -> None:
    rng = np.random.default_rng(7)
    # a wandering polyline: a circle of radius 2 mm walked in steps, with jitter
    n = max(8, int(2 * np.pi * 2.0 / step_mm))
    angle = np.linspace(0.0, 2 * np.pi, n)
    trace = np.c_[2 * np.cos(angle), 2 * np.sin(angle)] + rng.normal(0, step_mm / 4, (n, 2))
    samples = rng.uniform(-2.0 - reach_mm, 2.0 + reach_mm, (400, 2))
    got = nearest_distances(samples, trace[:-1], trace[1:])
    assert np.max(np.abs(got - _shapely(samples, trace[:-1], trace[1:]))) <= NEAREST_TOLERANCE_MM


def test_points_and_no_segments() -> None:
    p = np.array([[0.0, 0.0], [3.0, 4.0]])
    assert nearest_distances(p, p[:1], p[:1]) == pytest.approx([0.0, 5.0])
    assert np.isinf(nearest_distances(p, np.zeros((0, 2)), np.zeros((0, 2)))).all()
