"""The shortfall measures only the path samples that can be the largest (issue 17).

:class:`camtool.verify.path_shortfall._Bounded` bounds every path sample's distance to the
contour's thinned trace by a few segments at its place along the trace, and hands only
the samples whose bound can reach the largest shortfall to
:func:`camtool.verify.path_shortfall._farthest_from_trace`. The figures must be the ones that
measuring every sample gives, bit for bit: the reference here is the loop
:func:`camtool.verify.path_shortfall.along_path` ran before (every sample of every contour,
contours in order, the first strictly larger one kept), kept as the independent judge.
"""

from __future__ import annotations

import itertools
import math
import threading

import numpy as np
import pytest
import shapely

from camtool.model.program import ArcMove, Linear, Program, Rapid, segment_of
from camtool.post.registry import load_target
from camtool.verify import (
    contour_measures,
    dda,
    deviations,
    nearest_exact,
    nearest_search,
    path_shortfall,
    trace_measures,
)
from camtool.verify.simulate import simulate_steps
from tests.verify.programs import TARGETS
from tests.verify.programs import mixed_program as _program

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")


def _shortfall_reference(
    points: np.ndarray, block_start: np.ndarray, start_mm: tuple[float, float], program: Program
) -> tuple[float, tuple[float, float], int, int]:
    """The shortfall as along_path measured it before the bounds: every sample, in order."""
    starts = [program.origin] + [(m.x, m.y) for m in program.moves]
    runs = contour_measures.contour_runs(program)
    total = sum(
        segment_of(starts[i], program.moves[i]).length for a, b in runs for i in range(a, b + 1)
    )
    spacing = max(path_shortfall.ALONG_SPACING_MM, total / path_shortfall.ALONG_MAX_SAMPLES)
    start = np.asarray(start_mm, dtype=np.float64).reshape(1, 2)
    worst: tuple[float, tuple[float, float], int] = (0.0, (0.0, 0.0), -1)
    count = 0
    for first, last in runs:
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        before = points[lo - 1 : lo] if lo > 0 else start
        run = np.vstack([before, points[lo:hi]])
        samples, owner, _ = path_shortfall._sample_moves(program, starts, first, last, spacing)
        count += len(samples)
        if len(samples) == 0:
            continue
        move_ends = block_start[first + 1 : last + 2] - lo
        far, k = path_shortfall._farthest_from_trace(
            samples, path_shortfall._thinned(run, move_ends)
        )
        if far * 1000.0 > worst[0]:
            worst = (far * 1000.0, (float(samples[k, 0]), float(samples[k, 1])), int(owner[k]))
    return worst[0], worst[1], worst[2], count


