"""Tests of the verifier's interpolators against the thesis notes and analytic facts.

Every expected value names its source: a table/section of docs/references.md,
or "analytic" for a property that follows from the geometry or the algorithm's definition.
"""

from __future__ import annotations

import math
from decimal import Decimal

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from camtool.model.errors import InputError, UsageError
from camtool.model.shapes import chord_count
from camtool.verify.dda import accumulator_dda_table, dda_iterations, dda_line, dda_line_reference
from camtool.verify.interpolators import (
    accumulator_dda_line,
    accumulator_dda_reference,
    bresenham_line,
    bresenham_lines,
    bresenham_reference,
    chord_sagitta,
    circular_dda_arc,
    corte_recto_line,
    corte_recto_max_deviation,
    corte_recto_reference,
    dsm_arc,
    dsm_arc_reference,
    polyline_steps,
    staircase_arc,
)
from camtool.verify.quantize import steps_from_mm
from camtool.verify.steparray import positions

LINES = [dda_line, dda_line_reference, accumulator_dda_line, accumulator_dda_reference,
         bresenham_line, bresenham_reference, corte_recto_line, corte_recto_reference]  # fmt: skip
ARCS = [dsm_arc, staircase_arc, circular_dda_arc]

small = st.integers(min_value=-300, max_value=300)


def pattern(steps: np.ndarray) -> str:
    """UNAM-GMM §4.2 notation: X, Y, XY per iteration, '-' without a pulse."""
    return " ".join(("X" if a else "") + ("Y" if b else "") or "-" for a, b in steps)


def assert_step_array(steps: np.ndarray) -> None:
    assert steps.dtype == np.int8
    assert steps.ndim == 2 and steps.shape[1] == 2
    assert not steps.flags.writeable
    assert np.all(np.abs(steps) <= 1)


def path(steps: np.ndarray, start: tuple[int, int]) -> list[tuple[int, int]]:
    return [start] + [(int(x), int(y)) for x, y in positions(steps, start)]


def radial_error(steps: np.ndarray, start: tuple[int, int], centre: tuple[int, int]) -> float:
    r = math.hypot(start[0] - centre[0], start[1] - centre[1])
    pos = positions(steps, start) - np.asarray(centre)
    return float(np.max(np.abs(np.hypot(pos[:, 0], pos[:, 1]) - r)))


# ------------------------------------------------------------------ linear DDA, UNAM-GMM


@pytest.mark.parametrize(
    ("dx", "dy", "expected"),
    [
        (3, 4, "- XY Y XY - XY"),  # UNAM-GMM §4.2 test vectors table
        (5, 0, "- X X X X X"),  # UNAM-GMM §4.2 test vectors table
        (10, 3, "- X X XY X X XY X X X XY"),  # UNAM-GMM §4.2 / §9 S000-13
        (7, 7, "- XY XY - XY XY - XY XY XY"),  # UNAM-GMM §4.2 test vectors table
    ],
)
@pytest.mark.parametrize("line", [dda_line, dda_line_reference])
def test_dda_golden_patterns(line, dx, dy, expected):
    steps = line(dx, dy)
    assert pattern(steps) == expected
    assert len(steps) == len(expected.split())  # iterations 6 / 6 / 11 / 10 (§4.2)


def test_dda_golden_iteration_counts():
    # UNAM-GMM §4.2 table: (3,4) → 6, (5,0) → 6, (10,3) → 11, (7,7) → 10 iterations
    assert [len(dda_line(*d)) for d in [(3, 4), (5, 0), (10, 3), (7, 7)]] == [6, 6, 11, 10]


def test_dda_signs_follow_the_move():
    # analytic: the sign of dx/dy only mirrors the steps (A.3 works on magnitudes)
    base = dda_line(10, 3)
    assert np.array_equal(dda_line(-10, 3), base * np.array([-1, 1]))
    assert np.array_equal(dda_line(-10, -3), -base)
    assert np.array_equal(dda_line_reference(10, -3), base * np.array([1, -1]))


@given(small, small)
def test_dda_vectorised_equals_reference_loop(dx, dy):
    # analytic: closed form ceil(n·P/HIPO) − 1 of the A.3 registers == the literal loop
    assert np.array_equal(dda_line(dx, dy), dda_line_reference(dx, dy))


