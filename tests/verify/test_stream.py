"""A streamed verification (the trace simulated and measured in chunks) equals the whole one.

A big program's trace is never held whole (:func:`camtool.verify.streamed.simulate_big`).
Run with a tiny chunk size and a tiny streaming threshold, the same programs must give
the same report as the whole-array path, figure for figure; the one allowed exception is
the deviation's rms, summed exactly instead of by numpy's pairwise mean (its value may
differ in the last bits; the report rounds it to 0.1 nm).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from camtool.model.program import Program
from camtool.model.shapes import Drawing
from camtool.post.registry import load_target
from camtool.verify import cutting_thin, path_shortfall, streamed, trace_measures
from camtool.verify.chunked import ChunkedSimulation, StreamedTrace
from camtool.verify.report import build_report
from camtool.verify.simulate import simulate_steps
from camtool.verify.verifier import verify_program
from tests.verify.programs import TARGETS
from tests.verify.programs import mixed_program as _program

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

kernels = pytest.importorskip("camtool.accel.kernels")


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("chunk", [1, 37, 300])
def test_chunked_simulation_gives_the_whole_trace(name: str, chunk: int) -> None:
    machine = load_target(name).machine
    program = _program(chunk)
    whole = simulate_steps(program, machine)
    sim = ChunkedSimulation(program, machine, chunk)
    parts = list(sim.chunks())
    assert len(parts) > 1
    for key, column in (("rows", "rows"), ("carriage", "carriage_mm"), ("comp", "compensation")):
        joined = np.concatenate([getattr(p, column) for p in parts])
        assert np.array_equal(joined, getattr(whole, column)), key
    assert np.array_equal(np.concatenate([p.block_of_row() for p in parts]), whole.block_of_row)
    summary = sim.trace_summary()
    for key, value in summary.items():
        expected = getattr(whole, key)
        if isinstance(value, np.ndarray):
            assert np.array_equal(value, expected), key
        else:
            assert value == expected, key


def _strip_rms(report: dict) -> dict:
    out = dict(report)
    out["deviation_um"] = {k: v for k, v in report["deviation_um"].items() if k != "rms"}
    return out


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(3))
def test_streamed_verification_reports_the_whole_figures(name: str, seed: int) -> None:
    target = load_target(name)
    program = _program(seed)
    whole = verify_program(program, target.machine, name=name, budget=False)
    assert not isinstance(whole.trace, StreamedTrace)
    expected = build_report(whole)
    for chunk in (1, 53, 4000):
        v = verify_program(
            program, target.machine, name=name, budget=False, chunk_rows=chunk, stream_above=10
        )
        assert isinstance(v.trace, StreamedTrace)
        got = build_report(v)
        assert _strip_rms(got) == _strip_rms(expected)
        # every figure, unrounded: the same floats (the rms: to the last bits)
        assert v.contours == whole.contours
        assert v.along == whole.along
        dev, ref = v.deviation, whole.deviation
        assert (dev.max_um, dev.at_mm, dev.block, dev.points) == (
            ref.max_um,
            ref.at_mm,
            ref.block,
            ref.points,
        )
        assert math.isclose(dev.rms_um, ref.rms_um, rel_tol=1e-13)
        assert v.time_s == whole.time_s and v.warnings == whole.warnings
        assert v.trace.row_count == whole.trace.row_count
        # the picture's rows are the whole trace's, the worst deviation among them
        rows = np.flatnonzero(np.isin(whole.trace.carriage_mm[:, 0], v.trace.carriage_mm[:, 0]))
        assert len(rows) >= len(v.trace.carriage_mm) > 0
        assert tuple(dev.at_mm) in {tuple(p) for p in v.trace.carriage_mm.tolist()}


@pytest.mark.parametrize("take", [True, False, "alternate"])
def test_distances_taken_by_the_thread_ahead_give_the_same_report(
    monkeypatch: pytest.MonkeyPatch, take: bool | str
) -> None:
    """Whichever thread takes a chunk's distances (all, none, every other), the same report."""
    target = load_target("pic-mmh")
    program = _program(1)
    reference = verify_program(
        program, target.machine, name="pic-mmh", budget=False, chunk_rows=53, stream_above=10
    )
    calls = iter(range(10**6))
    taken: list[bool] = []

    def decide(self: streamed.Share) -> bool:
        got = next(calls) % 2 == 0 if take == "alternate" else bool(take)
        taken.append(got)
        return got

    monkeypatch.setattr(streamed.Share, "take", decide)
    v = verify_program(
        program, target.machine, name="pic-mmh", budget=False, chunk_rows=53, stream_above=10
    )
    assert len(taken) > 3 and (any(taken) if take else not any(taken))
    assert build_report(v) == build_report(reference)
    assert (v.deviation, v.along, v.contours) == (
        reference.deviation,
        reference.along,
        reference.contours,
    )