def _shortfall(along: path_shortfall.AlongPath) -> tuple[float, tuple[float, float], int, int]:
    return along.shortfall_um, along.shortfall_at_mm, along.shortfall_block, along.samples


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("bound_from", [0, path_shortfall.SHORTFALL_BOUND_FROM])
def test_the_shortfall_is_the_one_of_every_sample(
    name: str, seed: int, bound_from: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every contour bounded (0), and small ones measured at once (the default)."""
    monkeypatch.setattr(path_shortfall, "SHORTFALL_BOUND_FROM", bound_from)
    machine = load_target(name).machine
    program = _program(seed)
    trace = simulate_steps(program, machine)
    args = (trace.carriage_mm, trace.block_start, trace.start_mm, program)
    want = _shortfall_reference(*args)
    got = _shortfall(path_shortfall.along_path(*args))
    assert got == want
    assert np.float64(got[0]).tobytes() == np.float64(want[0]).tobytes()


def _square_pass(n: int, lag: int) -> tuple[list[Linear | Rapid], np.ndarray]:
    """A rapid to a 1 mm square's corner, its four sides, and a trace of them.

    The trace has the rapid's one row, then ``n`` rows a side that zig-zag 2**-10 mm off
    it; its first ``lag`` rows of a side stay at the side's start (a backlash taking up
    its play).
    """
    corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
    moves: list[Linear | Rapid] = [Rapid(0.0, 0.0)]
    rows = [np.zeros((1, 2))]
    wiggle = np.where(np.arange(n) % 2 == 0, 0.0, 2.0**-10)
    for (ax, ay), (bx, by) in itertools.pairwise(corners):
        t = np.arange(1, n + 1, dtype=np.float64) / n
        t[:lag] = 0.0
        x = ax + (bx - ax) * t + (by - ay) * wiggle
        y = ay + (by - ay) * t - (bx - ax) * wiggle
        rows.append(np.column_stack([x, y]))
        moves.append(Linear(bx, by, 300.0))
    return moves, np.vstack(rows)


@pytest.mark.parametrize("lag", [0, 40])
@pytest.mark.parametrize("later_first", [False, True])
def test_equal_shortfalls_name_the_first_contour(
    lag: int, later_first: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Three passes over one square (step-downs): the same shortfall, bit for bit.

    The bounds measure the likeliest contour first; a later one with an equal figure
    must not displace an earlier one (the loop kept the first strictly larger).
    ``later_first``: each later pass's bounds are made a little looser (still bounds),
    so the passes are measured last first. Every contour is bounded here, however small.
    """
    monkeypatch.setattr(path_shortfall, "SHORTFALL_BOUND_FROM", 0)
    if later_first:
        sample, real = path_shortfall._sample_moves, path_shortfall._Bounded.of_run
        passing = [0]

        def samples_of(program: Program, starts: list, first: int, *rest: object) -> tuple:
            passing[0] = (first - 1) // 5  # the pass: its moves are 5k + 1 … 5k + 4
            return sample(program, starts, first, *rest)  # type: ignore[arg-type]

        def looser(*args: object, **kwargs: object) -> path_shortfall._Bounded:
            bounded = real(*args, **kwargs)  # type: ignore[arg-type]
            bounded.reach = bounded.reach + 1e-6 * passing[0]  # looser: still a bound
            bounded.reach_max = float(np.max(bounded.reach))
            return bounded

        monkeypatch.setattr(path_shortfall, "_sample_moves", samples_of)
        monkeypatch.setattr(path_shortfall._Bounded, "of_run", looser)
    moves: list[Linear | Rapid] = []
    rows = []
    for _ in range(3):
        m, r = _square_pass(256, lag)
        moves += m
        rows.append(r)
    program = Program(tuple(moves), origin=(0.0, 0.0))
    points = np.vstack(rows)
    block_start = np.concatenate(([0], np.cumsum([1, 256, 256, 256, 256] * 3))).astype(np.int64)
    args = (points, block_start, (0.0, 0.0), program)
    want = _shortfall_reference(*args)
    assert want[0] > 0 and want[2] in (1, 2, 3, 4)  # on the first pass
    assert _shortfall(path_shortfall.along_path(*args)) == want


