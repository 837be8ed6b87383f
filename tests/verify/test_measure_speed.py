"""The faster paths of the verifier's measures equal the slow ones exactly (issue 17).

Each fast path is compared with the code it replaces, kept for that purpose, on many
random inputs: equality is bit for bit (``==`` on float64), not approximate, since the
reports are written from these values.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.model.shapes import Arc, Contour, Drawing, Line, Segment
from camtool.post.registry import load_target
from camtool.verify import (
    cutting_thin,
    drawing_compare,
    nearest_exact,
    nearest_search,
    path_shortfall,
)
from camtool.verify.sources import ALL
from camtool.verify.streamed import cutting_rows
from camtool.verify.trace_sources import simulate
from camtool.verify.verifier import verify_program


def _polyline(rng: np.random.Generator, kind: int) -> np.ndarray:
    """A staircase on a step grid (many equal distances) or a jittered arc snapped to one."""
    n = int(rng.integers(2, 2500))
    step = (0.004, 0.0005, 0.5)[kind % 3]
    if kind % 2:
        return np.cumsum(rng.choice([-step, 0.0, step], size=(n, 2)), axis=0)
    angle = np.linspace(0.0, rng.uniform(1.0, 7.0), n)
    radius = rng.uniform(0.1, 3.0)
    pts = np.c_[radius * np.cos(angle), radius * np.sin(angle)] + rng.normal(0, step / 4, (n, 2))
    return np.round(pts / step) * step


@pytest.mark.parametrize("seed", range(6))
def test_nearby_exact_is_the_all_segments_query_bit_for_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for kind in range(20):
        pts = _polyline(rng, kind)
        a, b = pts[:-1], pts[1:]
        step = float(np.max(np.hypot(*(b - a).T))) if len(a) else 0.0
        lo, hi = pts.min(axis=0) - 0.01, pts.max(axis=0) + 0.01
        samples = rng.uniform(lo, hi, (300, 2))
        on = pts[rng.integers(0, len(pts), 100)]  # on the vertices and half a step off
        samples[:100] = on + rng.choice([0.0, step / 2, step], size=(100, 2))
        half = step / 2.0
        ends = cKDTree(np.concatenate([a, b]))
        upper, _ = nearest_exact._nearest_chunk(samples, a, b, ends, half)
        fast = nearest_exact._nearby_exact(samples, upper, a, b, ends, half)
        assert fast is not None
        assert np.array_equal(fast, nearest_exact._all_exact(samples, a, b))


def _with_jumps(rng: np.random.Generator, n: int, step: float, jumps: int) -> np.ndarray:
    """A staircase of ``step`` with ``jumps`` moves 20 steps long (backlash take-ups)."""
    moves = rng.choice([-step, 0.0, step], size=(n, 2))
    at = rng.choice(n, size=jumps, replace=False)
    moves[at] = rng.choice([-20 * step, 20 * step], size=(jumps, 2))
    return np.cumsum(moves, axis=0)


@pytest.mark.parametrize("block", [None, 97])
@pytest.mark.parametrize("seed", range(6))
def test_long_segments_searched_apart_give_the_all_segments_query_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch, seed: int, block: int | None
) -> None:
    """Few long segments among short ones: each found within its own reach, the same minimum.

    ``block``: the unsure samples measured 97 at a time (``NEARBY_BLOCK``), the same answers.
    """
    if block is not None:
        monkeypatch.setattr(nearest_exact, "NEARBY_BLOCK", block)
    rng = np.random.default_rng(seed)
    step = (0.001, 0.004, 0.0005)[seed % 3]
    pts = _with_jumps(rng, int(rng.integers(3000, 6000)), step, int(rng.integers(1, 40)))
    a, b = pts[:-1], pts[1:]
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    long = nearest_exact.long_segments(a, b, half)
    assert long is not None and long.short_half <= half / 4.0
    assert np.all(np.hypot(*(b - a).T)[long.index] > 2.0 * long.short_half)
    samples = pts[rng.integers(0, len(pts), 1500)] + rng.normal(0.0, 2.0 * step, (1500, 2))
    samples[:300] = (a[long.index[0]] + b[long.index[0]]) / 2.0 + rng.normal(0, step, (300, 2))
    ends = cKDTree(np.concatenate([a, b]))
    upper, _ = nearest_exact._nearest_chunk(samples, a, b, ends, half)
    want = nearest_exact._all_exact(samples, a, b)
    apart = nearest_exact._nearby_exact(samples, upper, a, b, ends, half, long=long)
    together = nearest_exact._nearby_exact(samples, upper, a, b, ends, half)
    assert apart is not None and together is not None
    assert np.array_equal(apart, want) and np.array_equal(together, want)
    need = rng.random(len(samples)) < 0.3
    some = nearest_exact._nearby_exact(samples, upper, a, b, ends, half, need=need, long=long)
    assert some is not None
    assert np.array_equal(some[need], want[need]) and np.array_equal(some[~need], upper[~need])


@pytest.mark.parametrize("seed", range(4))
def test_long_segments_apart_settle_a_sample_only_at_its_true_nearest(seed: int) -> None:
    """The cheap test with the long segments apart settles only exact distances.

    A line's staircase with 20-step jumps (as a trace with backlash take-ups):
    half the longest segment is 10 steps, so the plain test settles few samples near the
    trace. A sample the test settles once the long segments are apart must have the least
    distance over every segment (the same formula, all segments: bit for bit).
    """
    rng = np.random.default_rng(seed)
    step = (0.001, 0.0009)[seed % 2]
    moves = np.c_[np.full(4000, step), rng.choice([0.0, step], size=4000)]  # a line's staircase
    moves[rng.choice(4000, size=30, replace=False)] *= 20.0
    pts = np.cumsum(moves, axis=0)
    a, b = pts[:-1], pts[1:]
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    long = nearest_exact.long_segments(a, b, half)
    assert long is not None
    samples = pts[rng.integers(0, len(pts), 800)] + rng.normal(0.0, step / 4, (800, 2))
    ends = cKDTree(np.concatenate([a, b]))
    plain, unsure_plain = nearest_exact._nearest_chunk(samples, a, b, ends, half)
    got, unsure = nearest_exact._nearest_chunk(samples, a, b, ends, half, long)
    assert np.array_equal(got, plain)
    newly = unsure_plain & ~unsure
    assert not (unsure & ~unsure_plain).any()
    assert newly.sum() > 100  # the case the long segments are for
    every = np.stack([nearest_exact._to_segments(s[None], a[None], b[None])[0] for s in samples])
    assert np.array_equal(got[newly], every.min(axis=1)[newly])


def test_segments_of_one_length_are_not_searched_apart() -> None:
    pts = np.cumsum(np.full((500, 2), [0.004, 0.0]), axis=0)
    a, b = pts[:-1], pts[1:]
    assert nearest_exact.long_segments(a, b, 0.002) is None  # the longest is no longer


def _brute(samples: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(N, M)`` distances of every sample to every segment (numpy, the textbook formula)."""
    ab = b - a
    t = np.clip(
        np.einsum("nmj,mj->nm", samples[:, None, :] - a, ab)
        / np.maximum(np.einsum("mj,mj->m", ab, ab), 1e-300),
        0.0,
        1.0,
    )
    foot = a + t[..., None] * ab
    return np.asarray(np.hypot(*(samples[:, None, :] - foot).transpose(2, 0, 1)))


