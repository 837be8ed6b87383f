"""The compiled (numba) interpolator paths give exactly the rows of the plain ones.

Expected values are never camtool's compiled output: every case compares the compiled path
with the literal register loops of UNAM-GMM annex A.3 / A.6 (``*_reference``) or with the
numpy / pure-Python path the compiled one replaces, on thousands of random cases and the
edge cases (zero-length, one axis, 45°, integer HIPO, negative, large).
"""

from __future__ import annotations

import random
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.verify import dda
from camtool.verify import interpolators as itp

pytestmark = pytest.mark.skipif(
    dda.compiled() is None,
    reason="compiled kernels off (CAMTOOL_ACCEL=0; CI's first run tests them) or numba missing",
)


@pytest.fixture
def plain(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Run the interpolators without the compiled kernels inside the ``with``-less test."""
    with dda.KERNELS.off():
        yield


def _plain(fn, *args):  # type: ignore[no-untyped-def]
    """``fn(*args)`` with the compiled kernels switched off."""
    with dda.KERNELS.off():
        return fn(*args)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and bool(np.array_equal(a, b))


EDGE_LINES = [
    (0, 0),
    (1, 0),
    (0, 1),
    (-1, 0),
    (0, -1),
    (1, 1),
    (-1, -1),
    (3, 4),
    (-3, 4),
    (4, -3),
    (6, 8),
    (5, 12),
    (20, 21),
    (7, 0),
    (0, -7),
    (1000, 1000),
    (-999, 999),
    (300, 400),
    (65535, 1),
    (1, 65535),
    (119, 120),
    (100_000, 0),
    (0, 100_000),
    (-250_000, 150_000),
    (2_000_000, 1_234_567),
    (1_234_567, -2_000_000),
]


@pytest.mark.parametrize(("dx", "dy"), EDGE_LINES)
def test_dda_edges_equal_the_a3_register_loop(dx: int, dy: int) -> None:
    """Analytic (UNAM-GMM A.3): the compiled DDA is the register loop, row for row."""
    fast = dda.dda_line(dx, dy)
    assert not fast.flags.writeable
    assert _same(fast, dda.dda_line_numpy(dx, dy))
    if abs(dx) + abs(dy) <= 300_000:  # the literal loop is slow on the largest ones
        assert _same(fast, dda.dda_line_reference(dx, dy))


def test_dda_thousands_of_random_lines() -> None:
    """Analytic: compiled == numpy closed form == A.3 loop on 4000 random lines."""
    rng = random.Random(17)
    for _ in range(4000):
        m = rng.choice((2, 10, 100, 1000, 20_000))
        dx, dy = rng.randint(-m, m), rng.randint(-m, m)
        if rng.random() < 0.1:
            dx, dy = (dx, 0) if rng.random() < 0.5 else (0, dy)
        fast = dda.dda_line(dx, dy)
        assert _same(fast, dda.dda_line_numpy(dx, dy)), (dx, dy)
        if m <= 1000:
            assert _same(fast, dda.dda_line_reference(dx, dy)), (dx, dy)


def test_dda_pythagorean_lines_take_the_integer_loop() -> None:
    """Analytic: with HIPO an integer (k·(3, 4), k·(5, 12), ...) ties are real and exact."""
    for a, b in ((3, 4), (5, 12), (8, 15), (7, 24), (20, 21)):
        for k in (1, 2, 7, 50, 1001):
            for sx, sy in ((1, 1), (-1, 1), (1, -1), (-1, -1)):
                dx, dy = sx * a * k, sy * b * k
                fast = dda.dda_line(dx, dy)
                assert _same(fast, dda.dda_line_reference(dx, dy)), (dx, dy)


@settings(max_examples=300, deadline=None)
@given(st.integers(-5000, 5000), st.integers(-5000, 5000))
def test_dda_property(dx: int, dy: int) -> None:
    """Analytic: any line, compiled == the literal A.3 loop."""
    assert _same(dda.dda_line(dx, dy), dda.dda_line_reference(dx, dy))


def test_dda_numpy_integers_accepted() -> None:
    """numpy integers are integers (as for the plain path)."""
    assert _same(dda.dda_line(np.int64(30), np.int32(-40)), dda.dda_line_reference(30, -40))


def _arc_cases(count: int, seed: int) -> Iterator[tuple[int, int, int, int, int, int, bool]]:
    rng = random.Random(seed)
    for _ in range(count):
        m = rng.choice((2, 5, 30, 300, 3000))
        cx, cy = rng.randint(-m, m), rng.randint(-m, m)
        x0, y0 = rng.randint(-m, m), rng.randint(-m, m)
        if (x0, y0) == (cx, cy):
            continue
        if rng.random() < 0.3:  # a full circle
            x1, y1 = x0, y0
        elif rng.random() < 0.5:  # an end on the circle (rounded)
            r = ((x0 - cx) ** 2 + (y0 - cy) ** 2) ** 0.5
            a = rng.uniform(0, 6.283)
            x1, y1 = cx + round(r * np.cos(a)), cy + round(r * np.sin(a))
        else:  # any end point (inconsistent: closing steps)
            x1, y1 = rng.randint(-m, m), rng.randint(-m, m)
        yield x0, y0, x1, y1, cx, cy, rng.random() < 0.5


def test_dsm_thousands_of_random_arcs_equal_the_a6_transcription() -> None:
    """Analytic (UNAM-GMM A.6): compiled DSM == the literal transcription on 3000 arcs."""
    for case in _arc_cases(3000, seed=6):
        assert _same(itp.dsm_arc(*case), itp.dsm_arc_reference(*case)), case


def test_staircase_and_dsm_random_arcs_equal_the_python_loops() -> None:
    """Analytic (UNAM-GMM A.5/A.6): compiled quadrant loops == the Python ones."""
    for case in _arc_cases(2000, seed=5):
        for fn in (itp.staircase_arc, itp.dsm_arc):
            assert _same(fn(*case), _plain(fn, *case)), (fn.__name__, case)


@pytest.mark.parametrize("radius", [1, 2, 30, 1000, 200_000])
@pytest.mark.parametrize("clockwise", [True, False])
def test_full_circles_edges(radius: int, clockwise: bool) -> None:
    """UNAM-GMM §4.7 Tabla 7 circles and large ones: compiled == plain, start on each axis."""
    for x0, y0 in ((radius, 0), (0, radius), (-radius, 0), (0, -radius)):
        case = (x0 + 7, y0 - 3, x0 + 7, y0 - 3, 7, -3, clockwise)
        for fn in (itp.staircase_arc, itp.dsm_arc):
            assert _same(fn(*case), _plain(fn, *case)), (fn.__name__, case)
    if radius == 30:  # Tabla 7: DSM 168 iterations, staircase 240 (8R)
        assert len(itp.dsm_arc(30, 0, 30, 0, 0, 0, clockwise)) == 168
        assert len(itp.staircase_arc(30, 0, 30, 0, 0, 0, clockwise)) == 240


@pytest.mark.parametrize("start", [0, 1, 7])
def test_quadrant_loops_grow_a_full_buffer_and_resume_where_they_stopped(start: int) -> None:
    """The quadrant kernels stop when their buffer is full, grow it and go on (``dx``,
    ``dy`` made again from ``x``, ``y``): from a buffer of a few rows, the rows, end state
    and D of the Python runners (UNAM-GMM A.5/A.6) on quarter circles of radius 1 to 5 000,
    both senses of the growing axis."""
    kernels = dda.compiled()
    for radius in (1, 2, 30, 997, 5000):
        for gx, sx, sy in ((-1, 0, radius), (1, radius, 0)):
            x, y = (radius, 0) if gx < 0 else (0, radius)
            for name, kernel in (
                ("dsm", kernels.dsm_quadrant),
                ("staircase", kernels.staircase_quadrant),
            ):
                runner = itp._dsm_run if name == "dsm" else itp._staircase_run
                codes = bytearray()
                want = runner(x, y, 0, gx, -gx, sx, sy, codes)
                rows = itp._code_rows(codes, 1, -1)
                out = np.full((start + 3, 2), 9, dtype=np.int8)
                *got, buffer, at = kernel(x, y, 0, gx, -gx, sx, sy, 1, -1, out, start)
                assert tuple(got) == want, (name, radius, gx)
                assert at - start == len(rows)
                assert np.array_equal(buffer[start:at], rows), (name, radius, gx)
                assert (buffer[:start] == 9).all()  # the rows before ``at`` kept as given


def test_huge_coordinates_stay_on_the_exact_python_path() -> None:
    """Magnitudes past int64 safety never reach the compiled loop (same rows as the plain)."""
    big = 1 << 41
    case = (big + 5, big, big + 5, big - 3, big, big, True)
    assert _same(itp.dsm_arc(*case), itp.dsm_arc_reference(*case))


def test_plain_fixture_switches_the_kernels_off(plain: None) -> None:
    """The comparison really runs two paths: with the fixture no kernel is loaded."""
    assert dda.compiled() is None
    assert _same(dda.dda_line(3, 4), dda.dda_line_reference(3, 4))


def _random_rows(rng: np.random.Generator, n: int) -> np.ndarray:
    """Step rows with long runs and reversals on both axes (as a real trace has)."""
    rows = np.zeros((n, 2), dtype=np.int8)
    at = 0
    while at < n:
        length = min(int(rng.integers(1, 4000)), n - at)
        rows[at : at + length, 0] = rng.choice((-1, 0, 1)) * (rng.random(length) < 0.9)
        rows[at : at + length, 1] = rng.choice((-1, 0, 1)) * (rng.random(length) < 0.3)
        at += length
    return rows


@pytest.mark.parametrize("profile", ["mmh-gmm", "valcnc", "grbl"])
def test_carriage_compiled_equals_numpy(profile: str) -> None:
    """The compiled play operator gives the numpy one's floats exactly (regions included)."""
    from camtool.post.registry import load_machine
    from camtool.verify import simulate

    machine = load_machine(profile)
    jit = dda.compiled()
    rng = np.random.default_rng(3)
    for n, origin in ((1, (0, 0)), (7, (5, -3)), (50_000, (3000, 20_000)), (200_000, (0, 0))):
        rows = _random_rows(rng, n)
        fast = simulate._carriage_compiled(jit, rows, origin, machine)
        slow = simulate._carriage_numpy(rows, origin, machine)
        assert fast.dtype == slow.dtype and np.array_equal(fast, slow), (profile, n)
    still = np.zeros((10, 2), dtype=np.int8)  # no step at all: the start, everywhere
    fast = simulate._carriage_compiled(jit, still, (4, 9), machine)
    assert np.array_equal(fast, simulate._carriage_numpy(still, (4, 9), machine))


@pytest.mark.parametrize("seed", range(6))
def test_reversals_and_pulses_equal_numpy(seed: int) -> None:
    """One compiled scan gives the numpy reversals, the direction after and the pulses."""
    jit = dda.compiled()
    rng = np.random.default_rng(seed)
    rows = _random_rows(rng, int(rng.integers(0, 20_000)))
    for axis in (0, 1):
        for direction in (-1, 0, 1):
            column = rows[:, axis].astype(np.int64)
            nz = np.flatnonzero(column)
            signs = np.sign(column[nz])
            before = np.concatenate(([direction], signs[:-1]))
            at = np.flatnonzero((signs != before) & (before != 0))
            rows_at, signs_at, last, pulses = jit.reversals(rows, axis, direction)
            assert np.array_equal(rows_at, nz[at]) and np.array_equal(signs_at, signs[at])
            assert signs_at.dtype == np.int8 and rows_at.dtype == np.int64
            assert last == (int(signs[-1]) if len(nz) else direction)
            assert pulses == int(np.abs(column).sum())


@pytest.mark.parametrize("seed", range(6))
def test_play_runs_equal_a_python_scan(seed: int) -> None:
    """Both axes' runs from one pass each: the first row, sign and motor of every run."""
    jit = dda.compiled()
    rng = np.random.default_rng(seed)
    rows = _random_rows(rng, int(rng.integers(0, 5000)))
    ox, oy = int(rng.integers(-100, 100)), int(rng.integers(-100, 100))
    got = jit.play_runs(rows, ox, oy)
    motor = np.cumsum(rows.astype(np.int64), axis=0) + np.asarray([ox, oy])
    for axis in (0, 1):
        starts, signs, last = [], [], 0
        for i, s in enumerate(rows[:, axis].tolist()):
            if s != 0 and s != last:
                starts.append(i)
                signs.append(s)
                last = s
        assert np.array_equal(got[3 * axis], np.asarray(starts, dtype=np.int64))
        assert np.array_equal(got[3 * axis + 1], np.asarray(signs, dtype=np.int8))
        assert np.array_equal(got[3 * axis + 2], motor[starts].reshape(-1, 2))


def test_deviation_by_blocks_equals_the_gathered_form() -> None:
    """Block-wise deviation (scalars for long lines, chunks) == the one-pass gathered form."""
    from camtool.model.program import ArcMove, Linear, Program, Rapid
    from camtool.verify import deviations

    rng = np.random.default_rng(8)
    moves = [Rapid(1.0, 1.0), Linear(5.0, 1.0, 100.0), ArcMove(5.0, 3.0, 5.0, 2.0, False, 100.0)]
    moves += [Linear(5.0, 3.0, 100.0), Rapid(2.0, 2.0), Linear(2.0, 2.0, 100.0)]  # zero-length
    moves += [Linear(1.0 + 0.001 * k, 2.0 + 0.002 * k, 100.0) for k in range(300)]
    program = Program(tuple(moves), origin=(0.0, 0.0))
    sizes = [int(rng.integers(0, 9000)) for _ in moves]
    sizes[1], sizes[2] = 20_000, 6_000  # a long line, a long arc
    blocks = np.repeat(np.arange(len(moves), dtype=np.int64), sizes)
    points = rng.uniform(0.0, 6.0, (len(blocks), 2))
    for chunk in (1 << 18, 1000):
        saved = deviations.DEVIATION_CHUNK
        deviations.DEVIATION_CHUNK = chunk
        try:
            fast = deviations.deviation(points, blocks, program)
        finally:
            deviations.DEVIATION_CHUNK = saved
        assert fast == deviations.deviation_gathered(points, blocks, program)
    shuffled = blocks[::-1].copy()  # not in block order: the gathered form runs
    assert deviations.deviation(points, shuffled, program) == deviations.deviation_gathered(
        points, shuffled, program
    )


def _star_program(machine_name: str) -> tuple[object, object]:
    """Circles and star lines about the work-area centre (reversals on both axes)."""
    import math

    from camtool.model.program import ArcMove, Linear, Program, Rapid
    from camtool.post.registry import load_machine

    machine = load_machine(machine_name)
    x0, y0, x1, y1 = machine.work_area_mm
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    size = min(x1 - x0, y1 - y0) * 0.2
    moves: list[object] = []
    for k in range(6):
        r = size * (0.3 + 0.7 * ((k * 0.618) % 1.0))
        moves += [Rapid(cx + r, cy), ArcMove(cx + r, cy, cx, cy, k % 2 == 0, 100.0)]
        a = k * 0.7
        moves += [Linear(cx + r * math.cos(a), cy + r * math.sin(a), 100.0), Linear(cx, cy, 100.0)]
    return Program(tuple(moves), origin=(cx, cy)), machine  # type: ignore[arg-type]


@pytest.mark.parametrize("machine_name", ["mmh-gmm", "valcnc", "grbl"])
def test_simulation_with_and_without_kernels_is_identical(machine_name: str) -> None:
    """The whole step trace (rows, compensation, carriage, counts) is the same either way."""
    import dataclasses

    from camtool.verify.simulate import simulate_steps

    program, machine = _star_program(machine_name)
    fast = simulate_steps(program, machine)  # type: ignore[arg-type]
    slow = _plain(simulate_steps, program, machine)
    for f in dataclasses.fields(fast):
        a, b = getattr(fast, f.name), getattr(slow, f.name)
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype and np.array_equal(a, b), f.name
        else:
            assert a == b, f.name
    assert fast.compensations > 0 or machine_name != "mmh-gmm"


@pytest.mark.parametrize("amass", [True, False])
@pytest.mark.parametrize(("dx", "dy"), EDGE_LINES)
def test_bresenham_edges_equal_grbl_s_counter_loop(dx: int, dy: int, amass: bool) -> None:
    """Analytic (grbl ``stepper.c``): the compiled Bresenham line is the counter loop."""
    if max(abs(dx), abs(dy)) > 300_000:
        pytest.skip("the reference loop is Python: kept to lines of a few 100 000 steps")
    fast = itp.bresenham_line(dx, dy, amass=amass)
    assert _same(fast, itp.bresenham_reference(dx, dy, amass=amass))
    assert _same(fast, _plain(lambda: itp.bresenham_line(dx, dy, amass=amass)))


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.tuples(st.integers(-3000, 3000), st.integers(-3000, 3000)), max_size=20),
    st.booleans(),
)
def test_bresenham_lines_compiled_equal_the_numpy_path(
    moves: list[tuple[int, int]], amass: bool
) -> None:
    """Many lines at once (an arc's chords): the compiled rows are the numpy path's, and
    each line's the counter loop's."""
    dx = np.array([m[0] for m in moves], dtype=np.int64)
    dy = np.array([m[1] for m in moves], dtype=np.int64)
    rows, first = itp.bresenham_lines(dx, dy, amass=amass)
    plain_rows, plain_first = _plain(lambda: itp.bresenham_lines(dx, dy, amass=amass))
    assert _same(rows, plain_rows)
    assert np.array_equal(first, plain_first)
    each = [itp.bresenham_reference(x, y, amass=amass) for x, y in moves]
    assert _same(rows, np.concatenate(each) if each else np.zeros((0, 2), dtype=np.int8))