def _contour_case(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random run (point before, then rows) of moves, some without rows, and the moves' ends."""
    counts = rng.integers(0, 700, int(rng.integers(1, 10)))
    counts[rng.random(len(counts)) < 0.2] = 0
    counts[0] = max(int(counts[0]), 1)
    rows = int(counts.sum())
    block_start = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    step = float(rng.choice([0.00014, 0.0002, 0.0007]))
    points = np.cumsum(rng.choice([-step, 0.0, step], size=(rows, 2)), axis=0)
    run = np.vstack([rng.random((1, 2)), points])
    return run, block_start[1:], counts


@pytest.mark.parametrize("seed", range(8))
def test_move_spans_name_each_moves_last_row_in_the_thinned_trace(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(seed)
    monkeypatch.setattr(path_shortfall, "ALONG_MAX_TRACE", int(rng.integers(30, 2000)))
    run, keep, _ = _contour_case(rng)
    every = path_shortfall._run_every(run)
    kept = np.zeros(len(run), dtype=bool)  # what _thinned keeps, from its docstring
    kept[::every] = True
    kept[-1] = True
    kept[keep] = True
    first, last = path_shortfall._move_spans(len(run), every, keep)
    assert np.array_equal(last, np.searchsorted(np.flatnonzero(kept), keep))
    assert np.array_equal(first, np.r_[0, last[:-1]])
    thinned = path_shortfall._thinned(run, keep)
    assert np.array_equal(thinned[last], run[keep])


def _traced(name: str, seed: int) -> tuple[Program, np.ndarray, np.ndarray, list, dict]:
    """:func:`_program` ``seed`` simulated on target ``name``: the program, its trace's
    carriage and move offsets, its moves' starts and their nominal arrays."""
    program = _program(seed)
    trace = simulate_steps(program, load_target(name).machine)
    starts = [program.origin] + [(m.x, m.y) for m in program.moves]
    nominal = deviations.nominal_arrays(program)
    return program, trace.carriage_mm, trace.block_start, starts, nominal


@pytest.mark.parametrize("name", TARGETS)
def test_a_bound_is_never_below_the_distance_to_the_whole_trace(name: str) -> None:
    """Each bound is a distance to one trace segment: at least the least over them all."""
    program, points, block_start, starts, nominal = _traced(name, 7)
    for first, last in contour_measures.contour_runs(program):
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        run = np.vstack([points[lo - 1 : lo], points[lo:hi]])
        samples, owner, t = path_shortfall._sample_moves(program, starts, first, last, 0.001)
        keep = block_start[first + 1 : last + 2] - lo
        part = {k: v[first : last + 1] for k, v in nominal.items()}
        bounded = path_shortfall._Bounded.of_run(samples, owner - first, t, run, keep, part)
        thinned = path_shortfall._thinned(run, keep)
        if len(thinned) < 2:  # one point: the distance to it
            point = np.hypot(*(samples - thinned[0]).T)
            assert np.all(bounded.reach >= point + nearest_exact.NEAREST_TOLERANCE_MM)
            continue
        a, b = thinned[:-1], thinned[1:]
        # GEOS's distance to the whole thinned trace, an independent judge of the bounds, to
        # the rounding of two formulas for one distance (64 ulps of the coordinates)
        every = shapely.distance(shapely.points(samples[::7]), shapely.linestrings(thinned))
        every -= 64.0 * np.spacing(np.max(np.abs(run)))
        upper = path_shortfall._window_bounds(samples, owner - first + t, bounded.places)
        assert np.all(upper[::7] >= every * (1 - 1e-12))
        assert np.all(bounded.reach[::7] >= every + nearest_exact.NEAREST_TOLERANCE_MM)
        # tight where the trace follows the path (the point of them); i8751's lines
        # stray up to 0.5 mm from it, so its nearest rows may lie elsewhere (still right)
        excess = np.median(upper - nearest_search.nearest_distances(samples, a, b))
        assert name == "i8751" or excess < 1e-4


def _first_contour_bounded(
    seed: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, path_shortfall._Bounded]:
    """The first contour of :func:`_program` ``seed`` on a target: samples, run, keep, bounds."""
    program, points, block_start, starts, nominal = _traced(TARGETS[seed % len(TARGETS)], seed)
    first, last = contour_measures.contour_runs(program)[0]
    lo, hi = int(block_start[first]), int(block_start[last + 1])
    run = np.vstack([points[lo - 1 : lo] if lo else np.zeros((1, 2)), points[lo:hi]])
    samples, owner, t = path_shortfall._sample_moves(program, starts, first, last, 0.001)
    keep = block_start[first + 1 : last + 2] - lo
    part = {k: v[first : last + 1] for k, v in nominal.items()}
    bounded = path_shortfall._Bounded.of_run(samples, owner - first, t, run, keep, part)
    return samples, run, keep, bounded


@pytest.mark.parametrize("seed", range(6))
def test_a_floor_leaves_out_only_samples_that_cannot_reach_it(seed: int) -> None:
    """With a floor the answer is the same when the largest reaches it, else below it."""
    samples, run, keep, bounded = _first_contour_bounded(seed)
    want = path_shortfall._farthest_from_trace(samples, path_shortfall._thinned(run, keep))
    for floor in (0.0, want[0] / 2, want[0], math.nextafter(want[0], 1.0), 2 * want[0] + 1e-3):
        got = bounded.farthest(floor)
        if floor <= want[0]:
            assert got == want
        else:
            assert got is None or got[0] < floor


@pytest.mark.parametrize("bound_from", [0, 10**9])
def test_a_streamed_shortfall_is_the_whole_ones(
    bound_from: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Streamed (batches bounded against the worst so far, or all measured): the same."""
    from camtool.verify.verifier import verify_program

    monkeypatch.setattr(path_shortfall, "SHORTFALL_BOUND_FROM", bound_from)
    machine = load_target("pic-mmh").machine
    for seed in range(3):
        program = _program(seed)
        trace = simulate_steps(program, machine)
        want = _shortfall_reference(trace.carriage_mm, trace.block_start, trace.start_mm, program)
        v = verify_program(
            program, machine, name="pic-mmh", budget=False, chunk_rows=300, stream_above=10
        )
        assert _shortfall(v.along) == want


def _circle_turns(turns: int, radius: float = 0.5) -> Program:
    """One contour going round a circle ``turns`` times in half circles (a hole in passes)."""
    cx, cy = 3.0, 3.0
    moves: list[Linear | Rapid | ArcMove] = [Rapid(cx - radius, cy, contour=1)]
    for k in range(2 * turns):
        x = cx + radius if k % 2 == 0 else cx - radius
        moves.append(ArcMove(x, cy, cx, cy, True, 300.0, contour=1))
    return Program(tuple(moves), origin=(0.0, 0.0))


@pytest.mark.parametrize("streamed", [False, True])
def test_the_likeliest_samples_measured_first_leave_most_out(
    streamed: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A staircase round a circle: few samples measured, the shortfall of every sample.

    The direct-search arcs' rows bound most path samples near the largest shortfall.
    The top sample's own distance left half of them to measure; the 1024 of largest
    bound measured first leave out all but a few of the rest.
    """
    from camtool.verify.verifier import verify_program

    machine = load_target("pic-mmh").machine
    program = _circle_turns(3)
    trace = simulate_steps(program, machine)
    want = _shortfall_reference(trace.carriage_mm, trace.block_start, trace.start_mm, program)
    measured = [0]
    real = nearest_search.farthest_nearest

    def spy(samples: np.ndarray, a: np.ndarray, b: np.ndarray, **kw: object) -> tuple[float, int]:
        measured[0] += len(samples)
        return real(samples, a, b, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(nearest_search, "farthest_nearest", spy)
    if streamed:
        v = verify_program(
            program, machine, name="pic-mmh", budget=False, chunk_rows=300, stream_above=10
        )
        along = v.along
        assert along is not None
    else:
        along = path_shortfall.along_path(
            trace.carriage_mm, trace.block_start, trace.start_mm, program
        )
    assert _shortfall(along) == want
    assert measured[0] < 0.2 * along.samples, (measured[0], along.samples)  # 51 % before


def test_a_streamed_contour_builds_its_search_trees_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """The batches and rounds of a streamed contour share its ends' search trees.

    A few samples to measure: the compiled box tree, built once for the contour (its
    form for few samples), and no scipy k-d tree (its build took most of the
    shortfall's time, for ~100 samples measured). The same shortfall. (The last
    contour's k-d tree built beside is the next test's; here none is.)
    """
    from camtool.verify.verifier import verify_program

    builds: list[tuple[int, bool]] = []
    kd: list[int] = []
    real_tree = nearest_search._ends_tree

    def ends_tree(points: np.ndarray, samples: int, kernels: object) -> tuple[object, ...]:
        got = real_tree(points, samples, kernels)  # type: ignore[arg-type]
        builds.append((len(points), len(got[0]) < len(points)))
        return got

    real_kd = nearest_search._LazyTree.tree.fget
    assert real_kd is not None

    def kd_tree(self: nearest_search._LazyTree) -> object:
        if self._tree is None:
            kd.append(len(self.points))
        return real_kd(self)

    monkeypatch.setattr(nearest_search, "_ends_tree", ends_tree)
    monkeypatch.setattr(nearest_search._LazyTree, "tree", property(kd_tree))
    monkeypatch.setattr(path_shortfall, "STREAM_SAMPLES", 3000)  # several batches per contour
    monkeypatch.setattr(trace_measures, "TREE_BESIDE_FROM", 10**12)
    machine = load_target("pic-mmh").machine
    moves = [Rapid(0.5, 0.5, contour=1)]
    for k in range(8):  # long lines along X, back and forth, 0.137 mm apart
        moves.append(Linear(6.0 if k % 2 == 0 else 0.5, 0.5 + 0.137 * (k + 1), 300.0, contour=1))
    program = Program(tuple(moves), origin=(0.0, 0.0))
    trace = simulate_steps(program, machine)
    want = _shortfall_reference(trace.carriage_mm, trace.block_start, trace.start_mm, program)
    builds.clear()
    kd.clear()
    v = verify_program(
        program, machine, name="pic-mmh", budget=False, chunk_rows=4096, stream_above=10
    )
    assert v.along is not None and _shortfall(v.along) == want
    assert want[3] > 5 * 3000  # path samples: several batches
    assert kd == []
    assert len(builds) == len(set(builds)) >= 1  # each form once for the contour


@pytest.mark.usefixtures("helpers_on")
@pytest.mark.parametrize("beside_from", [0, 10**12])
def test_the_last_contours_tree_is_built_beside_once_with_the_same_shortfall(
    beside_from: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The last contour's k-d tree is built in a thread while its samples are bounded.

    Two contours; with the rule on (``TREE_BESIDE_FROM`` 0), the last one's tree is built
    once, in the ``camtool-beside`` thread, and serves every batch; the first contour's
    is not. Off, no tree is built beside. The shortfall is the reference's either way.
    """
    from camtool.verify.verifier import verify_program

    monkeypatch.setattr(trace_measures, "TREE_BESIDE_FROM", beside_from)
    monkeypatch.setattr(path_shortfall, "STREAM_SAMPLES", 3000)  # several batches per contour
    built: list[tuple[int, str]] = []
    real_build = nearest_search._LazyTree._build

    def build(self: nearest_search._LazyTree) -> object:
        built.append((len(self.points), threading.current_thread().name))
        return real_build(self)

    monkeypatch.setattr(nearest_search._LazyTree, "_build", build)
    machine = load_target("pic-mmh").machine
    moves: list[Linear | Rapid | ArcMove] = []
    for c, y0 in ((1, 0.5), (2, 3.5)):
        moves.append(Rapid(0.5, y0, contour=c))
        for k in range(6):
            x = 6.0 if k % 2 == 0 else 0.5
            moves.append(Linear(x, y0 + 0.137 * (k + 1), 300.0, contour=c))
    program = Program(tuple(moves), origin=(0.0, 0.0))
    trace = simulate_steps(program, machine)
    want = _shortfall_reference(trace.carriage_mm, trace.block_start, trace.start_mm, program)
    v = verify_program(
        program, machine, name="pic-mmh", budget=False, chunk_rows=4096, stream_above=10
    )
    assert v.along is not None and _shortfall(v.along) == want
    assert not [t for t in threading.enumerate() if t.name == "camtool-beside"]
    beside = [n for n, thread in built if thread == "camtool-beside"]
    if beside_from == 0:
        assert len(beside) == 1  # the last contour's, once for its batches
    else:
        assert beside == []


@pytest.mark.parametrize("seed", range(4))
def test_the_rounds_by_partition_are_the_sorted_ones(seed: int) -> None:
    """:meth:`_Bounded.farthest` (a partition) against its stable sort, ties and floors included."""
    rng = np.random.default_rng(seed)
    for _ in range(300):
        n = int(rng.integers(1, 3000))
        count = int(rng.integers(1, 64))
        if seed % 2:
            values = rng.integers(0, int(rng.integers(1, 30)), n).astype(np.float64)
        else:
            values = rng.random(n)
        want = np.zeros(n, dtype=bool)
        want[np.argsort(-values, kind="stable")[:count]] = True
        assert np.array_equal(path_shortfall._largest(values, count), want)
    bounded = _first_contour_bounded(seed)[3]
    # bounds rounded to a coarse grid: many ties at the round's edge
    bounded.reach = np.round(bounded.reach, 4)
    far = bounded._farthest_sorted(0.0)
    assert far is not None
    for floor in (0.0, far[0] / 2, far[0], math.nextafter(far[0], 1.0), 2 * far[0] + 1e-3):
        assert bounded.farthest(floor) == bounded._farthest_sorted(floor)


@pytest.mark.parametrize("name", TARGETS)
def test_the_compiled_window_bounds_are_numpys_bit_for_bit(name: str) -> None:
    """:func:`camtool.accel.kernels.window_bounds` against the numpy form it replaces.

    Real traces of every target, plus one with rows that do not move (pieces of no
    length), samples far away, on the trace and NaN (kept, as ``np.minimum`` keeps it).
    """
    if dda.compiled() is None:
        pytest.skip("numba missing")
    program, points, block_start, starts, nominal = _traced(name, 3)
    rng = np.random.default_rng(len(name))
    for first, last in contour_measures.contour_runs(program):
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        run = np.vstack([points[lo - 1 : lo] if lo else np.zeros((1, 2)), points[lo:hi]])
        run = np.repeat(run, rng.integers(1, 3, len(run)), axis=0)  # rows that do not move
        samples, owner, t = path_shortfall._sample_moves(program, starts, first, last, 0.002)
        extra = np.vstack([run[::97], run[::89] + 5.0, [[np.nan, 1.0]]])
        samples = np.vstack([samples, extra])
        place = np.concatenate([owner - first + t, rng.random(len(extra)) * (last - first + 1)])
        keep = np.minimum(np.cumsum(np.ones(last - first + 1, dtype=np.int64)) * 5, len(run) - 1)
        part = {k: v[first : last + 1] for k, v in nominal.items()}
        a, b = path_shortfall._segments(run)
        places = path_shortfall._Places(a, b, path_shortfall._move_spans(len(run), 1, keep), part)
        compiled = path_shortfall._window_bounds(samples, place, places)
        with dda.KERNELS.off():
            plain = path_shortfall._window_bounds(samples, place, places)
        assert np.array_equal(compiled, plain, equal_nan=True)
        assert np.isnan(compiled[-1]) and np.isnan(plain[-1])
        assert np.all(compiled[:-1] >= 0.0)