@pytest.mark.parametrize("seed", range(6))
def test_the_segment_bounds_hold_for_every_segment(seed: int) -> None:
    """The two bounds of the exact stage, against every segment's distance.

    A segment nearer than ``upper`` has an end within
    :func:`~camtool.verify.nearest_exact.within_reach` (so the pairs of the exact stage hold
    the nearest), and where :func:`~camtool.verify.nearest_exact.beyond_kth` says so, the
    segments of the k nearest ends hold the nearest one. Segments of many lengths, up to
    ``2·half``; samples near them and a tool radius off.
    """
    rng = np.random.default_rng(seed)
    m = 300
    a = rng.uniform(0.0, 3.0, (m, 2))
    b = a + rng.normal(0.0, float(rng.choice([0.01, 0.2])), (m, 2))
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    samples = np.concatenate(
        [a[:100] + rng.normal(0.0, 0.05, (100, 2)), rng.uniform(-1, 4, (200, 2))]
    )
    every = _brute(samples, a, b)
    ends = np.concatenate([a, b])
    to_end = np.hypot(*(samples[:, None, :] - ends).transpose(2, 0, 1))
    to_seg_end = np.minimum(to_end[:, :m], to_end[:, m:])  # each segment's nearer end
    upper = every[np.arange(len(samples)), rng.integers(0, m, len(samples))]
    reach = nearest_exact.within_reach(upper, half)
    nearer = every <= upper[:, None]
    assert np.all(to_seg_end[nearer] <= np.broadcast_to(reach[:, None], nearer.shape)[nearer])
    k = nearest_exact.NEAREST_ENDS
    order = np.argsort(to_end, axis=1)[:, :k]
    rk = np.take_along_axis(to_end, order[:, -1:], axis=1)[:, 0]
    d = np.take_along_axis(every, order % m, axis=1).min(axis=1)
    sure = nearest_exact.beyond_kth(d, rk, half)
    assert sure.any()
    assert np.allclose(d[sure], every.min(axis=1)[sure], rtol=0.0, atol=1e-12)