def test_the_share_balances_the_two_threads_time_a_row() -> None:
    """f = (c + d − m) / 2d of the chunks, in [0, 1]; none before anything is measured."""
    share = streamed.Share()
    assert not share.take()
    share.made(10e-6, 1000)  # m = 10 ns a row
    share.measured(7e-6, 1000)  # c = 7 ns
    share.measured_distances(11e-6, 1000)  # d = 11 ns: f = 8 / 22
    taken = sum(share.take() for _ in range(2200))
    assert abs(taken - 800) <= 1  # the credit is summed in floats
    share.made(40e-6, 1000)  # simulating slower than both: the mean moves, none taken
    for _ in range(40):
        share.made(40e-6, 1000)
    assert not any(share.take() for _ in range(100))
    fast = streamed.Share()
    fast.made(1e-9, 1000)
    fast.measured(50e-6, 1000)
    fast.measured_distances(1e-6, 1000)  # f > 1: every chunk
    assert all(fast.take() for _ in range(100))


def test_a_streamed_rms_is_the_exact_mean() -> None:
    """The rms of a streamed trace is sqrt(exact sum of the squares / n), from first principles."""
    target = load_target("pic-mmh")
    program = _program(5)
    v = verify_program(
        program, target.machine, name="pic-mmh", budget=False, chunk_rows=100, stream_above=10
    )
    whole = simulate_steps(program, target.machine)
    from camtool.verify.deviations import nominal_arrays, point_distances

    nominal = nominal_arrays(program)
    cutting = nominal["kind"][whole.block_of_row] != 2
    d = point_distances(whole.carriage_mm[cutting], whole.block_of_row[cutting], nominal)
    exact = sum((Fraction(float(x) * float(x)) for x in d), Fraction(0))
    assert v.deviation.rms_um == math.sqrt(float(exact) / len(d)) * 1000.0


def test_a_small_program_is_measured_whole() -> None:
    target = load_target("pic-mmh")
    v = verify_program(_program(0), target.machine, name="pic-mmh", budget=False)
    assert not isinstance(v.trace, StreamedTrace)


