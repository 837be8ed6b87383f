"""Distances from points taken along a path: GEOS's nearest query's floats, bit for bit.

:func:`camtool.verify.nearest_along.along_distances` against shapely's ``STRtree``
nearest query over every segment (GEOS, the independent answer the drawing comparison
took before): the same float64 bits, for a drawing's points (contour after contour, a few
µm apart) against a programmed path of arcs as chords of many lengths and single points.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from camtool import accel
from camtool.verify import drawing_compare, nearest_along, nearest_exact

pytestmark = pytest.mark.usefixtures("accel_on")
pytest.importorskip("camtool.accel.nearkernels")


def _geos(samples: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Shapely's nearest query over every segment ``a → b`` (a point where they are equal)."""
    shapes = np.where(
        np.all(a == b, axis=1),
        shapely.points(a),
        shapely.linestrings(np.stack([a, b], axis=1)),
    )
    tree = shapely.STRtree(shapes)
    _, d = tree.query_nearest(shapely.points(samples), return_distance=True, all_matches=False)
    return np.asarray(d, dtype=np.float64)


def _part(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drawing points 5 µm apart along circles and a square; the path 1.5 mm outside them.

    The path's arcs are chords of 0.02–0.6 mm, a few of them 3 mm long, with holes drilled
    as single points (zero-length segments).
    """
    samples, a, b = [], [], []
    for _ in range(int(rng.integers(3, 7))):
        centre = rng.uniform(0.0, 60.0, 2)
        radius = float(rng.uniform(1.0, 8.0))
        t = np.arange(0.0, 2 * np.pi, 0.005 / radius)
        samples.append(centre + radius * np.c_[np.cos(t), np.sin(t)])
        chord = float(rng.choice([0.02, 0.1, 0.6]))
        u = np.linspace(0.0, 2 * np.pi, max(8, int(2 * np.pi * (radius + 1.5) / chord)))
        path = centre + (radius + 1.5) * np.c_[np.cos(u), np.sin(u)]
        a.append(path[:-1])
        b.append(path[1:])
    x = np.arange(0.0, 20.0, 0.005)
    square = np.concatenate([np.c_[x, 0 * x], np.c_[20 + 0 * x, x], np.c_[20 - x, 20 + 0 * x]])
    samples.append(square + 70.0)
    corners = np.array([[-1.5, -1.5], [21.5, -1.5], [21.5, 21.5], [-1.5, 21.5]]) + 70.0
    a.append(corners[:-1])  # three 23 mm sides among short chords
    b.append(corners[1:])
    holes = rng.uniform(0.0, 90.0, (5, 2))
    return np.concatenate(samples), np.concatenate([*a, holes]), np.concatenate([*b, holes])


@pytest.mark.parametrize("seed", range(3))
def test_along_distances_are_geos_nearest_query_bit_for_bit(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(seed)
    samples, a, b = _part(rng)
    want = _geos(samples, a, b)
    got = nearest_along.along_distances(samples, a, b)
    assert got is not None and got.tobytes() == want.tobytes()
    # blocks with many ends near them go to GEOS's query; pairs measured a few at a time
    monkeypatch.setattr(nearest_along, "ALONG_MAX_CANDIDATES", 12)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 5000)
    got = nearest_along.along_distances(samples, a, b)
    assert got is not None and got.tobytes() == want.tobytes()
    # the blocks' spreads a few blocks at a time (the last part short, its last block too)
    for blocks in (1, 3):
        monkeypatch.setattr(nearest_along, "ALONG_PART_BLOCKS", blocks)
        got = nearest_along.along_distances(samples[:-5], a, b)
        assert got is not None and got.tobytes() == want[:-5].tobytes()


def test_samples_out_of_order_are_still_exact() -> None:
    """Blocks of points far apart have wide reaches (slower), never a wrong distance."""
    rng = np.random.default_rng(7)
    samples, a, b = _part(rng)
    samples = samples[rng.permutation(len(samples))[:20_000]]
    got = nearest_along.along_distances(samples, a, b)
    assert got is not None and got.tobytes() == _geos(samples, a, b).tobytes()


def test_no_segments_and_no_samples() -> None:
    samples = np.array([[0.0, 0.0], [1.0, 1.0]])
    none = np.zeros((0, 2))
    assert np.array_equal(nearest_along.along_distances(samples, none, none), [np.inf] * 2)
    got = nearest_along.along_distances(none, samples[:1], samples[1:])
    assert got is not None and len(got) == 0


def test_without_the_compiled_distance_the_comparison_asks_shapely(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    rng = np.random.default_rng(3)
    samples, a, b = _part(rng)
    lines = [np.stack([p, q]) for p, q in zip(a[:50], b[:50], strict=True)] + [a[-1:]]
    chords = np.concatenate([np.stack([line[:-1], line[1:]], axis=1) for line in lines[:-1]])
    want = _geos(samples, np.r_[chords[:, 0], a[-1:]], np.r_[chords[:, 1], a[-1:]])
    got = drawing_compare._distance_to_now(samples, lines)
    assert got.tobytes() == want.tobytes()
    monkeypatch.setenv(accel.SWITCH, "0")
    assert nearest_along.along_distances(samples, a, b) is None
    assert drawing_compare._distance_to_now(samples, lines).tobytes() == want.tobytes()