def test_samples_a_tool_radius_from_a_trace_are_settled_or_measured_near(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Samples 1.5 mm from a straight trace of 0.05 mm steps at y = 0: exactly 1.5 mm.

    Cut once, the k-th end's bound (:func:`~camtool.verify.nearest_exact.beyond_kth`)
    settles every sample (``d + L/2 < rk`` settled none, and the vertex bound left those
    near a vertex). Cut twice with the second pass's vertices half a step along (as a
    thinned trace gives them), a sample's 4 nearest ends lie within a step and leave it
    unsure; the exact stage then measures the few segments with an end within
    ``sqrt(d² + L²/4)`` (:func:`~camtool.verify.nearest_exact.within_reach`): a handful a
    sample, never GEOS's query over every segment.
    """
    x = np.arange(0.0, 20.0, 0.05)
    first = np.c_[x, np.zeros_like(x)]
    samples = np.c_[np.linspace(5.0, 15.0, 2001), np.full(2001, 1.5)]
    a, b = first[:-1], first[1:]
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    d, unsure = nearest_exact._nearest_chunk(samples, a, b, cKDTree(np.concatenate([a, b])), half)
    assert not unsure.any()
    assert np.allclose(d, 1.5, rtol=0.0, atol=1e-12)

    def refused(*args: object) -> np.ndarray:
        raise AssertionError("GEOS's query of every segment asked")

    monkeypatch.setattr(nearest_exact, "_all_exact", refused)
    second = first + np.array([0.025, 0.0])
    a, b = np.concatenate([first[:-1], second[:-1]]), np.concatenate([first[1:], second[1:]])
    ends = cKDTree(np.concatenate([a, b]))
    d, unsure = nearest_exact._nearest_chunk(samples, a, b, ends, half)
    assert unsure.mean() > 0.5
    near = ends.query_ball_point(samples, nearest_exact.within_reach(d, half), return_length=True)
    assert np.max(near) <= 8
    for search in (nearest_search.nearest_distances, nearest_search.nearest_distances_kd):
        assert np.all(search(samples, a, b) == 1.5)


def test_nearby_exact_gives_way_when_too_many_segments_are_near(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    pts = _polyline(np.random.default_rng(3), 1)
    a, b = pts[:-1], pts[1:]
    ends = cKDTree(np.concatenate([a, b]))
    samples = pts[:50] + 0.001
    upper, _ = nearest_exact._nearest_chunk(samples, a, b, ends, 0.002)
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 0)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 10)
    assert nearest_exact._nearby_exact(samples, upper, a, b, ends, 0.002) is None
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 10**9)
    got = nearest_search.nearest_distances(samples, a, b)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 0)  # every unsure sample: all segments
    assert np.array_equal(got, nearest_search.nearest_distances(samples, a, b))


def _thin_index_reference(n: int, limit: int, runs: np.ndarray | None) -> np.ndarray:
    """The code :func:`cutting_thin._thin_index` replaced (sorted unique of the picks)."""
    k = max(1, -(-n // limit))
    picked = [np.arange(0, n, k), np.array([n - 1])]
    if runs is not None and n > 1:
        change = np.flatnonzero(runs[1:] != runs[:-1])
        picked += [change, change + 1]
    return np.unique(np.concatenate(picked))


def test_thin_index_is_the_sorted_unique_picks() -> None:
    rng = np.random.default_rng(11)
    for _ in range(300):
        n = int(rng.integers(1, 3000))
        limit = int(rng.integers(1, 4000))
        runs = None if rng.random() < 0.3 else np.cumsum(rng.random(n) < 0.01)
        got = cutting_thin._thin_index(n, limit, runs)
        want = _thin_index_reference(n, limit, runs)
        assert got.dtype == want.dtype
        assert np.array_equal(got, want)


@pytest.mark.usefixtures("accel_on")  # a kept answer is the accel layer's
def test_drawing_samples_are_kept_for_the_same_drawing_only() -> None:
    one = Drawing((Contour((Line((0.0, 0.0), (1.0, 0.0)),), False),))
    two = Drawing((Contour((Line((0.0, 0.0), (2.0, 0.0)),), False),))
    first, sizes = drawing_compare._sample_drawing(one, 0.005)
    again, _ = drawing_compare._sample_drawing(one, 0.005)
    assert again is first and not first.flags.writeable
    other, other_sizes = drawing_compare._sample_drawing(two, 0.005)
    assert len(other) == 401 and other_sizes == [401] and sizes == [201]
    assert np.array_equal(drawing_compare._sample_drawing(one, 0.005)[0], first)


def _plate() -> tuple[Program, Drawing]:
    """A 6 × 4 mm rectangle at (5, 5) with a ø2 mm hole; a 0.5 mm tool outside / inside."""
    c = [(5.0, 5.0), (11.0, 5.0), (11.0, 9.0), (5.0, 9.0)]
    outline = Contour(tuple(Line(c[i], c[(i + 1) % 4]) for i in range(4)), True)
    hole = Contour((Arc((10.0, 7.0), (10.0, 7.0), (9.0, 7.0), False),), True)
    r = 0.25
    moves = (
        Rapid(9.75, 7.0, contour=1),
        ArcMove(9.75, 7.0, 9.0, 7.0, False, 300.0, contour=1),
        Rapid(5 - r, 5 - r, contour=2),
        Linear(11 + r, 5 - r, 300.0, contour=2),
        Linear(11 + r, 9 + r, 300.0, contour=2),
        Linear(5 - r, 9 + r, 300.0, contour=2),
        Linear(5 - r, 5 - r, 300.0, contour=2),
    )
    return Program(moves, origin=(0.0, 0.0)), Drawing((hole, outline))


def test_budget_reuses_the_drawing_figure_only_when_the_trace_is_the_same() -> None:
    """grbl's 4 µm steps absorb the plan's sub-µm rounding: the same trace, the same figure.

    The figure the budget reuses equals the one measured again from the plan's own trace.
    """
    target = load_target("grbl")
    program, drawing = _plate()
    moved = tuple(
        dataclasses.replace(m, x=m.x + 0.0002) if i == 3 else m for i, m in enumerate(program.moves)
    )
    planned = dataclasses.replace(program, moves=moved)  # 0.2 µm off: under a step
    v = verify_program(program, target.machine, against=drawing, tool_diameter=0.5,
                       planned=planned)  # fmt: skip
    trace = simulate(planned, target.machine)
    assert np.array_equal(cutting_rows(planned, trace)[0], cutting_rows(program, v.trace)[0])
    cut, runs = cutting_rows(planned, trace)
    again = drawing_compare.against_drawing(cut, drawing, 0.25, runs=runs)
    assert v.against is not None
    assert v.error_budget.without["rounding"]["distance to the drawing"] == again.max_um
    assert again.max_um == v.against.max_um


@pytest.mark.usefixtures("accel_on")  # a kept answer is the accel layer's
def test_distance_to_the_path_is_kept_only_for_inputs_that_cannot_change() -> None:
    samples = np.random.default_rng(5).uniform(0.0, 2.0, (200, 2))
    lines = (np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]), np.array([[0.5, 1.0]]))
    want = drawing_compare._distance_to_now(samples, lines)
    open_answer = drawing_compare._distance_to(samples, lines)  # writeable: measured, not kept
    assert np.array_equal(open_answer, want) and open_answer.flags.writeable
    samples.flags.writeable = False
    for line in lines:
        line.flags.writeable = False
    first = drawing_compare._distance_to(samples, lines)
    assert drawing_compare._distance_to(samples, lines) is first and np.array_equal(first, want)
    copied = tuple(line.copy() for line in lines)  # other objects: measured again
    assert drawing_compare._distance_to(samples, copied) is not first


@pytest.mark.usefixtures("accel_on")  # a kept answer is the accel layer's
def test_nominal_lines_are_kept_for_the_code_and_the_plan() -> None:
    from camtool.verify.trace_sources import _nominal_lines, _nominal_lines_now

    code, _ = _plate()
    plan = dataclasses.replace(code, moves=code.moves[:-1])
    lines = _nominal_lines(code)
    assert _nominal_lines(plan) is not lines
    assert _nominal_lines(code) is lines  # two kept: the code's survives the plan's
    want = _nominal_lines_now(code)
    assert all(np.array_equal(a, b) for a, b in zip(lines, want, strict=True))
    assert not any(line.flags.writeable for line in lines)


def _farthest_reference(samples: np.ndarray, a: np.ndarray, b: np.ndarray) -> tuple[float, int]:
    """What the shortfall took before :func:`nearest_search.farthest_nearest`: every distance."""
    d = nearest_search.nearest_distances(samples, a, b)
    k = int(np.argmax(d))
    return float(d[k]), k


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("compiled", [False, True])
def test_farthest_nearest_is_the_max_of_every_distance(
    seed: int, compiled: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same largest distance and the same first sample at it, bit for bit.

    Samples on the trace's grid, half a step off (unsure for the cheap tests), repeated
    (ties at the largest) and far off; both nearest-end searches (the k-d tree and, with
    numba, the box tree), and both exact stages (the pairs near each sample, and GEOS's
    query over all segments when the pairs are over the limit).
    """
    if compiled:
        if nearest_search.near_kernels() is None:
            pytest.skip("numba is not installed")
    else:
        monkeypatch.setattr(nearest_search, "near_kernels", lambda work=0: None)
    rng = np.random.default_rng(100 + seed)
    for kind in range(12):
        pts = _polyline(rng, kind)
        if kind % 4 == 3:  # far from the origin: coordinates of a 5 m machine
            pts = pts + 5000.0
        a, b = pts[:-1], pts[1:]
        step = float(np.max(np.hypot(*(b - a).T)))
        on = pts[rng.integers(0, len(pts), 200)]
        samples = on + rng.choice([0.0, step / 2, step, 3 * step], size=(200, 2))
        if kind % 3 == 0:  # the farthest sample repeated: the first one must be named
            far = int(rng.integers(0, 200))
            samples = np.insert(samples, [far // 2, far], samples[far] + 5 * step, axis=0)
        for limit in (nearest_exact.NEARBY_MAX_PAIRS, 0):
            monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", limit)
            monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 64 if limit else 0)
            want = _farthest_reference(samples, a, b)
            got = nearest_search.farthest_nearest(samples, a, b)
            assert got[1] == want[1]
            assert np.float64(got[0]).tobytes() == np.float64(want[0]).tobytes()
            ends = nearest_search._LazyTree(np.concatenate([a, b]))  # a tree shared by batches
            assert nearest_search.farthest_nearest(samples, a, b, ends=ends) == got


def test_farthest_nearest_measures_few_unsure_samples(monkeypatch: pytest.MonkeyPatch) -> None:
    """Unsure samples far below the largest settled distance are not measured exactly."""
    monkeypatch.setattr(nearest_search, "near_kernels", lambda work=0: None)
    x = np.arange(0.0, 4.0, 0.004)
    pts = np.c_[x, np.zeros_like(x)]  # a straight trace of 4 µm steps, cut twice
    a, b = np.concatenate([pts[:-1]] * 2), np.concatenate([pts[1:]] * 2)
    # 10 µm above each vertex: its 4 nearest ends are at it and the vertex bound is
    # loose (unsure); 0.5 mm above a segment's middle: settled by it, and the farthest
    above = pts[:300] + np.array([0.0, 0.01])
    samples = np.concatenate([above, [[0.002, 0.5]]])
    measured: list[int] = []
    real = nearest_exact._nearby_pairs

    def spy(s: np.ndarray, *args: object) -> np.ndarray:
        measured.append(len(s))
        return real(s, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(nearest_exact, "_nearby_pairs", spy)
    want = _farthest_reference(samples, a, b)
    every = sum(measured)
    measured.clear()
    assert nearest_search.farthest_nearest(samples, a, b) == want == (0.5, 300)
    assert every == 299 and sum(measured) == 0


@pytest.mark.parametrize("size", [1, 7, 100, 10_000])
def test_sample_batches_are_the_slices_of_the_whole_samples(size: int) -> None:
    """The streamed shortfall's path samples, built move by move, are the whole ones sliced."""
    moves = (
        Rapid(1.0, 1.0, contour=1),
        Linear(3.0, 1.5, 300.0, contour=1),
        ArcMove(3.0, 3.5, 3.0, 2.5, True, 300.0, contour=1),
        Linear(3.0, 3.5, 300.0, contour=1),  # no length: its two ends
        Linear(1.0, 1.0, 300.0, contour=1),
    )
    program = Program(moves, origin=(0.0, 0.0))
    starts = [program.origin] + [(m.x, m.y) for m in program.moves]
    whole, owner, along = path_shortfall._sample_moves(program, starts, 1, 4, 0.01)
    pieces = list(path_shortfall._sample_batches(program, starts, 1, 4, 0.01, size))
    assert [len(p) for p, _, _ in pieces[:-1]] == [size] * (len(pieces) - 1)
    assert np.concatenate([p for p, _, _ in pieces]).tobytes() == whole.tobytes()
    assert np.array_equal(np.concatenate([o for _, o, _ in pieces]), owner)
    assert np.concatenate([t for _, _, t in pieces]).tobytes() == along.tobytes()
    # each move's fractions run from 0 at its start to 1 at its end
    for move in (1, 2, 3, 4):
        t = along[owner == move]
        assert t[0] == 0.0 and t[-1] == 1.0 and np.all(np.diff(t) > 0)
    assert set(owner.tolist()) == {1, 2, 3, 4}


@pytest.mark.parametrize("seed", range(4))
def test_the_all_segments_query_in_chunks_is_one_query_of_them_all(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """GEOS's nearest query asked a few samples at a time = asked of all at once (shapely)."""
    import shapely

    rng = np.random.default_rng(seed)
    pts = _polyline(rng, seed)
    a, b = pts[:-1], pts[1:]
    samples = rng.uniform(pts.min(axis=0) - 0.01, pts.max(axis=0) + 0.01, (500, 2))
    tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
    _, once = tree.query_nearest(shapely.points(samples), return_distance=True, all_matches=False)
    monkeypatch.setattr(nearest_exact, "ALL_EXACT_CHUNK", int(rng.integers(1, 60)))
    assert (
        nearest_exact._all_exact(samples, a, b).tobytes() == np.asarray(once, np.float64).tobytes()
    )


@pytest.mark.parametrize("seed", range(4))
def test_the_counts_within_reach_are_scipys_or_none_over_the_limit(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(seed)
    pts = _polyline(rng, seed + 1)
    ends = cKDTree(pts)
    samples = pts[rng.integers(0, len(pts), 400)] + rng.normal(0.0, 0.01, (400, 2))
    reach = rng.uniform(0.0, 0.05, 400)
    once = ends.query_ball_point(samples, reach, return_length=True)
    monkeypatch.setattr(nearest_exact, "NEARBY_COUNT_CHUNK", int(rng.integers(1, 50)))
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 0)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", int(np.sum(once)))
    got = nearest_exact._counts_within(ends, samples, reach)
    assert got is not None and np.array_equal(got, once)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", int(np.sum(once)) - 1)
    assert nearest_exact._counts_within(ends, samples, reach) is None
    # or so many pairs a sample, beyond the pairs measured at once
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 1)
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", -(-int(np.sum(once)) // 400))
    got = nearest_exact._counts_within(ends, samples, reach)
    assert got is not None and np.array_equal(got, once)


def test_a_drawing_sampled_into_one_array_is_its_contours_stacked() -> None:
    """The drawing's points written in place = each contour's points stacked (the old form)."""
    square = Contour(
        (
            Line((0.0, 0.0), (1.0, 0.0)),
            Arc((1.0, 0.0), (1.5, 0.5), (1.0, 0.5), False),
            Line((1.5, 0.5), (0.0, 0.0)),
        ),
        True,
    )
    circle = Contour((Arc((3.0, 0.0), (3.0, 0.0), (2.0, 0.0), True),), True)
    dot = Contour((Line((5.0, 5.0), (5.0, 5.0)),), False)
    drawing = Drawing((square, circle, dot))
    got, sizes = drawing_compare._sample_drawing_now(drawing, 0.013)
    parts = [drawing_compare._sample_contour(c.segments, 0.013) for c in drawing.contours]
    assert sizes == [len(p) for p in parts]
    assert got.tobytes() == np.vstack(parts).tobytes()


def _sampled_one_at_a_time(segments: tuple[Segment, ...], spacing_mm: float) -> np.ndarray:
    """The contour sampler as it was, a point at a time in Python (the reference)."""
    pts: list[tuple[float, float]] = []
    for seg in segments:
        n = max(1, math.ceil(seg.length / spacing_mm))
        if isinstance(seg, Line):
            (x0, y0), (x1, y1) = seg.start, seg.end
            pts.extend((x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n))
        else:
            pts.extend(seg.point_at(k / n) for k in range(n))
    pts.append(segments[-1].end)
    return np.asarray(pts, dtype=np.float64)


@pytest.mark.parametrize("seed", range(4))
def test_contours_sampled_in_arrays_are_the_points_made_one_at_a_time(seed: int) -> None:
    """Lines (long, short, of length 0, far from the origin) and arcs (spirals too): the
    same floats."""
    rng = np.random.default_rng(seed)
    for _ in range(40):
        scale = float(rng.choice([1e-3, 1.0, 1e3]))
        at = (float(rng.normal()) * 1e4 if seed % 2 else 0.0, float(rng.normal()) * scale)
        segments: list[Segment] = []
        for _ in range(int(rng.integers(1, 30))):
            start = segments[-1].end if segments else at
            if rng.random() < 0.3:
                centre = (start[0] + float(rng.normal()) * scale, start[1] + 0.5 * scale)
                sweep = float(rng.uniform(-6.0, 6.0))
                # a spiral now and then: its end at another radius, as code may give it
                r = math.dist(start, centre) * (1.0 + float(rng.choice([0.0, 0.0, 1e-3])))
                a = math.atan2(start[1] - centre[1], start[0] - centre[0]) + sweep
                end = (centre[0] + r * math.cos(a), centre[1] + r * math.sin(a))
                segments.append(Arc(start, end, centre, sweep < 0))
            else:
                step = rng.normal(size=2) * scale * float(rng.choice([0.0, 0.01, 1.0, 50.0]))
                segments.append(Line(start, (start[0] + float(step[0]), start[1] + float(step[1]))))
        spacing = float(rng.choice([0.001, 0.013, 0.4])) * scale
        got = drawing_compare._sample_contour(tuple(segments), spacing)
        want = _sampled_one_at_a_time(tuple(segments), spacing)
        assert got.tobytes() == want.tobytes()


def test_the_cutting_count_is_the_count_of_cutting_rows() -> None:
    """same_against tells traces apart by the digest of their cutting rows, copying none."""
    from camtool.verify.budget_run import BudgetInputs, same_against, trace_digest
    from camtool.verify.streamed import cutting_count

    target = load_target("grbl")
    program, drawing = _plate()
    trace = simulate(program, target.machine)
    assert cutting_count(program, trace.block_start) == len(cutting_rows(program, trace)[0])
    assert 0 < cutting_count(program, trace.block_start) < trace.row_count  # rapids left out
    v = verify_program(program, target.machine, against=drawing, tool_diameter=0.5)
    ideal = simulate(program, target.machine, sources=ALL.without("interpolation"))
    assert cutting_count(program, ideal.block_start) != cutting_count(program, trace.block_start)
    inputs = BudgetInputs(program, target.machine, v.trace, None, drawing, 0.5, ())
    assert not same_against(inputs, program, trace_digest(program, ideal))
    assert same_against(inputs, program, trace_digest(program, trace))
    assert not same_against(inputs, program, None)