@pytest.mark.parametrize(
    ("dx", "dy"),
    [(3000, 4000), (-5000, 12000), (8000, 15000), (1, 1), (99991, 3), (70000, 70001), (0, 9)],
)
def test_dda_vectorised_equals_reference_large_and_ties(dx, dy):
    # analytic: integer HIPO (Pythagorean triples) gives exact ties n·P = k·HIPO, where
    # the strict '>' of A.3 must not overflow; large irrational HIPO gives near-ties
    assert np.array_equal(dda_line(dx, dy), dda_line_reference(dx, dy))


@given(small, small)
def test_dda_iterations_is_floor_hipo_plus_one(dx, dy):
    # analytic (UNAM-GMM §4.2 notes: "about L iterations per segment")
    expected = 0 if dx == dy == 0 else math.isqrt(dx * dx + dy * dy) + 1
    assert dda_iterations(dx, dy) == expected == len(dda_line(dx, dy))


def test_dda_zero_move_and_bad_input():
    assert dda_line(0, 0).shape == (0, 2)
    with pytest.raises(UsageError):
        dda_line(1.5, 2)  # type: ignore[arg-type]


# ---------------------------------------------------------------------- all lines


@pytest.mark.parametrize("line", LINES)
@given(dx=small, dy=small)
@settings(suppress_health_check=[HealthCheck.function_scoped_fixture], max_examples=60)
def test_lines_end_exactly_at_the_target(line, dx, dy):
    # analytic: every line interpolator issues exactly |dx| X and |dy| Y steps
    steps = line(dx, dy)
    assert_step_array(steps)
    assert tuple(int(v) for v in steps.astype(np.int64).sum(axis=0)) == (dx, dy)


# ------------------------------------------------------------ accumulator DDA, Munoz-22


def test_accumulator_dda_reproduces_table_8():
    # Munoz-22 §4.1 Table 8 (L1241–L1250): 7 steps in X, 3 in Y; columns
    # iteration, X travelled, Y travelled, CUENTA
    expected = [
        [1, 1, 0, 3],
        [2, 2, 0, 6],
        [3, 3, 1, 2],
        [4, 4, 1, 5],
        [5, 5, 2, 1],
        [6, 6, 2, 4],
        [7, 7, 3, 0],
    ]
    assert accumulator_dda_table(7, 3).tolist() == expected
    steps = accumulator_dda_line(7, 3)
    assert path(steps, (0, 0))[1:] == [(r[1], r[2]) for r in expected]


@given(small, small)
def test_accumulator_dda_vectorised_equals_reference(dx, dy):
    assert np.array_equal(accumulator_dda_line(dx, dy), accumulator_dda_reference(dx, dy))


def test_accumulator_dda_timing_example():
    # Munoz-22 §8 S004-R13: a 10 mm single-axis move = 250 steps (25 steps/mm) = 41.7 ms
    # at 166.667 µs per iteration; a 10×10 mm diagonal also takes 41.7 ms
    n = steps_from_mm(10.0, 0.04)
    assert n == 250
    for move in [(n, 0), (n, n)]:
        assert len(accumulator_dda_line(*move)) * 166.667e-6 == pytest.approx(0.0417, abs=5e-5)