@pytest.mark.parametrize("seed", range(20))
def test_exact_sum_squares_is_the_exact_sum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 4000))
    values = rng.random(n) * 10.0 ** rng.uniform(-160, 150)
    if seed % 4 == 0:
        values[: n // 3] = 0.0
    if seed % 5 == 0 and n:
        values[-1] = 5e-324  # a subnormal (its square is 0)
        values[0] = 1e-160  # a subnormal square
    bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
    for i in range(0, n, 997):  # in pieces, past the carry at 512
        kernels.exact_sum_squares(values[i : i + 997], bins)
    exact = sum((Fraction(float(x) * float(x)) for x in values), Fraction(0))
    assert kernels.exact_sum(bins) == float(exact)


def _all_ones_square() -> float:
    """A double whose square (rounded) is within 4 ulps below 2: its mantissa's top 50 bits set.

    The largest double whose square is below 2. Such an addend, ``m > 2^53 − 2^21``,
    is what could overflow a bin carried only every 1024 additions (see below).
    """
    x = math.sqrt(2.0)
    while x * x >= 2.0:
        x = math.nextafter(x, 0.0)
    mantissa = int((x * x).hex()[4:17], 16) | (1 << 52)
    assert mantissa > (1 << 53) - (1 << 21)
    return x


@pytest.mark.parametrize("count", [511, 512, 513, 2048, 5000])
def test_exact_sum_squares_of_the_largest_mantissas_does_not_overflow(count: int) -> None:
    """Thousands of equal squares of all-ones mantissa in one bin (a constant offset).

    Carried every 1024 additions, the bin held ``1024·m`` (below 2^63), kept its low 32
    bits after the carry, and 1024 more such mantissas ``m`` took it past 2^63: it
    wrapped. Carried every 512 additions it cannot (analysis: a carried bin is below
    2^32 + 2^31, plus 512 mantissas below 2^53).
    """
    x = _all_ones_square()
    values = np.full(count, x)
    bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
    kernels.exact_sum_squares(values[: count // 3], bins)  # in two calls, too
    kernels.exact_sum_squares(values[count // 3 :], bins)
    assert kernels.exact_sum(bins) == float(Fraction(x * x) * count)


def test_exact_sum_squares_carries_what_earlier_calls_left() -> None:
    """Small pieces at far exponents, then many at one: every bin stays exact."""
    bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
    x = _all_ones_square()
    pieces = [np.full(300, 1e-150), np.full(300, x), np.full(300, 3e100), np.full(3000, x)]
    for values in pieces:
        kernels.exact_sum_squares(values, bins)
    total = sum((Fraction(float(v) * float(v)) for p in pieces for v in p), Fraction(0))
    assert kernels.exact_sum(bins) == float(total)


def test_carry_leaves_every_bin_it_reaches_below_two_to_the_32() -> None:
    """A carry into a bin outside the range added to carries that bin too, up the chain."""
    bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
    bins[900] = 1 << 62
    bins[932] = (1 << 62) - (1 << 30)  # becomes 2^62 with the carry from bin 900
    bins[964] = 5
    before = sum(int(v) << e for e, v in enumerate(bins.tolist()))
    assert kernels._carry(bins, 900, 900) == 964
    assert sum(int(v) << e for e, v in enumerate(bins.tolist())) == before
    assert int(bins.max()) < 1 << 32 and bins[964] == 5 + (1 << 30)


def test_exact_sum_squares_flags_a_non_finite_square() -> None:
    bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
    kernels.exact_sum_squares(np.asarray([1.0, 1e200]), bins)
    assert math.isnan(kernels.exact_sum(bins))


@pytest.mark.parametrize("seed", range(8))
def test_extent_is_numpys_max_and_min(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3000))
    points = (rng.random((n, 2)) - 0.5) * 10.0 ** rng.uniform(-3, 3)
    if seed % 3 == 1:
        points[rng.integers(0, n), int(rng.integers(0, 2))] = np.nan
    if seed % 4 == 2:
        points[:, 1] = 7.25  # a column of one value
    got = kernels.extent(points)
    want = (points[:, 0].max(), points[:, 0].min(), points[:, 1].max(), points[:, 1].min())
    for g, w in zip(got, want, strict=True):
        same_sign = math.copysign(1, g) == math.copysign(1, w)
        assert (math.isnan(g) and math.isnan(w)) or (g == w and same_sign)


def test_extent_of_a_nan_first_point() -> None:
    points = np.asarray([[np.nan, 1.0], [2.0, -3.0], [-4.0, 5.0]])
    x_top, x_low, y_top, y_low = kernels.extent(points)
    assert math.isnan(x_top) and math.isnan(x_low) and (y_top, y_low) == (5.0, -3.0)


@pytest.mark.parametrize("seed", range(12))
def test_compiled_to_line_is_the_numpy_distance_bit_for_bit(seed: int) -> None:
    from camtool.verify.deviations import _to_line

    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-4, 3)
    points = rng.normal(0.0, scale, (20_000, 2))
    if seed % 3 == 0:  # on a step grid, as a trace is
        points = np.round(points / 1.4e-4) * 1.4e-4
    ends = rng.normal(0.0, scale, 4)
    if seed % 4 == 0:  # a segment of no length
        ends[2:] = ends[:2]
    if seed % 4 == 1:  # points on the segment's ends and beyond them
        points[:100] = ends[:2]
        points[100:200] = ends[2:] + (ends[2:] - ends[:2])
    out = np.empty(len(points))
    kernels.to_line(points, *ends, out)
    assert np.array_equal(out.view(np.int64), _to_line(points, *ends).view(np.int64))


@pytest.mark.parametrize("seed", range(10))
def test_a_contour_thinned_on_the_fly_keeps_the_points_thinned_keeps(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A streamed contour keeps the points :func:`_thinned` keeps of the whole run."""
    from camtool.verify import path_shortfall

    rng = np.random.default_rng(seed)
    monkeypatch.setattr(path_shortfall, "ALONG_MAX_TRACE", int(rng.integers(50, 3000)))
    counts = rng.integers(0, 900, int(rng.integers(1, 12)))  # rows of each move
    counts[rng.random(len(counts)) < 0.2] = 0  # moves without rows
    rows = int(counts.sum())
    block_start = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    step = float(rng.choice([0.00014, 0.0002, 0.0007, 0.0]))
    points = np.cumsum(rng.choice([-step, 0.0, step], size=(rows, 2)), axis=0)
    before = rng.random(2)
    run = np.vstack([before, points])
    expected = path_shortfall._thinned(run, block_start[1:])
    contour = trace_measures._Contour(1, 0, len(counts) - 1, block_start)
    contour.add(0, before.reshape(1, 2))
    cuts = np.sort(rng.integers(0, rows + 1, int(rng.integers(0, 6))))
    for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, rows], strict=True):
        if hi > lo:
            contour.add(int(lo) + 1, points[lo:hi])
    # the segment ends, made from the pieces, before the pieces are joined
    ends = contour.ends()
    if len(expected) == 1:
        assert np.array_equal(ends, np.concatenate([expected, expected]))
    else:
        assert np.array_equal(ends, np.concatenate([expected[:-1], expected[1:]]))
    assert np.array_equal(contour.trace(), expected)


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(4))
def test_rows_at_least_never_overstates_the_trace(name: str, seed: int) -> None:
    """The bound that loads the kernels before a big program is counted is a lower bound.

    (A row steps each motor at most once, so a move takes at least its larger axis's
    steps in rows; the rounding of the ends takes one off.)
    """
    from camtool.verify.streamed import rows_at_least

    machine = load_target(name).machine
    program = _program(seed)
    trace = simulate_steps(program, machine)
    bound = rows_at_least(program, machine)
    assert 0 < bound <= trace.row_count
    per_move = np.diff(trace.block_start)
    start = program.origin
    for move, rows in zip(program.moves, per_move, strict=True):  # move by move too
        alone = Program((move,), origin=start)
        assert rows_at_least(alone, machine) <= rows
        start = (move.x, move.y)


def _drawn(program: Program) -> Drawing:
    """The drawing :func:`_program` cuts: its full circle and its square with an arc corner."""
    from camtool.model.shapes import Arc, Contour, Line

    circle = Contour((Arc((4.5, 3.0), (4.5, 3.0), (3.5, 3.0), False),), True)
    square = Contour(
        (
            Line((1.0, 1.0), (2.0, 1.0)),
            Arc((2.0, 1.0), (2.5, 1.5), (2.0, 1.5), False),
            Line((2.5, 1.5), (2.5, 2.5)),
            Line((2.5, 2.5), (1.0, 2.5)),
            Line((1.0, 2.5), (1.0, 1.0)),
        ),
        True,
    )
    return Drawing((circle, square))


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(3))
def test_a_streamed_verification_compares_the_drawing_as_the_whole_one(
    name: str, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With a drawing, a streamed trace gives the whole trace's comparison, float for float.

    Few thinned rows (``CUT_MAX_ROWS``) and a short head, so the every-k-th, the runs' ends
    and the head all fall across chunk edges.
    """

    monkeypatch.setattr(cutting_thin, "CUT_MAX_ROWS", 97)
    monkeypatch.setattr(cutting_thin, "CUT_HEAD_ROWS", 11)
    target = load_target(name)
    program = _program(seed)
    drawing = _drawn(program)
    whole = verify_program(
        program, target.machine, name=name, budget=False, against=drawing, tool_diameter=0.2
    )
    assert not isinstance(whole.trace, StreamedTrace)
    assert whole.against is not None and whole.against.samples > 0
    for chunk in (1, 53, 4000):
        v = verify_program(
            program,
            target.machine,
            name=name,
            budget=False,
            against=drawing,
            tool_diameter=0.2,
            chunk_rows=chunk,
            stream_above=10,
        )
        assert isinstance(v.trace, StreamedTrace)
        assert v.against == whole.against
        assert _strip_rms(build_report(v)) == _strip_rms(build_report(whole))


@pytest.mark.parametrize("seed", range(40))
def test_the_cutting_stream_keeps_the_rows_the_whole_trace_keeps(
    seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """:class:`CuttingStream` over any split of the rows = the whole trace's thinning.

    The reference is what :func:`against_drawing` does with the whole cutting trace
    (``cutting_rows``, then the every-k-th from its head and ``_thin_index``).
    """
    from camtool.verify import cutting_thin

    rng = np.random.default_rng(seed)
    monkeypatch.setattr(cutting_thin, "CUT_MAX_ROWS", int(rng.integers(1, 400)))
    monkeypatch.setattr(cutting_thin, "CUT_HEAD_ROWS", int(rng.integers(2, 60)))
    counts = rng.integers(0, 300, int(rng.integers(1, 30)))  # rows of each move
    counts[rng.random(len(counts)) < 0.2] = 0
    rapid = rng.random(len(counts)) < 0.3
    if seed % 7 == 0:
        rapid[:] = True  # nothing cuts
    blocks = np.repeat(np.arange(len(counts)), counts)
    step = float(rng.choice([0.0001, 0.004, 0.0]))
    points = np.cumsum(rng.choice([-step, 0.0, step], size=(len(blocks), 2)), axis=0)
    resolution = float(rng.choice([0.0005, 0.01, 0.1]))
    cutting = ~rapid[blocks]
    runs = np.cumsum(~cutting)[cutting]
    cut = points[cutting]
    n = len(cut)
    every = cutting_thin._cut_every(cut[: min(n, cutting_thin.CUT_HEAD_ROWS)], resolution)
    keep = (
        cutting_thin._thin_index(n, cutting_thin._cut_limit(n, every), runs)
        if n
        else np.zeros(0, int)
    )
    stream = cutting_thin.CuttingStream(rapid, n, resolution)
    edges = np.sort(rng.integers(0, len(blocks) + 1, int(rng.integers(0, 12))))
    if seed % 3 == 1:
        edges = np.arange(len(blocks) + 1)  # a row at a time: every row waits for the next
    for lo, hi in zip(np.r_[0, edges], np.r_[edges, len(blocks)], strict=True):
        stream.add(points[lo:hi], blocks[lo:hi])
    thin = stream.finish()
    assert thin.rows == n
    assert np.array_equal(thin.points, cut[keep])
    assert thin.runs is not None and np.array_equal(thin.runs, runs[keep])


def test_the_cutting_stream_refuses_rows_it_was_not_told_of() -> None:
    from camtool.verify.cutting_thin import CuttingStream

    stream = CuttingStream(np.zeros(1, dtype=bool), 5, 0.0005)
    stream.add(np.zeros((3, 2)), np.zeros(3, dtype=np.int64))
    with pytest.raises(RuntimeError, match="3 cutting rows streamed, 5 announced"):
        stream.finish()


@pytest.mark.parametrize("name", TARGETS)
def test_a_streamed_picture_keeps_the_rows_around_the_worst_point(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The zoom on the worst point has a trace to show: the rows around it are kept.

    Every k-th row alone (k = rows / PICTURE_ROWS) left the zoom of a 13 M-row job with
    the worst point's marker and nothing else.
    """

    monkeypatch.setattr(path_shortfall, "PICTURE_ROWS", 50)
    monkeypatch.setattr(path_shortfall, "ZOOM_ROWS", 30)
    target = load_target(name)
    program = _program(4)
    whole = simulate_steps(program, target.machine)
    v = verify_program(
        program, target.machine, name=name, budget=False, chunk_rows=10**6, stream_above=10
    )
    assert isinstance(v.trace, StreamedTrace)
    at = np.asarray(v.deviation.at_mm)
    # the first row of the worst move at that point (a carriage may stay put for rows)
    here = (whole.carriage_mm == at).all(axis=1) & (whole.block_of_row == v.deviation.block)
    worst = int(np.flatnonzero(here)[0])
    near = whole.carriage_mm[max(0, worst - 30) : worst + 31]
    kept = {tuple(p) for p in v.trace.carriage_mm.tolist()}
    assert {tuple(p) for p in near.tolist()} <= kept
    assert len(v.trace.carriage_mm) < len(whole.carriage_mm)  # still thinned elsewhere


def test_a_streamed_verification_tells_its_rows_as_they_are_measured() -> None:
    """``progress`` hears the rows measured after each chunk, rising to the trace's
    iterations, then the comparison with the drawing and its cutting rows."""
    from camtool.model.progress import Step

    target = load_target("pic-mmh")
    program = _program(0)
    heard: list[Step] = []
    v = verify_program(
        program,
        target.machine,
        name="pic-mmh",
        budget=False,
        against=_drawn(program),
        tool_diameter=0.2,
        chunk_rows=53,
        stream_above=10,
        progress=heard.append,
    )
    assert isinstance(v.trace, StreamedTrace)
    rows = [s for s in heard if s.stage == "simulating"]
    assert {s.total for s in rows} == {v.trace.total_rows}
    done = [s.done for s in rows]
    assert done[0] == 0 and done[-1] == v.trace.total_rows and done == sorted(done)
    assert len(rows) > 2  # a step per chunk
    comparing = [s for s in heard if s.stage == "comparing"]
    assert len(comparing) == 1 and comparing[0].total > 0
    assert heard.index(comparing[0]) > heard.index(rows[-1])
