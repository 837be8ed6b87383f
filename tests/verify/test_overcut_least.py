"""The overcut's least distance, measured only where it can be least, is the full minimum.

``drawing_compare._least_nearest`` measures every ``OVERCUT_ANCHOR``-th trace point first and
then only the points whose bound from the anchors beside them (the triangle inequality,
less the search's tolerance) can reach the least anchor's distance. The judge is the
plain form it replaced: ``np.min`` of :func:`nearest_distances` of every point, bit for
bit, on drawings of circles and polylines with traces about a tool radius off, with
gouges between anchors, and on the benchmark part's drawing.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from camtool.verify import drawing_compare, nearest_search


def _plain(points: np.ndarray, samples: np.ndarray, sizes: list[int]) -> float:
    same = drawing_compare._same_contour(sizes)
    d = nearest_search.nearest_distances(points, samples[:-1][same], samples[1:][same])
    return float(np.min(d)) if len(d) else math.inf


def _drawing(rng: np.random.Generator) -> tuple[np.ndarray, list[int]]:
    """A circle of radius 5 and an open zig-zag, sampled ~5 µm apart."""
    t = np.linspace(0.0, 2.0 * np.pi, 6000)
    circle = np.column_stack([20 + 5 * np.cos(t), 20 + 5 * np.sin(t)])
    corners = np.cumsum(rng.uniform(-3, 3, (6, 2)), axis=0) + np.asarray([40.0, 10.0])
    pieces = [np.linspace(p, q, 800, endpoint=False) for p, q in itertools.pairwise(corners)]
    zig = np.vstack([*pieces, corners[-1:]])
    return np.vstack([circle, zig]), [len(circle), len(zig)]


def _trace(rng: np.random.Generator, n: int, gouges: int) -> np.ndarray:
    """A tool-centre path 1.5 mm outside the circle with µm noise, and sharp gouges."""
    t = np.linspace(0.0, 2.0 * np.pi, n)
    radius = 6.5 + rng.normal(0.0, 0.002, n)
    for at in rng.integers(0, n, gouges):
        radius[at] -= rng.uniform(0.001, 0.02)  # one point nearer, between anchors or on one
    return np.column_stack([20 + radius * np.cos(t), 20 + radius * np.sin(t)])


@pytest.mark.parametrize("seed", range(8))
def test_least_nearest_is_the_minimum_of_every_point(seed: int) -> None:
    rng = np.random.default_rng(seed)
    samples, sizes = _drawing(rng)
    points = _trace(rng, int(rng.integers(20_000, 60_000)), gouges=int(rng.integers(0, 4)))
    assert len(points) >= drawing_compare.OVERCUT_PRUNE_FROM
    assert drawing_compare._least_nearest(points, samples, sizes) == _plain(points, samples, sizes)


@pytest.mark.parametrize("offset", [1, 2, 3])
def test_a_single_deep_point_between_anchors_is_found(
    offset: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One point far nearer than its anchors: only the anchors' gap lets it through."""
    monkeypatch.setattr(drawing_compare, "OVERCUT_PRUNE_FROM", 0)
    rng = np.random.default_rng(offset)
    samples, sizes = _drawing(rng)
    points = _trace(rng, 4001, gouges=0)
    k = 4 * 500 + offset  # not an anchor
    points[k] = points[k] + (np.array([20.0, 20.0]) - points[k]) * 0.2  # 1.3 mm nearer
    got = drawing_compare._least_nearest(points, samples, sizes)
    assert got == _plain(points, samples, sizes)
    assert got < 0.3


def test_few_points_or_no_chords(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(9)
    samples, sizes = _drawing(rng)
    points = _trace(rng, 500, gouges=1)  # under OVERCUT_PRUNE_FROM: measured at once
    assert drawing_compare._least_nearest(points, samples, sizes) == _plain(points, samples, sizes)
    monkeypatch.setattr(drawing_compare, "OVERCUT_PRUNE_FROM", 0)
    single = np.asarray([[1.0, 2.0], [3.0, 4.0]])
    assert drawing_compare._least_nearest(points, single, [1, 1]) == math.inf  # two lone points
    assert drawing_compare._least_nearest(points[:0], samples, sizes) == math.inf


def test_every_point_an_anchor_or_a_candidate(monkeypatch: pytest.MonkeyPatch) -> None:
    """Anchors every point, or every 1 000th: the same minimum."""
    monkeypatch.setattr(drawing_compare, "OVERCUT_PRUNE_FROM", 0)
    rng = np.random.default_rng(4)
    samples, sizes = _drawing(rng)
    points = _trace(rng, 9000, gouges=3)
    want = _plain(points, samples, sizes)
    for every in (1, 2, 1000, 20_000):
        monkeypatch.setattr(drawing_compare, "OVERCUT_ANCHOR", every)
        assert drawing_compare._least_nearest(points, samples, sizes) == want


@pytest.mark.parametrize("rows", [1, 7, 4096])
def test_the_bounds_taken_a_part_at_a_time_find_the_same_least(
    rows: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Parts of ``OVERCUT_BOUND_ROWS`` points (edges between anchors, a lone point, one
    anchor's neighbours split): the least distance of every point, as in one part."""
    monkeypatch.setattr(drawing_compare, "OVERCUT_PRUNE_FROM", 0)
    monkeypatch.setattr(drawing_compare, "OVERCUT_BOUND_ROWS", rows)
    rng = np.random.default_rng(rows)
    samples, sizes = _drawing(rng)
    points = _trace(rng, 9001 if rows > 1 else 801, gouges=3)
    assert drawing_compare._least_nearest(points, samples, sizes) == _plain(points, samples, sizes)
