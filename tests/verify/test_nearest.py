"""nearest_distances against shapely's own distance (an independent evaluator), point by point."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from camtool.verify.nearest_exact import NEAREST_TOLERANCE_MM
from camtool.verify.nearest_search import nearest_distances


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


@pytest.mark.parametrize("runs", [None, "three", "all-apart"])
def test_the_chords_and_their_ends_are_numpy_s_own_selection_and_concatenation(
    runs: str | None,
) -> None:
    """The machined edge's segments (``_chords``) are the boolean selection of consecutive
    rows of a run, and the ends the searches hold are ``np.concatenate([a, b])``: made in
    one array, handed over without a second copy (the comparison's memory peak)."""
    from camtool.verify.cutting_thin import ThinTrace
    from camtool.verify.drawing_compare import _chords
    from camtool.verify.nearest_search import _end_points

    rng = np.random.default_rng(3)
    points = rng.uniform(-5.0, 5.0, (101, 2))
    run_ids = {
        None: None,
        "three": np.repeat([0, 1, 2], [40, 30, 31]),
        "all-apart": np.arange(101),
    }[runs]
    thin = ThinTrace(points, run_ids, 101)
    a, b = _chords(thin)
    joined = np.ones(100, dtype=bool) if run_ids is None else run_ids[1:] == run_ids[:-1]
    if not joined.any():  # single points: each point to the next
        joined[:] = True
    assert a.dtype == b.dtype == np.float64
    assert np.array_equal(a, points[:-1][joined]) and np.array_equal(b, points[1:][joined])
    ends = _end_points(a, b)
    assert np.array_equal(ends, np.concatenate([a, b]))
    assert ends is a.base is b.base  # no copy of the ends


def test_the_ends_are_shared_only_when_a_and_b_are_the_halves_of_one_array() -> None:
    from camtool.verify.nearest_search import _end_points

    trace = np.arange(24.0).reshape(12, 2).copy()  # an array of its own, not a view
    cases = [
        ((trace[:-1], trace[1:]), False),  # overlapping views of one polyline
        ((trace[:6], trace[6:]), True),  # its two halves: concatenated, they are the array
        ((trace[::2], trace[1::2]), False),  # strided views
        ((trace[6:], trace[:6]), False),  # the halves the other way round
        ((trace[:5].copy(), trace[5:10].copy()), False),  # separate arrays
    ]
    for (a, b), shared in cases:
        ends = _end_points(a, b)
        assert np.array_equal(ends, np.concatenate([a, b]))
        assert (ends is trace) == shared
        assert shared or not np.shares_memory(ends, trace)


def test_the_k_d_tree_s_answers_in_parts_are_the_answers_at_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Samples whose nearest ends tie go to the k-d tree (``_BoxSearch.chosen``) in parts of
    ``NEAREST_CHUNK`` rows: the distances are those of one query of all of them, and each
    is the distance to the nearest segment (shapely)."""
    from camtool.verify import nearest_search

    if nearest_search.near_kernels() is None:
        pytest.skip("the compiled search is off (CAMTOOL_ACCEL=0 or no numba)")
    rng = np.random.default_rng(3)
    steps = np.arange(2_000, dtype=np.float64)
    trace = np.c_[steps * 0.5, (steps % 2) * 0.25]
    samples = np.r_[trace[rng.integers(0, len(trace), 900)], rng.uniform(0, 1000, (300, 2))]
    search = nearest_search._box_search(samples, trace[:-1], trace[1:])
    assert search is not None
    ends = nearest_search._LazyTree(search.points)
    rows = np.arange(len(samples))
    whole = search.chosen(ends, rows)
    monkeypatch.setattr(nearest_search, "NEAREST_CHUNK", 7)
    assert np.array_equal(search.chosen(ends, rows), whole)
    truth = _shapely(samples, trace[:-1], trace[1:])
    assert np.max(np.abs(whole - truth)) <= NEAREST_TOLERANCE_MM


@pytest.mark.parametrize(("samples", "threads"), [(200, False), (4_000, True)])
def test_only_queries_of_many_points_start_threads(
    monkeypatch: pytest.MonkeyPatch, samples: int, threads: bool
) -> None:
    """scipy starts its worker threads at every query: a small one (a job's shortfall asks
    one per contour, thousands of them) runs on one thread, with the same distances."""
    import threading

    from camtool.accel.cores import default_jobs
    from camtool.verify import nearest_exact
    from camtool.verify.nearest_search import nearest_distances_kd

    if threads and default_jobs() < 2:
        pytest.skip("one core: every query runs on one thread")
    monkeypatch.setattr(nearest_exact, "KD_WORKERS", -1)
    rng = np.random.default_rng(7)
    a = rng.uniform(0, 10, (300, 2))
    b = a + rng.uniform(-0.2, 0.2, (300, 2))
    x = rng.uniform(0, 10, (samples, 2))
    started: list[int] = []
    real = threading.Thread.start

    def start(self: threading.Thread) -> None:
        started.append(1)
        real(self)

    monkeypatch.setattr(threading.Thread, "start", start)
    got = nearest_distances_kd(x, a, b)
    assert bool(started) is threads
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    want = shapely.distance(shapely.points(x)[:, None], lines[None, :]).min(axis=1)
    assert np.all(np.abs(got - want) <= NEAREST_TOLERANCE_MM)
