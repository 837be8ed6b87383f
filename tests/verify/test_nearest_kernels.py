"""The compiled nearest-end search gives what the k-d tree path gives, bit for bit (issue 17).

:func:`camtool.verify.nearest_search.nearest_distances` (numba box tree,
:mod:`camtool.accel.nearkernels`) against
:func:`~camtool.verify.nearest_search.nearest_distances_kd`
(scipy's k-d tree, the code it replaces) on many random inputs built to tie: traces on a
step grid, samples on the same grid, traces cut in several identical passes (every end
repeated), samples far from the trace (a drawing point a tool radius away). Equality is
``==`` of the float64 bits, not approximate: the reports are written from these values.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camtool.verify import nearest_exact, nearest_search

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

nearkernels = pytest.importorskip("camtool.accel.nearkernels")


@pytest.fixture(autouse=True)
def _compiled(accel_on: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """The compiled search in use from the first call (the default threshold is a load),
    near samples included (:func:`nearest_search._far`, :func:`~nearest_search._dense` and
    :func:`~nearest_search._far_kd` would send those to the k-d tree)."""
    assert nearest_search.near_kernels() is nearkernels
    monkeypatch.setattr(nearest_search, "_far", lambda *args: True)
    monkeypatch.setattr(nearest_search, "_far_kd", lambda *args: True)
    monkeypatch.setattr(nearest_search, "_dense", lambda *args: False)


def _trace(rng: np.random.Generator, kind: int) -> np.ndarray:
    """A staircase or an arc on a step grid, sometimes repeated in passes."""
    n = int(rng.integers(3, 1500))
    step = (0.004, 0.0005, 0.25, 0.001)[kind % 4]
    if kind % 2:
        pts = np.cumsum(rng.choice([-step, 0.0, step], size=(n, 2)), axis=0)
    else:
        angle = np.linspace(0.0, rng.uniform(1.0, 7.0), n)
        radius = rng.uniform(0.1, 3.0)
        pts = np.c_[radius * np.cos(angle), radius * np.sin(angle)]
        pts = np.round((pts + rng.normal(0, step / 4, (n, 2))) / step) * step
    passes = int(rng.integers(1, 4))
    return np.concatenate([pts] * passes)


def _samples(rng: np.random.Generator, pts: np.ndarray, n: int, reach: float) -> np.ndarray:
    """Points on the trace's grid, half steps off it, a ``reach`` away and anywhere."""
    step = float(np.min(np.abs(np.diff(pts, axis=0))[np.abs(np.diff(pts, axis=0)) > 0]))
    pick = pts[rng.integers(0, len(pts), n)]
    out = [
        pick[: n // 4] + rng.integers(-3, 4, (n // 4, 2)) * step,
        pick[n // 4 : n // 2] + rng.choice([0.0, step / 2, -step / 2], size=(n // 2 - n // 4, 2)),
    ]
    angle = rng.uniform(0, 2 * np.pi, n // 4)
    out.append(pick[: n // 4] + reach * np.c_[np.cos(angle), np.sin(angle)])
    lo, hi = pts.min(axis=0) - reach, pts.max(axis=0) + reach
    out.append(rng.uniform(lo, hi, (n - n // 2 - n // 4, 2)))
    samples = np.concatenate(out)
    # queries come along a path, as the verifier makes them
    return samples[np.argsort(samples[:, 0] + samples[:, 1], kind="stable")]


@pytest.mark.parametrize("seed", [*range(4), *range(300, 304)])
def test_nearest_distances_equal_the_kd_tree_path_bit_for_bit(seed: int) -> None:
    """And the largest of them and its first sample (:func:`farthest_nearest`): step-grid
    traces tie ends at the k-th distance for many samples, which it measures last, only
    where they can be the largest."""
    rng = np.random.default_rng(seed)
    for kind in range(12):
        pts = _trace(rng, kind)
        a, b = pts[:-1], pts[1:]
        samples = _samples(rng, pts, 1000, reach=float(rng.choice([0.0015, 0.1, 1.5])))
        got = nearest_search.nearest_distances(samples, a, b)
        want = nearest_search.nearest_distances_kd(samples, a, b)
        assert np.array_equal(got.view(np.int64), want.view(np.int64))
        farthest = nearest_search.farthest_nearest(samples, a, b)
        assert farthest == (float(np.max(want)), int(np.argmax(want)))


@pytest.mark.parametrize("merge", [True, False])
@pytest.mark.parametrize("seed", range(4))
def test_knn_finds_the_kd_trees_ends_where_they_are_one_set(seed: int, merge: bool) -> None:
    """Every end counts, whether the ends at one point are one place of the tree or not."""
    rng = np.random.default_rng(100 + seed)
    for kind in range(12):
        pts = _trace(rng, kind)
        points = np.concatenate([pts[:-1], pts[1:]])
        samples = _samples(rng, pts, 1000, reach=0.5)
        tree = nearkernels.tree(points, merge=merge)
        for k in (1, 4, 7):
            r0, rk, index, state = nearkernels.knn(samples, *tree, k)
            r, want = cKDTree(points).query(samples, k=k)
            r = np.asarray(r).reshape(len(samples), k)
            want = np.asarray(want).reshape(len(samples), k)
            assert np.array_equal(np.sqrt(r0), r[:, 0])  # the k-d tree's own distances
            assert np.array_equal(np.sqrt(rk), r[:, -1])
            one = state == 0
            assert np.array_equal(np.sort(index[one], axis=1), np.sort(want[one], axis=1))
            # where not one set, every end the k-d tree chose is within the k-th distance
            found, _, count = nearkernels.within(samples[~one], *tree, rk[~one])
            for row, chosen in enumerate(want[~one]):
                if count[row] <= found.shape[1]:
                    assert set(chosen.tolist()) <= set(found[row, : count[row]].tolist())


@pytest.mark.parametrize("segments", [True, False])
def test_the_tree_holds_each_end_once_at_its_place(segments: bool) -> None:
    """Three passes of a stepped path: one place per distinct point, every end at its own.

    The places are numbered in the order of their first end (along the segments with
    ``segments``: ``a[0]``, ``b[0]``, ``a[1]``…), and 0.0 and -0.0 stay apart (bits).
    """
    rng = np.random.default_rng(5)
    path = np.cumsum(rng.integers(-1, 2, size=(3000, 2)) * 0.004, axis=0)
    pts = np.concatenate([path] * 3)
    pts[7] = [0.0, -0.0]
    pts[8] = [0.0, 0.0]
    a, b = pts[:-1], pts[1:]
    points = np.concatenate([a, b])
    places, _, _, start, ends = nearkernels.tree(points, segments=segments)
    m = len(a)
    taken = np.ravel(np.c_[np.arange(m), m + np.arange(m)]) if segments else np.arange(2 * m)
    bits = points.view(np.uint64)
    assert np.array_equal(np.sort(ends), np.arange(2 * m))  # every end, once
    assert len(places) == len(np.unique(bits, axis=0))  # one place per distinct point
    rank = np.empty(2 * m, dtype=np.int64)
    rank[taken] = np.arange(2 * m)
    for u in range(len(places)):
        at = ends[start[u] : start[u + 1]]
        assert (bits[at] == places[u].view(np.uint64)).all()
        assert (np.diff(rank[at]) > 0).all()  # in the order taken
    assert (np.diff(rank[ends[start[:-1]]]) > 0).all()  # places by their first end


def test_knn_on_a_line_of_repeated_ends_far_away() -> None:
    """Six copies of every end (two per vertex, three passes) 1.5 mm from the samples."""
    x = np.arange(0.0, 20.0, 0.004)
    line = np.c_[x, np.zeros_like(x)]
    pts = np.concatenate([line] * 3)
    samples = np.c_[np.arange(0.0, 20.0, 0.005), np.full(4000, 1.5)]
    got = nearest_search.nearest_distances(samples, pts[:-1], pts[1:])
    want = nearest_search.nearest_distances_kd(samples, pts[:-1], pts[1:])
    assert np.array_equal(got, want)
    assert np.allclose(got, 1.5, atol=1e-12)  # the line is 1.5 mm away everywhere


def test_small_inputs_take_the_kd_tree_path() -> None:
    a = np.array([[0.0, 0.0]])
    b = np.array([[1.0, 0.0]])
    samples = np.array([[0.5, 1.0], [2.0, 0.0]])
    assert np.array_equal(nearest_search.nearest_distances(samples, a, b), [1.0, 1.0])
    assert np.array_equal(
        nearest_search.nearest_distances(samples, np.zeros((0, 2)), np.zeros((0, 2))), [np.inf] * 2
    )


@pytest.mark.parametrize("seed", range(3))
def test_nearby_boxes_is_the_kd_tree_nearby_query_bit_for_bit(seed: int) -> None:
    """The same GEOS minimum as :func:`~camtool.verify.nearest_exact._nearby_exact`.

    (Not always :func:`~camtool.verify.nearest_exact._all_exact`'s: with a segment 2.3 mm long
    joining two passes, GEOS's tree query and its plain distance were seen 1 ulp apart.)
    """
    rng = np.random.default_rng(200 + seed)
    for kind in range(12):
        pts = _trace(rng, kind)
        a, b = pts[:-1], pts[1:]
        samples = _samples(rng, pts, 400, reach=float(rng.choice([0.0015, 1.5])))
        half = float(np.max(np.hypot(*(b - a).T))) / 2.0
        ends = cKDTree(np.concatenate([a, b]))
        upper, _ = nearest_exact._nearest_chunk(samples, a, b, ends, half)
        tree = nearkernels.tree(np.concatenate([a, b]))
        fast = nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels)
        assert fast is not None
        assert np.array_equal(fast, nearest_exact._nearby_exact(samples, upper, a, b, ends, half))


@pytest.mark.parametrize("seed", range(3))
def test_nearby_boxes_in_parts_is_the_whole_answer_bit_for_bit(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Samples asked a few at a time, fewer where their pairs are over the pairs at once.

    The pairs of all samples are over :data:`NEARBY_MAX_PAIRS` (made small here) but
    within :func:`~camtool.verify.nearest_exact.pair_limit`'s allowance a sample: the
    same minimum as one query of them all, and for the samples ``need`` names.
    """
    rng = np.random.default_rng(300 + seed)
    pts = _trace(rng, 4 * seed + 1)
    a, b = pts[:-1], pts[1:]
    samples = _samples(rng, pts, 300, reach=1.5)
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    upper, _ = nearest_exact._nearest_chunk(samples, a, b, cKDTree(np.concatenate([a, b])), half)
    tree = nearkernels.tree(np.concatenate([a, b]))
    need = rng.random(len(samples)) < 0.5
    whole = nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels)
    some = nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels, need)
    assert whole is not None and some is not None
    reach = nearest_exact.within_reach(upper, half) * (1.0 + 1e-12)
    owner, _ = nearkernels.pairs_within(samples, *tree, reach, 10**9)
    most = int(np.bincount(owner).max())  # the pairs of one sample must fit at once
    assert len(owner) > 4 * most
    monkeypatch.setattr(nearest_exact, "NEARBY_BOX_SAMPLES", int(rng.integers(2, 40)))
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 2 * most)
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 10**6)
    parts = nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels)
    assert parts is not None and parts.tobytes() == whole.tobytes()
    parts = nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels, need)
    assert parts is not None and parts.tobytes() == some.tobytes()
    assert np.array_equal(some[~need], upper[~need])
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 0)  # over the limit
    assert nearest_exact._nearby_boxes(samples, upper, a, b, tree, half, nearkernels) is None


def test_nearby_boxes_gives_way_over_the_pair_limit(monkeypatch: pytest.MonkeyPatch) -> None:
    pts = _trace(np.random.default_rng(3), 1)
    a, b = pts[:-1], pts[1:]
    tree = nearkernels.tree(np.concatenate([a, b]))
    samples = pts[:50] + 0.001
    upper = np.full(50, 0.01)
    monkeypatch.setattr(nearest_exact, "NEARBY_PAIRS_PER_SAMPLE", 0)
    monkeypatch.setattr(nearest_exact, "NEARBY_MAX_PAIRS", 10)
    assert nearest_exact._nearby_boxes(samples, upper, a, b, tree, 0.002, nearkernels) is None


@pytest.mark.parametrize("chunk", [1, 2, 5, 37, 1000])
def test_nearby_min_in_groups_is_the_whole_pairs_answer_bit_for_bit(chunk: int) -> None:
    """Measuring the pairs a few samples at a time changes no distance and no minimum.

    The reference is the one-group answer, computed here independently of
    :func:`nearest_exact._nearby_min`: GEOS's distance of every pair, the least per sample.
    """
    import shapely

    rng = np.random.default_rng(17 + chunk)
    samples = rng.uniform(0.0, 5.0, (60, 2))
    a = rng.uniform(0.0, 5.0, (40, 2))
    b = a + rng.normal(0.0, 0.3, (40, 2))
    counts = rng.integers(1, 9, len(samples))  # every sample has a pair, some have many
    owner = np.repeat(np.arange(len(samples)), counts)
    seg = rng.integers(0, 2 * len(a), len(owner))  # ends of either side, repeats included
    lines = shapely.linestrings(np.stack([a, b], axis=1))
    pair_d = shapely.distance(shapely.points(samples)[owner], lines[seg % len(a)])
    expected = np.array([pair_d[owner == i].min() for i in range(len(samples))])
    got = nearest_exact._nearby_min(samples, owner, seg, a, b, chunk=chunk)
    assert got.tobytes() == expected.tobytes()


@pytest.mark.parametrize("chunk", [1, 3, 50])
def test_nearby_exact_in_groups_is_geos_over_all_segments(
    chunk: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The k-d tree's nearby pairs, asked a few samples at a time, give GEOS's exact minimum.

    The reference is :func:`nearest_exact._all_exact` (GEOS's nearest query over every segment)
    on a staircase trace of 1 µm steps with a far-off pass, where the upper bounds are the
    distances to the first segment (loose, so many pairs per sample).
    """
    monkeypatch.setattr(nearest_exact, "NEARBY_CHUNK_PAIRS", chunk)
    rng = np.random.default_rng(chunk)
    steps = rng.integers(0, 2, (400, 2)) * 0.001
    trace = np.cumsum(steps, axis=0)
    a, b = trace[:-1], trace[1:]
    samples = trace[rng.integers(0, len(trace), 40)] + rng.normal(0.0, 0.002, (40, 2))
    upper = nearest_exact._to_segments(
        samples, a[:1][None, :, :].repeat(40, 0), b[:1][None, :, :].repeat(40, 0)
    )[:, 0]
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0
    got = nearest_exact._nearby_exact(samples, upper, a, b, cKDTree(np.concatenate([a, b])), half)
    assert got is not None
    assert got.tobytes() == nearest_exact._all_exact(samples, a, b).tobytes()


@pytest.mark.parametrize("seed", range(4))
def test_near_segments_is_the_numpy_form_bit_for_bit(seed: int) -> None:
    """The one-pass kernel gives the numpy form's distances, tie verdicts and asks.

    The numpy form (:func:`nearest_search._near_segments_numpy`: :func:`nearest_exact._to_segments`
    and :func:`nearest_search._tied`) is the code the kernel replaced; on traces built to tie
    (step grids, repeated passes, samples on the grid and a tool radius away) every
    distance the kernel settles has the same float64 bits, and it asks the k-d tree
    for exactly the same samples.
    """
    rng = np.random.default_rng(300 + seed)
    asked = 0
    for kind in range(12):
        pts = _trace(rng, kind)
        a, b = np.ascontiguousarray(pts[:-1]), np.ascontiguousarray(pts[1:])
        points = np.concatenate([a, b])
        samples = _samples(rng, pts, 1000, reach=float(rng.choice([0.0015, 0.1, 1.5])))
        every = nearkernels.tree(points, merge=False)  # the reference: each end its own place
        want = nearest_search._near_segments_numpy(samples, a, b, every, nearkernels)
        places = nearkernels.tree(points, segments=True)  # as nearest_distances builds it
        got = nearkernels.near_segments(samples, *places, a, b, 4)
        assert np.array_equal(got[3], want[3])  # the same samples ask the k-d tree
        for g, w in zip(got[1:3], want[1:3], strict=True):
            assert np.array_equal(g, w)
        settled = ~want[3]
        assert got[0][settled].tobytes() == want[0][settled].tobytes()
        asked += int(want[3].sum())
    assert asked > 0  # the inputs do reach the k-d tree's own choice


def test_segment_distance_is_numpys_on_awkward_segments() -> None:
    """Point segments, points on a segment and its extension, ends, tiny and huge scales."""
    rng = np.random.default_rng(9)
    n = 4000
    a = rng.normal(size=(n, 2)) * rng.choice([1e-9, 1e-3, 1.0, 1e3], size=(n, 1))
    b = a + rng.normal(size=(n, 2)) * rng.choice([0.0, 1e-12, 1e-3, 10.0], size=(n, 1))
    t = rng.choice([-1.0, 0.0, 0.5, 1.0, 2.0, 0.3], size=(n, 1))
    off = rng.choice([0.0, 1e-15, 1e-3], size=(n, 1)) * rng.normal(size=(n, 2))
    p = a + t * (b - a) + off
    want = nearest_exact._to_segments(p, a[:, None, :], b[:, None, :])[:, 0]
    got = np.array([nearkernels._segment(p[i, 0], p[i, 1], a, b, i) for i in range(n)])
    assert got.tobytes() == want.tobytes()


def _awkward_pairs(rng: np.random.Generator, n: int) -> tuple[np.ndarray, ...]:
    """Points against segments: point segments, on the segment, its ends and extension,
    tiny and huge scales, and a step grid (where products and sums tie)."""
    scale = rng.choice([1e-9, 1e-3, 1.0, 1e3], size=(n, 1))
    a = rng.normal(size=(n, 2)) * scale + rng.normal(size=(n, 2)) * 10
    b = a + rng.normal(size=(n, 2)) * rng.choice([0.0, 1e-12, 1e-3, 10.0], size=(n, 1))
    t = rng.choice([-1.0, 0.0, 0.5, 1.0, 2.0, 0.3, 1e-17], size=(n, 1))
    p = a + t * (b - a) + rng.choice([0.0, 1e-15, 1e-3], size=(n, 1)) * rng.normal(size=(n, 2))
    half = n // 2
    a[half:], b[half:] = np.round(a[half:] / 0.004) * 0.004, np.round(b[half:] / 0.004) * 0.004
    p[half:] = np.round(p[half:] / 0.001) * 0.001
    return p, a, b


def test_least_of_pairs_is_geos_distance_bit_for_bit() -> None:
    """The compiled GEOS point-segment distance against shapely's (GEOS) on 200 000 pairs."""
    import shapely

    p, a, b = _awkward_pairs(np.random.default_rng(11), 200_000)
    one = np.arange(len(p))
    got = nearkernels.least_of_pairs(p, one, one, a, b)
    want = shapely.distance(shapely.points(p), shapely.linestrings(np.stack([a, b], axis=1)))
    assert got.tobytes() == np.asarray(want, dtype=np.float64).tobytes()


@pytest.mark.parametrize("seed", range(3))
def test_nearby_min_compiled_is_the_geos_grouping(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Each sample's least distance over its pairs: compiled, and by GEOS in groups."""
    rng = np.random.default_rng(20 + seed)
    p, a, b = _awkward_pairs(rng, 3000)
    counts = rng.integers(1, 30, size=len(p))
    owner = np.repeat(np.arange(len(p)), counts)
    seg = rng.integers(0, 2 * len(a), size=len(owner))  # ends of a or b: seg % len(a)
    assert nearest_exact._pair_kernels(1) is nearkernels  # numba is loaded: the compiled form
    compiled = nearest_exact._nearby_min(p, owner, seg, a, b)
    monkeypatch.setattr(nearest_exact, "_pair_kernels", lambda pairs: None)
    for chunk in (7, nearest_exact.NEARBY_CHUNK_PAIRS):
        assert nearest_exact._nearby_min(p, owner, seg, a, b, chunk).tobytes() == compiled.tobytes()


def test_the_box_tree_searches_only_samples_far_from_the_segments(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A dense line of 4 µm segments: samples 1.5 mm off are far (375 half-lengths), on
    it near; the distances are the same whichever search answers."""
    monkeypatch.undo()  # the real _far
    x = np.arange(0.0, 20.0, 0.004)
    line = np.c_[x, np.zeros_like(x)]
    tree = nearkernels.tree(np.concatenate([line[:-1], line[1:]]))
    off = np.c_[np.arange(0.0, 20.0, 0.005), np.full(4000, 1.5)]
    on = off * [1.0, 0.0] + [0.001, 0.0001]
    assert nearest_search._far(off, tree, 0.002, nearkernels)
    assert not nearest_search._far(on, tree, 0.002, nearkernels)
    for samples in (off, on):
        want = nearest_search.nearest_distances_kd(samples, line[:-1], line[1:])
        got = nearest_search.nearest_distances(samples, line[:-1], line[1:])
        assert got.tobytes() == want.tobytes()


@pytest.mark.parametrize("every", [False, True])
@pytest.mark.parametrize("seed", range(4))
def test_farthest_off_is_the_largest_offset_distance_bit_for_bit(
    seed: int, every: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``farthest_off`` against ``max(|nearest_distances − offset|)`` on traces built to tie.

    Offsets of 0 (a path on its line), a few steps, and a tool radius (a drawing point
    1.5 mm from the tool centre); the k-d tree of every end is built only where a tied
    sample can be the largest, and some cases need none at all. ``every``: every
    sample is taken as able to reach the largest, so the k-d tree's choice and the exact
    stage are made for all of them, as :func:`nearest_search.nearest_distances` makes them.
    """
    if every:
        monkeypatch.setattr(
            nearest_search, "_can_reach", lambda upper, *args: np.ones(len(upper), bool)
        )
    built = [0]
    tree = nearest_search._LazyTree.tree

    def counted(self: nearest_search._LazyTree) -> object:
        built[0] += self._tree is None
        return tree.fget(self)  # type: ignore[attr-defined]

    monkeypatch.setattr(nearest_search._LazyTree, "tree", property(counted))
    rng = np.random.default_rng(600 + seed)
    spared = used = 0
    for kind in range(12):
        pts = _trace(rng, kind)
        a, b = pts[:-1], pts[1:]
        reach = float(rng.choice([0.0015, 0.1, 1.5]))
        samples = _samples(rng, pts, 2000, reach=reach)
        distances = nearest_search.nearest_distances(samples, a, b)
        for offset in (0.0, 0.003, reach):
            want = float(np.max(np.abs(distances - offset)))
            before = built[0]
            with monkeypatch.context() as m:
                if every:  # not by measuring every distance, its fallback
                    m.setattr(nearest_search, "nearest_distances", None)
                got = nearest_search.farthest_off(samples, a, b, offset)
            assert got == want
            spared += built[0] == before
            used += built[0] != before
    assert used > 0 if every else spared > 0  # the tied samples' own branch ran, or not


def test_farthest_off_asks_the_tree_for_every_tie_that_may_end_unsure(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With no tolerance a tied sample may end unsure whatever its bounds: all are asked.

    The exact stage then gets the unsure samples the full search gets, and the figure is
    the same.
    """
    monkeypatch.setattr(nearest_exact, "NEAREST_TOLERANCE_MM", 0.0)
    rng = np.random.default_rng(7)
    pts = _trace(rng, 1)
    a, b = pts[:-1], pts[1:]
    samples = _samples(rng, pts, 2000, reach=1.5)
    want = float(np.max(np.abs(nearest_search.nearest_distances(samples, a, b) - 1.5)))
    asked: list[int] = []

    class Counted:  # the k-d tree, counting the samples it is asked about
        def __init__(self, points: np.ndarray) -> None:
            self.kd = cKDTree(points)

        def query(self, x: np.ndarray, *args: object, **kwargs: object) -> object:
            asked.append(len(x))
            return self.kd.query(x, *args, **kwargs)

    monkeypatch.setattr(
        nearest_search._LazyTree, "tree", property(lambda self: Counted(self.points))
    )
    assert nearest_search.farthest_off(samples, a, b, 1.5) == want
    tree = nearkernels.tree(np.concatenate([a, b]), segments=True)
    ask = nearkernels.near_segments(samples, *tree, a, b, 4)[3]
    assert ask.any() and sum(asked) == int(ask.sum())


def _zigzag(lines: int, step: float = 0.004) -> np.ndarray:
    """A trace of ``lines`` 9 mm lines across a 6 mm band and back, ``step`` apart along each."""
    x = np.arange(0.0, 9.0, step)
    rows = []
    for k in range(lines):
        y = (k * 0.137) % 6.0
        rows.append(np.c_[x if k % 2 == 0 else x[::-1], np.full(len(x), y)])
    return np.concatenate(rows)


def test_nodes_within_counts_every_box_within_reach() -> None:
    """Each box within reach of a sample, counted by brute force over every level's boxes
    (a child's box lies in its parent's, so the search opens exactly those)."""
    rng = np.random.default_rng(5)
    pts = _zigzag(12)
    _, boxes, offsets, _, _ = nearkernels.tree(pts, merge=False)
    samples = rng.uniform([0.0, 0.0], [9.0, 6.0], (200, 2))
    reach = rng.uniform(0.0, 0.5, 200)
    got = nearkernels.nodes_within(samples, boxes, offsets, reach)
    dx = np.maximum(
        np.maximum(boxes[None, :, 0] - samples[:, None, 0], 0.0),
        samples[:, None, 0] - boxes[None, :, 2],
    )
    dy = np.maximum(
        np.maximum(boxes[None, :, 1] - samples[:, None, 1], 0.0),
        samples[:, None, 1] - boxes[None, :, 3],
    )
    want = (dx * dx + dy * dy <= (reach * reach)[:, None]).sum(axis=1)
    assert got.tolist() == want.tolist()


def test_a_trace_that_passes_again_and_again_is_dense(monkeypatch: pytest.MonkeyPatch) -> None:
    """Samples on a zig-zag of 300 lines 20 µm apart on average: dense; on 3 of its lines,
    or 2 mm off to the side of the 300: not (the box tree's case)."""
    monkeypatch.undo()  # the real _dense
    for lines, off, dense in ((300, 0.0, True), (3, 0.0, False), (300, 2.0, False)):
        pts = _zigzag(lines)
        a, b = pts[:-1], pts[1:]
        tree = nearkernels.tree(np.concatenate([a, b]), segments=True, merge=False)
        samples = pts[:: max(1, len(pts) // 500)] + np.array([0.0005, 0.0003])
        if off:  # beside the band, below it
            samples = samples * np.array([1.0, 0.0]) - np.array([0.0, off])
        assert nearest_search._dense(samples, tree, 0.002, nearkernels) is dense


def test_the_shortfall_of_a_dense_trace_is_the_same_on_either_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Batches of path samples against one dense trace's ends, as the shortfall asks them:
    the k-d tree answers from the first batch on, with the box tree's distances."""
    monkeypatch.undo()  # the real choice
    pts = _zigzag(300, step=0.02)  # 270 000 ends: 600 samples ask (KD_ENDS_PER_SAMPLE)
    a, b = pts[:-1], pts[1:]
    rng = np.random.default_rng(9)
    ends = nearest_search._LazyTree(nearest_search._end_points(a, b))
    batches = [pts[rng.integers(0, len(pts), 600)] + rng.normal(0.0, 0.003, (600, 2)) for _ in "ab"]
    for samples in batches:
        want = nearest_search.nearest_distances_kd(samples, a, b)
        got = nearest_search.farthest_nearest(samples, a, b, ends=ends)
        assert ends.built()  # the k-d tree's path: nearest_distances_kd's numbers
        assert got == (float(np.max(want)), int(np.argmax(want)))


def test_ties_that_cannot_be_the_largest_build_no_k_d_tree(monkeypatch: pytest.MonkeyPatch) -> None:
    """Samples on and beside a stepped trace, and one far off it: the samples whose ends
    tie lie a few steps from the trace, far below the largest, so the k-d tree of the
    ends is never built."""
    rng = np.random.default_rng(5)
    pts = _trace(rng, 1)  # a random walk on a 4 µm grid
    a, b = pts[:-1], pts[1:]
    samples = _samples(rng, pts, 2000, reach=0.0015)
    far = pts.max(axis=0) + 1.0
    samples = np.concatenate([samples, [far]])  # the farthest, at least 1 mm off
    asked: list[int] = []
    real = nearest_search._ask_reaching

    def spy(*args: Any) -> None:
        asked.append(sum(len(rows) for rows, _, _ in args[3]))  # (search, ends, d, tied)
        real(*args)

    monkeypatch.setattr(nearest_search, "_ask_reaching", spy)
    builds: list[int] = []
    build = nearest_search._LazyTree._build
    monkeypatch.setattr(
        nearest_search._LazyTree, "_build", lambda self: builds.append(1) or build(self)
    )
    got = nearest_search.farthest_nearest(samples, a, b)
    assert asked and asked[0] > 0  # ties there were
    assert not builds
    assert got[1] == len(samples) - 1
    want = nearest_search.nearest_distances_kd(samples, a, b)
    assert got == (float(np.max(want)), int(np.argmax(want)))


def test_what_the_search_leaves_unset_for_ties_is_never_read(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The compiled search leaves a tied sample's distance unset (whatever the memory
    held): the largest distances come out the same, and no arithmetic warns, whatever it is."""
    import warnings

    measure = nearest_search._BoxSearch.measure

    def unset(self: nearest_search._BoxSearch, part: slice) -> tuple[np.ndarray, ...]:
        near, rk, lower, ask = measure(self, part)
        near[ask] = 1e300  # what an unset float may hold
        return near, rk, lower, ask

    rng = np.random.default_rng(11)
    pts = _trace(rng, 1)  # a random walk on a step grid: many ties
    a, b = pts[:-1], pts[1:]
    samples = _samples(rng, pts, 2000, reach=0.1)
    want = nearest_search.nearest_distances_kd(samples, a, b)
    monkeypatch.setattr(nearest_search._BoxSearch, "measure", unset)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for offset in (0.0, 0.1):
            got = nearest_search.farthest_off(samples, a, b, offset)
            assert got == float(np.max(np.abs(want - offset)))
        assert nearest_search.farthest_nearest(samples, a, b) == (
            float(np.max(want)),
            int(np.argmax(want)),
        )


def test_a_small_contour_s_few_samples_search_the_box_tree_without_a_probe(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A few path samples against a small dense trace (fewer than DENSE_PROBE_FROM samples
    and DENSE_PROBE_ENDS ends): the box tree answers them without the probe that would
    choose between the trees, with the k-d tree's distances; against a long trace the
    probe is still asked."""
    from camtool.accel import SWITCH

    monkeypatch.undo()  # the real choice
    monkeypatch.setenv(SWITCH, "1")  # undone with the rest: the compiled search still
    probed: list[int] = []
    real = nearest_search._dense
    monkeypatch.setattr(
        nearest_search, "_dense", lambda *args: probed.append(len(args[0])) or real(*args)
    )
    rng = np.random.default_rng(3)
    for lines, want_probe in ((4, False), (300, True)):
        pts = _zigzag(lines, step=0.02)
        a, b = pts[:-1], pts[1:]
        assert (2 * len(a) < nearest_search.DENSE_PROBE_ENDS) is not want_probe
        samples = pts[rng.integers(0, len(pts), 600)] + rng.normal(0.0, 0.003, (600, 2))
        probed.clear()
        want = nearest_search.nearest_distances_kd(samples, a, b)
        got = nearest_search.farthest_nearest(samples, a, b)
        assert got == (float(np.max(want)), int(np.argmax(want)))
        assert bool(probed) is want_probe