def test_accumulator_dda_minor_axis_lags():
    # Munoz-22 §4.1 [derived]: the accumulator starts at 0, so the minor axis never
    # leads the ideal line: minor travelled = floor(n·minor/major)
    table = accumulator_dda_table(-13, 5)
    n = table[:, 0]
    assert np.array_equal(table[:, 2], (n * 5) // 13)


# ------------------------------------------------------------------- Bresenham (GRBL)


@pytest.mark.parametrize("amass", [True, False])
@given(dx=small, dy=small)
@settings(suppress_health_check=[HealthCheck.function_scoped_fixture], max_examples=60)
def test_bresenham_vectorised_equals_reference(amass, dx, dy):
    assert np.array_equal(
        bresenham_line(dx, dy, amass=amass), bresenham_reference(dx, dy, amass=amass)
    )


@given(small, small)
def test_bresenham_visits_the_nearest_lattice_point(dx, dy):
    # analytic: with the counter at half the event count the minor axis stays within
    # half a step of the ideal line at every major step
    steps = bresenham_line(dx, dy)
    big = max(abs(dx), abs(dy))
    pos = positions(steps).astype(np.float64)
    n = np.arange(1, big + 1)
    if big:
        assert np.all(np.abs(pos[:, 0] - n * dx / big) <= 0.5)
        assert np.all(np.abs(pos[:, 1] - n * dy / big) <= 0.5)
    assert len(steps) == big  # one iteration per major-axis step


# ------------------------------------------------------------------- corte recto, Intf8751


def test_corte_recto_golden():
    # Intf8751 §9 R10: (100, 50) visits (50, 50); max deviation 22.36 steps;
    # (100, 100) and (100, 0) have zero deviation
    assert (50, 50) in path(corte_recto_line(100, 50), (0, 0))
    assert corte_recto_max_deviation(100, 50) == pytest.approx(22.36, abs=0.005)
    assert corte_recto_max_deviation(100, 100) == 0.0
    assert corte_recto_max_deviation(100, 0) == 0.0
    # Intf8751 §4.2: "(100, 50) gives 22.4 steps"
    assert round(corte_recto_max_deviation(100, 50), 1) == 22.4


@given(small, small)
def test_corte_recto_deviation_is_the_worst_visited_point(dx, dy):
    # analytic: the formula of Intf8751 §4.2 equals the largest distance of the
    # visited lattice points from the ideal segment
    steps = corte_recto_line(dx, dy)
    assert np.array_equal(steps, corte_recto_reference(dx, dy))
    if dx == dy == 0:
        return
    pos = positions(steps).astype(np.float64)
    dist = np.abs(pos[:, 0] * dy - pos[:, 1] * dx) / math.hypot(dx, dy)
    assert dist.max() == pytest.approx(corte_recto_max_deviation(dx, dy), abs=1e-9)
    m = min(abs(dx), abs(dy))
    assert np.all(np.abs(steps[:m]).sum(axis=1) == 2)  # diagonal first (RUT2)
    assert np.all(np.abs(steps[m:]).sum(axis=1) == 1)  # then the longer axis (GIRA1)


# -------------------------------------------------------------------------- mm → steps


def test_steps_from_mm_seed001_golden():
    # Yanez-07 §4.5 / §10 R8: 10 mm → 5263 and 5 mm → 2632 steps at 1.9 µm/step
    for rounding in ("half_even", "half_up"):
        assert steps_from_mm(10.0, 0.0019, rounding) == 5263
        assert steps_from_mm(5.0, 0.0019, rounding) == 2632
    # Yanez-07 §4.5: truncation would give 2631 (the thesis' values rule it out)
    assert steps_from_mm(5.0, 0.0019, "trunc") == 2631
    # Yanez-07 §4.5: 345.27 µm → 182 steps at 1.9 µm
    assert steps_from_mm(0.34527, 0.0019) == 182


def test_steps_from_mm_rules():
    # analytic: exact decimal quotients are not spoiled by binary floats
    assert steps_from_mm(0.0057, 0.0019, "floor") == 3
    assert steps_from_mm(0.00095, 0.0019, "half_even") == 0  # 0.5 → 0 (banker's, VB6 CLng)
    assert steps_from_mm(0.00285, 0.0019, "half_even") == 2  # 1.5 → 2
    assert steps_from_mm(0.00095, 0.0019, "half_up") == 1
    assert steps_from_mm(-0.00095, 0.0019, "half_up") == -1  # halves away from zero
    assert steps_from_mm(-0.001, 0.0019, "floor") == -1
    assert steps_from_mm(-0.001, 0.0019, "trunc") == 0
    assert steps_from_mm(8.0, 0.04) == 200  # Munoz-22 §8 S004-R08: 8 mm → 200 steps


def _decimal_steps(value: float, step: float, rounding: str) -> int:
    """The rule's definition: the decimal quotient of the shortest reprs, rounded."""
    from decimal import ROUND_FLOOR, ROUND_HALF_EVEN, ROUND_HALF_UP

    q = Decimal(repr(value)) / Decimal(repr(step))
    if rounding == "trunc":
        return int(q)
    mode = {"half_even": ROUND_HALF_EVEN, "half_up": ROUND_HALF_UP, "floor": ROUND_FLOOR}
    return int(q.to_integral_value(rounding=mode[rounding]))


STEP_SIZES = [0.0019, 1 / 250, 1 / 80, 0.001, 0.0125, 0.005, 1 / 3, 0.01, 2.54 / 4000, 0.04]


@given(
    st.sampled_from(STEP_SIZES),
    st.one_of(
        st.floats(-500, 500, allow_nan=False),
        st.integers(-(10**6), 10**6),  # whole steps: every rule's boundary for floor and trunc
        st.tuples(st.integers(-500, 500), st.integers(0, 4)),  # a value written with 0-4 decimals
    ),
    st.sampled_from([1.0, 0.5, 1.5, -0.5]),
    st.sampled_from(["half_even", "half_up", "floor", "trunc"]),
)
def test_steps_from_mm_is_the_decimal_rule_on_and_off_its_boundaries(
    step: float, raw: object, half: float, rounding: str
) -> None:
    """Values on a rule's boundaries (whole and half steps, in binary a hair off) and
    between them round as the decimal quotient of their shortest reprs does."""
    if isinstance(raw, tuple):
        value = round(raw[0] * 0.9731, raw[1])
    elif isinstance(raw, int):  # a whole or half number of steps in decimal (0.0057 mm)
        value = float(Decimal(raw) * Decimal(repr(step)) * Decimal(repr(half)))
    else:
        value = float(raw)
    assert steps_from_mm(value, step, rounding) == _decimal_steps(value, step, rounding)


@pytest.mark.parametrize(
    ("value", "step", "rounding"),
    [(1.0, 0.0, "half_even"), (1.0, -1.0, "half_even"), (math.nan, 0.1, "floor"), (1.0, 0.1, "up")],
)
def test_steps_from_mm_rejects_bad_arguments(value, step, rounding):
    with pytest.raises(UsageError):
        steps_from_mm(value, step, rounding)


# ------------------------------------------------------------------- arcs, UNAM-GMM


@pytest.mark.parametrize(
    ("arc", "radius", "iterations"),
    [
        (staircase_arc, 30, 240),  # UNAM-GMM §4.7 Tabla 7
        (circular_dda_arc, 30, 188),  # UNAM-GMM §4.7 Tabla 7
        (dsm_arc, 30, 168),  # UNAM-GMM §4.7 Tabla 7, §9 S000-14
        (staircase_arc, 5, 40),  # UNAM-GMM §4.7 further reference values
        (circular_dda_arc, 5, 36),
        (dsm_arc, 5, 28),
        (staircase_arc, 10, 80),
        (circular_dda_arc, 10, 64),
        (dsm_arc, 10, 56),
        (staircase_arc, 100, 800),
        (circular_dda_arc, 100, 628),
        (dsm_arc, 100, 564),
    ],
)
def test_full_circle_iteration_counts(arc, radius, iterations):
    steps = arc(0, radius, 0, radius, 0, 0, True)
    assert len(steps) == iterations
    assert path(steps, (0, radius))[-1] == (0, radius)  # analytic: a full circle closes


@pytest.mark.parametrize(
    ("arc", "radius", "max_error"),
    [
        (staircase_arc, 5, 0.88),  # UNAM-GMM §4.7 further reference values (stair/DDA/DSM)
        (circular_dda_arc, 5, 0.83),
        (dsm_arc, 5, 0.39),
        (staircase_arc, 10, 0.95),
        (circular_dda_arc, 10, 0.82),
        (dsm_arc, 10, 0.44),
        (staircase_arc, 30, 0.98),  # UNAM-GMM §4.7 measured at R = 30
        (circular_dda_arc, 30, 0.89),
        (dsm_arc, 30, 0.45),
        (staircase_arc, 100, 1.00),
        (circular_dda_arc, 100, 1.02),
        (dsm_arc, 100, 0.50),
    ],
)
def test_full_circle_radial_errors(arc, radius, max_error):
    # the notes give two decimals; allow 0.006 because the staircase at R = 10 is
    # 0.9446 with the annex rule (D ≤ 0 → X), which the notes print as 0.95
    err = radial_error(arc(0, radius, 0, radius, 0, 0, True), (0, radius), (0, 0))
    assert err == pytest.approx(max_error, abs=0.006)


def test_tabla7_error_bounds_at_r30():
    # UNAM-GMM §4.7 Tabla 7: max theoretical radial error 140 nm = 1 BLU (staircase,
    # DDA) and 70 nm = ½ BLU (DSM); §9 S000-14 "≤ 0.5 BLU"
    for arc, bound in [(staircase_arc, 1.0), (circular_dda_arc, 1.0), (dsm_arc, 0.5)]:
        assert radial_error(arc(0, 30, 0, 30, 0, 0, True), (0, 30), (0, 0)) <= bound


# UNAM-GMM §4.7 "Per-quadrant paths for R = 5, from (0,5) to (5,0), magnitudes"
R5_STAIRCASE = [(0, 5), (1, 5), (1, 4), (2, 4), (3, 4), (4, 4), (4, 3), (5, 3), (5, 2), (5, 1)]
R5_STAIRCASE += [(5, 0)]
R5_DSM = [(0, 5), (1, 5), (2, 5), (3, 4), (4, 3), (5, 2), (5, 1), (5, 0)]
R5_DDA = [(0, 5), (1, 5), (2, 5), (3, 4), (4, 4), (5, 3), (5, 2), (5, 1), (5, 0)]


def dedup(points: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Drop repeated points (iterations without a pulse)."""
    return [p for i, p in enumerate(points) if i == 0 or p != points[i - 1]]


@pytest.mark.parametrize(
    ("arc", "expected"),
    [(staircase_arc, R5_STAIRCASE), (dsm_arc, R5_DSM), (circular_dda_arc, R5_DDA)],
)
def test_r5_quadrant_paths(arc, expected):
    steps = arc(0, 5, 5, 0, 0, 0, True)  # G02 through the first quadrant
    # the circular DDA's first iteration has no pulse (accumulator starts at 0)
    assert dedup(path(steps, (0, 5))) == expected
    # every quadrant of the full circle follows the same magnitude path (§4.7: per quadrant)
    full = path(arc(0, 5, 0, 5, 0, 0, True), (0, 5))
    mags = dedup([(abs(x), abs(y)) for x, y in full])
    assert mags[: len(expected)] == expected
    assert len(mags) == 4 * (len(expected) - 1) + 1


def test_dsm_ties_follow_the_annex():
    # UNAM-GMM §4.5: D1 = D2 tie goes to X, ties with the diagonal go to a single axis.
    # At (0, 5) on R = 5, G02: D1 = |0 + 1| = 1, D2 = |0 − 9| = 9, D3 = |−8| = 8 → X.
    # At (4, 3): D1 = |0 + 9| = 9, D2 = |0 − 5| = 5, D3 = |4| = 4 → diagonal to (5, 2).
    visited = path(dsm_arc(0, 5, 5, 0, 0, 0, True), (0, 5))
    assert visited[1] == (1, 5) and visited[visited.index((4, 3)) + 1] == (5, 2)


@pytest.mark.parametrize("arc", ARCS)
@pytest.mark.parametrize("start", [(0, 7), (7, 0), (0, -7), (-7, 0)])
def test_ccw_is_the_mirror_of_cw(arc, start):
    # analytic: mirroring x maps G02 onto G03; the algorithms work on magnitudes
    cw = arc(start[0], start[1], start[0], start[1], 0, 0, True)
    ccw = arc(-start[0], start[1], -start[0], start[1], 0, 0, False)
    assert np.array_equal(ccw, cw * np.array([-1, 1]))


@pytest.mark.parametrize("arc", ARCS)
def test_quarter_arc_stays_in_its_quadrant(arc):
    # analytic: G02 from (0, R) to (R, 0) about the origin never leaves x ≥ 0, y ≥ 0,
    # and G03 between the same points goes the long way (three quadrants)
    cw = positions(arc(0, 20, 20, 0, 0, 0, True), (0, 20))
    assert cw.min() >= 0
    ccw = positions(arc(0, 20, 20, 0, 0, 0, False), (0, 20))
    assert ccw[:, 0].min() == -20 and ccw[:, 1].min() == -20


coord = st.integers(min_value=-40, max_value=40)


@st.composite
def on_circle_arcs(draw):
    """Start and end lattice points on the same circle about a random centre."""
    cx, cy = draw(coord), draw(coord)
    u0, v0 = draw(coord), draw(coord)
    if u0 == v0 == 0:
        u0 = 1
    r2 = u0 * u0 + v0 * v0
    r = math.isqrt(r2) + 1
    ends = [(a, b) for a in range(-r, r + 1) for b in range(-r, r + 1) if a * a + b * b == r2]
    u1, v1 = draw(st.sampled_from(ends))
    return (cx + u0, cy + v0, cx + u1, cy + v1, cx, cy, draw(st.booleans()))


@given(on_circle_arcs())
@settings(max_examples=300)
def test_dsm_on_circle_end_and_half_step_bound(args):
    # UNAM-GMM §4.7 Tabla 7 (70 nm = ½ BLU) and §9 S000-14: radial error ≤ 0.5 step;
    # analytic: ends exactly at the end point; equal to the literal transcription
    steps = dsm_arc(*args)
    assert_step_array(steps)
    assert path(steps, args[:2])[-1] == args[2:4]
    assert radial_error(steps, args[:2], args[4:6]) <= 0.5
    assert np.array_equal(steps, dsm_arc_reference(*args))


@given(on_circle_arcs())
@settings(max_examples=300)
def test_staircase_on_circle_end_and_one_step_bound(args):
    # UNAM-GMM §4.7 Tabla 7: 140 nm = 1 BLU; §4.4: one axis per iteration
    steps = staircase_arc(*args)
    assert_step_array(steps)
    assert path(steps, args[:2])[-1] == args[2:4]
    assert radial_error(steps, args[:2], args[4:6]) <= 1.0


@pytest.mark.parametrize("arc", ARCS)
@given(args=st.tuples(coord, coord, coord, coord, coord, coord, st.booleans()))
@settings(suppress_health_check=[HealthCheck.function_scoped_fixture], max_examples=150)
def test_arcs_always_end_at_the_end_point(arc, args):
    # analytic: whatever the end point (even off the circle), the arc terminates at it
    x0, y0, _x1, _y1, cx, cy, _cw = args
    if (x0, y0) == (cx, cy):
        with pytest.raises(InputError):
            arc(*args)
        return
    steps = arc(*args)
    assert_step_array(steps)
    assert path(steps, (x0, y0))[-1] == args[2:4]


@pytest.mark.parametrize("arc", ARCS)
def test_full_circle_from_mid_quadrant(arc):
    # analytic: start == end is a full circle; it passes all four axis extremes
    steps = arc(3, 4, 3, 4, 0, 0, False)
    pos = positions(steps, (3, 4))
    assert tuple(pos[-1]) == (3, 4)
    assert pos[:, 0].max() == 5 and pos[:, 0].min() == -5
    assert pos[:, 1].max() == 5 and pos[:, 1].min() == -5


@pytest.mark.parametrize("arc", ARCS)
def test_arc_rejects_bad_input(arc):
    with pytest.raises(InputError):
        arc(2, 2, 5, 5, 2, 2, True)  # start is the centre
    with pytest.raises(UsageError):
        arc(0.5, 2, 5, 5, 0, 0, True)


# --------------------------------------------------------------------------- chord arcs


def test_chord_count():
    # analytic: the returned count meets the tolerance and one fewer does not
    n = chord_count(5.0, math.pi, 0.01)
    assert chord_sagitta(5.0, math.pi / n) <= 0.01 < chord_sagitta(5.0, math.pi / (n - 1))
    with pytest.raises(UsageError):
        chord_count(5.0, math.pi, 0.0)


def test_polyline_steps_joins_lines():
    pts = np.array([[0, 0], [3, 4], [13, 7]])
    steps = polyline_steps(pts)
    assert len(steps) == 6 + 11  # UNAM-GMM §4.2: (3,4) → 6 and (10,3) → 11 iterations
    assert tuple(positions(steps)[-1]) == (13, 7)
    with pytest.raises(UsageError):
        polyline_steps(np.array([[0.0, 0.0], [1.0, 1.0]]))


@given(st.lists(st.tuples(small, small), max_size=12), st.booleans())
def test_bresenham_lines_are_the_lines_one_after_the_other(
    moves: list[tuple[int, int]], amass: bool
) -> None:
    """analytic: many lines at once (an arc's chords) are each line's rows, concatenated,
    and each starts where the lines before it end (zero moves included)."""
    dx = np.array([m[0] for m in moves], dtype=np.int64)
    dy = np.array([m[1] for m in moves], dtype=np.int64)
    rows, first = bresenham_lines(dx, dy, amass=amass)
    each = [bresenham_reference(x, y, amass=amass) for x, y in moves]
    want = np.concatenate(each) if each else np.zeros((0, 2), dtype=np.int8)
    assert rows.dtype == np.int8
    assert np.array_equal(rows, want)
    assert first.tolist() == list(np.cumsum([0] + [len(e) for e in each])[:-1])
