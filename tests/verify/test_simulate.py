"""The step simulation of emitted programs: the thesis figures, end to end.

Expected values come from docs/references.md (the thesis and section is named in each test);
machine profiles are the built-in ones in postprocessors/*.toml ([machine] tables).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from camtool.model.machine import Machine, machine_from_table, merge_tables
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import machine_table
from camtool.verify.circlefit import fit_circle
from camtool.verify.deviations import nominal_arrays, point_distances
from camtool.verify.motion import StepTrace
from camtool.verify.simulate import simulate_steps
from camtool.verify.verifier import verify_program
from tests.shapes import STAR_XY_01MM


def profile(name: str, **override: Any) -> Machine:
    """A built-in machine profile with some keys laid over it (as --machine does)."""
    table, where = machine_table(name)
    return machine_from_table(merge_tables(table, override), where=where)


def block_rows(trace: StepTrace, block: int) -> slice:
    return slice(int(trace.block_start[block]), int(trace.block_start[block + 1]))


def carriage_at_end(trace: StepTrace, block: int) -> np.ndarray:
    """Carriage position after the last row of ``block`` (start if it has none), mm."""
    end = int(trace.block_start[block + 1])
    return trace.carriage_mm[end - 1] if end > 0 else np.asarray(trace.start_mm)


def line_length(trace: StepTrace, block: int) -> float:
    before = carriage_at_end(trace, block - 1) if block > 0 else np.asarray(trace.start_mm)
    return float(np.linalg.norm(carriage_at_end(trace, block) - before))


def iterations(trace: StepTrace, blocks: list[int]) -> int:
    return sum(int((~trace.compensation[block_rows(trace, b)]).sum()) for b in blocks)


GMM = profile("mmh-gmm")
STEP_GMM = 1.0 / GMM.steps_per_mm[0]  # 140 nm


# --------------------------------------------------------------- UNAM-GMM interpolators


def test_dda_line_3_4_takes_six_iterations_through_the_simulator() -> None:
    """UNAM-GMM §4.2 (S000-13): (3, 4) steps -> 6 iterations '- XY Y XY - XY'."""
    program = Program((Linear(3 * STEP_GMM, 4 * STEP_GMM, 0.8),))
    trace = simulate_steps(program, profile("mmh-gmm", backlash={"compensation_um": [0, 0, 0]}))
    names = {(0, 0): "-", (1, 1): "XY", (0, 1): "Y", (1, 0): "X"}
    assert " ".join(names[tuple(r)] for r in trace.rows.tolist()) == "- XY Y XY - XY"


def test_dda_line_10_3_takes_eleven_iterations() -> None:
    """UNAM-GMM §4.2 (S000-13): (10, 3) steps -> 11 iterations."""
    trace = simulate_steps(Program((Linear(10 * STEP_GMM, 3 * STEP_GMM, 0.8),)), GMM)
    assert len(trace.rows) == 11


@pytest.mark.parametrize("emitted", [False, True])
def test_full_circle_r30_takes_168_dsm_iterations(emitted: bool) -> None:
    """UNAM-GMM §4.7 Tabla 7 (S000-14): a full circle of R = 30 steps, DSM: 168 iterations,
    radial error <= 1/2 step; also after pic-mmh writes it as two half arcs and reads it back."""
    r = 30 * STEP_GMM
    program = Program((Rapid(5.0, 3.5), ArcMove(5.0, 3.5, 5.0 - r, 3.5, True, 0.8)))
    arcs = [1]
    if emitted:
        from camtool.post.registry import load_target

        target = load_target("pic-mmh")
        program = target.post.parse(str(target.emit(program).code))
        arcs = [1, 2]
    machine = profile(
        "mmh-gmm", backlash={"true_um": [0, 0, 0], "compensation_um": [0, 0, 0], "regions": []}
    )
    trace = simulate_steps(program, machine)
    assert iterations(trace, arcs) == 168
    rows = slice(int(trace.block_start[arcs[0]]), int(trace.block_start[arcs[-1] + 1]))
    steps = np.rint(trace.carriage_mm[rows] / STEP_GMM)  # back on the step lattice
    centre = (round(5.0 / STEP_GMM) - 30, round(3.5 / STEP_GMM))
    radial = np.hypot(*(steps - centre).T) - 30
    assert np.max(np.abs(radial)) <= 0.5


# ----------------------------------------------------------------- backlash, UNAM-GMM §5


@pytest.mark.parametrize(("y_mm", "expected_um"), [(1.0, 190.0), (3.5, 201.0), (6.0, 187.0)])
def test_u_pattern_recovers_the_true_x_backlash_of_each_region(
    y_mm: float, expected_um: float
) -> None:
    """UNAM-GMM §5.2 Tabla 13: two 2.5 mm X lines joined by a step; without compensation
    their length difference is the true backlash of the region (H1/H2/H3: 190/201/187 µm)."""
    machine = profile("mmh-gmm", backlash={"compensation_um": [0, 0, 0]})
    program = Program(
        (
            Rapid(1.0, y_mm),
            Linear(3.5, y_mm, 0.8),
            Linear(3.5, y_mm + 0.3, 0.8),
            Linear(1.0, y_mm + 0.3, 0.8),
        )
    )
    trace = simulate_steps(program, machine)
    difference_um = (line_length(trace, 1) - line_length(trace, 3)) * 1000.0
    assert difference_um == pytest.approx(expected_um, abs=STEP_GMM * 1000)


@pytest.mark.parametrize(("x_mm", "expected_um"), [(1.0, 152.0), (5.0, 180.0), (8.0, 173.0)])
def test_u_pattern_recovers_the_true_y_backlash_of_each_region(
    x_mm: float, expected_um: float
) -> None:
    """UNAM-GMM §5.2 Tabla 13: 1.2 mm Y lines in V1/V2/V3 -> 152/180/173 µm."""
    machine = profile("mmh-gmm", backlash={"compensation_um": [0, 0, 0]})
    program = Program(
        (
            Rapid(x_mm, 1.0),
            Linear(x_mm, 2.2, 0.8),
            Linear(x_mm + 0.3, 2.2, 0.8),
            Linear(x_mm + 0.3, 1.0, 0.8),
        )
    )
    trace = simulate_steps(program, machine)
    difference_um = (line_length(trace, 1) - line_length(trace, 3)) * 1000.0
    assert difference_um == pytest.approx(expected_um, abs=STEP_GMM * 1000)


def square(x0: float, y0: float, side: float, feed: float = 0.8) -> Program:
    """A counter-clockwise square from its lower-left corner."""
    return Program(
        (
            Rapid(x0, y0),
            Linear(x0 + side, y0, feed),
            Linear(x0 + side, y0 + side, feed),
            Linear(x0, y0 + side, feed),
            Linear(x0, y0, feed),
        )
    )


def test_square_with_the_first_compensation_is_off_by_the_residual() -> None:
    """UNAM-GMM §5.2 Tabla 14: true 204/178 µm, compensation 192.5/168.5 µm: the 2.5 mm
    square comes out 11.5/9.5 µm off (its closure gap), and the X distance between its
    two Y edges is 2.5 - 0.0115 = 2.4885 mm (Cuadrado_X measured Dx = 2.489 mm)."""
    machine = profile(
        "mmh-gmm",
        backlash={"true_um": [204, 178, 0], "compensation_um": [192.5, 168.5, 0], "regions": []},
    )
    v = verify_program(square(2.0, 2.0, 2.5), machine)
    (contour,) = v.contours
    assert contour.closure_um == pytest.approx((11.5, 9.5), abs=STEP_GMM * 1000)
    trace = v.trace
    right_edge_x = carriage_at_end(trace, 2)[0]
    left_edge_x = carriage_at_end(trace, 4)[0]
    assert right_edge_x - left_edge_x == pytest.approx(2.4885, abs=STEP_GMM)
    assert trace.reversals == (1, 1)
    assert trace.compensations == 2


def test_exact_compensation_closes_the_square() -> None:
    """Compensation equal to the true backlash (UNAM-GMM §5.2, final 204/178 µm): no gap."""
    machine = profile(
        "mmh-gmm",
        backlash={"true_um": [204, 178, 0], "compensation_um": [204, 178, 0], "regions": []},
    )
    v = verify_program(square(2.0, 2.0, 2.5), machine)
    assert v.contours[0].closure_um == pytest.approx((0.0, 0.0), abs=STEP_GMM * 1000)
    assert v.deviation.max_um < 1.0


def test_many_compensations_on_a_sub_millimetre_part_are_warned() -> None:
    """UNAM-GMM §5.3, S000-19: parts under 1 mm fail after about 16 compensations."""
    moves: list[Linear | Rapid] = [Rapid(1.0, 1.0)]
    for i in range(20):  # a zigzag: every stroke reverses X
        x = 1.5 if i % 2 == 0 else 1.0
        moves += [Linear(x, 1.0 + 0.02 * i, 0.8), Linear(x, 1.0 + 0.02 * (i + 1), 0.8)]
    v = verify_program(Program(tuple(moves)), GMM)
    assert v.trace.compensations > 16
    assert any("compensations on a part of" in w for w in v.warnings)


# ---------------------------------------------------------------- Yanez-07, the LMM MMH


LMM = profile("mmh-lmm")


def test_lines_are_rounded_at_the_applications_1_9_um() -> None:
    """Yanez-07 §4.5, R8: 10 mm -> 5263 steps, 5 mm -> 2632 steps."""
    machine = profile("mmh-lmm", motion={"line": "bresenham"})
    trace = simulate_steps(Program((Linear(10.0, 5.0, 10.0),)), machine)
    assert tuple(trace.block_steps[0, :2]) == (5263, 2632)


def test_a_10_mm_line_measures_5263_real_steps_of_1_88_um() -> None:
    """Yanez-07 R14: 10 mm commanded -> 5263 x 1.88 µm = 9.894 mm (measured 9.897, L1568)."""
    trace = simulate_steps(Program((Linear(10.0, 0.0, 10.0),)), LMM)
    assert line_length(trace, 0) == pytest.approx(5263 * 0.00188, abs=1e-9)


@pytest.mark.parametrize(("period_ms", "y_steps"), [(20, 2763), (30, 2719), (40, 2697)])
def test_timer_stepping_overshoots_the_minor_axis(period_ms: int, y_steps: int) -> None:
    """Yanez-07 §4.7 Table 3.8 (R11): a 10 x 5 mm line makes 5263 X and 2763 / 2719 / 2697
    Y motor steps at P = 20 / 30 / 40 ms (programmed: 2632)."""
    machine = profile("mmh-lmm", timing={"model": "flashcut", "half_period_ms": period_ms})
    trace = simulate_steps(Program((Linear(10.0, 5.0, 10.0),)), machine)
    assert tuple(np.abs(trace.rows.sum(axis=0, dtype=np.int64))) == (5263, y_steps)


def test_uncompensated_rectangle_fails_to_close_by_the_backlash() -> None:
    """Yanez-07 §5, R13: a 10 x 5 mm rectangle without compensation leaves a gap equal to the
    true backlash, 0.654 / 0.302 mm (the thesis measured 0.675 / 0.321)."""
    machine = profile("mmh-lmm", backlash={"compensation_um": [0, 0, 0]})
    program = Program(
        (
            Linear(10.0, 0.0, 10.0),
            Linear(10.0, 5.0, 10.0),
            Linear(0.0, 5.0, 10.0),
            Linear(0.0, 0.0, 10.0),
        )
    )
    v = verify_program(program, machine)
    assert v.contours[0].closure_um == pytest.approx((654.0, 302.0), abs=1.88)


def test_timer_model_time_of_the_10_mm_square() -> None:
    """Yanez-07 §4.7, R15: the 10 x 10 mm square at P = 3 ms took 2:53 = 173 s (within 5 %)."""
    machine = profile("mmh-lmm", timing={"model": "flashcut", "half_period_ms": 3})
    program = Program(square(1.0, 1.0, 10.0, feed=10.0).moves[1:], origin=(1.0, 1.0))
    v = verify_program(program, machine)
    assert v.trace.compensations == 2  # 348 + 161 steps, as the thesis's time fit assumes
    assert v.time_s == pytest.approx(173.0, rel=0.05)


# ------------------------------------------------------------- Intf8751, Munoz-22, GRBL


def test_corte_recto_deviation_of_a_100_by_50_move() -> None:
    """Intf8751 §4.2 (R10): (100, 50) steps goes through (50, 50); max deviation
    b(a-b)/sqrt(a^2+b^2) = 22.36 steps."""
    machine = Machine(
        name="8751 test",
        steps_per_mm=(100.0, 100.0, 100.0),
        work_area_mm=(0.0, 0.0, 100.0, 100.0),
        # a profile of its own: another target's chord rule is named qualified
        motion=profile("valcnc", motion={"line": "corte-recto", "chords": "valcnc:valcnc"}).motion,
    )
    v = verify_program(Program((Linear(1.0, 0.5, 100.0),)), machine)
    assert v.deviation.max_um == pytest.approx(50 * 50 / math.hypot(100, 50) * 10.0, abs=1e-6)
    assert v.deviation.at_mm == pytest.approx((0.5, 0.5))


def test_valcnc_line_time() -> None:
    """Munoz-22 §4.3: 166.667 µs per step; 10 mm at 25 steps/mm -> 250 steps -> 41.7 ms."""
    v = verify_program(Program((Linear(10.0, 0.0, 100.0),)), profile("valcnc"))
    assert tuple(v.trace.block_steps[0]) == (250, 0, 0)
    assert v.time_s == pytest.approx(0.0417, abs=5e-5)


def test_grbl_circle_stays_within_arc_tolerance_plus_a_step() -> None:
    """GRBL 1.1 mc_arc with $12 = 0.002 mm, Bresenham at 250 steps/mm: the trace stays within
    the chord sagitta plus one step of the circle."""
    machine = profile("grbl")
    program = Program((Rapid(15.0, 10.0), ArcMove(15.0, 10.0, 10.0, 10.0, False, 500.0)))
    v = verify_program(program, machine)
    assert v.deviation.max_um <= 2.0 + 1000.0 * math.sqrt(2) / 250.0
    (contour,) = v.contours
    assert contour.circle is not None
    assert contour.circle[1] == pytest.approx(10.0, abs=0.004)


# ------------------------------------------------------------------------- metrics


def test_point_distances_lines_and_arcs() -> None:
    """Analytic: distance to a segment and to an arc (radial inside the sweep)."""
    program = Program((Linear(10.0, 0.0, 1.0), ArcMove(0.0, 10.0, 0.0, 0.0, False, 1.0)))
    nominal = nominal_arrays(program)
    points = np.array([[5.0, 1.0], [12.0, 0.0], [8.0, 6.0], [-3.0, -4.0]])
    blocks = np.array([0, 0, 1, 1])
    got = point_distances(points, blocks, nominal)
    # (8, 6) is 10 from the centre: on the arc; (-3, -4) is outside the quarter arc,
    # nearest end (10, 0) or (0, 10): sqrt(13^2 + 4^2)
    assert got == pytest.approx([1.0, 2.0, 0.0, min(math.hypot(13, 4), math.hypot(3, 14))])


def test_fit_circle_recovers_centre_and_radius() -> None:
    angles = np.linspace(0.0, math.tau, 50, endpoint=False)
    pts = np.column_stack([3 + 2 * np.cos(angles), -1 + 2 * np.sin(angles)])
    assert fit_circle(pts) == pytest.approx((3.0, -1.0, 2.0))


# ------------------------------------------------------------ Angel-11, the servo router

STAR_01MM = list(zip(*STAR_XY_01MM, strict=True))  # Angel-11 §3: (x, y) per point, 0.1 mm


def test_star_on_the_router_closes_off_by_the_chunk_flooring() -> None:
    """Angel-11 §8 R14: with the floor(d/2) chunk rule the star ends (+0.4, -0.2) mm from its
    first point (it was drawn ending at (+0.2, 0)); its cruise time is ~79 s (R14e) plus ten
    150 ms handshakes and the speed loops' lag."""
    moves = [Rapid(STAR_01MM[0][0] / 10, STAR_01MM[0][1] / 10)]
    moves += [Linear(x / 10, y / 10, 225.0) for x, y in STAR_01MM[1:]]
    v = verify_program(Program(tuple(moves)), profile("router-2011"))
    trace = v.trace
    end = trace.carriage_mm[-1] - np.asarray(STAR_01MM[0]) / 10
    assert end == pytest.approx((0.4, -0.2), abs=1e-6)
    cutting = v.block_time_s[1:].sum()
    assert 78.83 + 1.5 <= cutting <= 78.83 + 1.5 + 1.0
    assert len(v.contours) == 1 and v.contours[0].closure_um is None  # drawn open


@pytest.mark.parametrize("name", ["mmh-gmm", "mmh-lmm", "i8751", "valcnc", "grbl", "linuxcnc"])
def test_every_built_in_profile_verifies_a_square_and_a_circle(name: str) -> None:
    """Every step profile loads and measures: the 2 mm square closes within its compensation
    residual, the circle's fitted diameter is within a few steps of 2 mm, time is positive."""
    machine = profile(name)
    x, y = 3.0, 3.0
    program = Program(
        (
            *square(x, y, 2.0, feed=50.0).moves,
            Rapid(x + 5.0, y + 1.0),
            ArcMove(x + 3.0, y + 1.0, x + 4.0, y + 1.0, True, 50.0),  # two halves, as posted
            ArcMove(x + 5.0, y + 1.0, x + 4.0, y + 1.0, True, 50.0),
        )
    )
    v = verify_program(program, machine)
    step_mm = 1.0 / min(machine.real_steps_per_mm[:2])
    true = machine.backlash.true_um
    residual_um = max(
        abs(c - t) for c, t in zip(machine.backlash.compensation_um, true, strict=True)
    )
    square_m, circle_m = v.contours
    assert square_m.closure_um is not None
    assert math.hypot(*square_m.closure_um) <= residual_um * 1.5 + 3000 * step_mm + 20
    assert circle_m.circle is not None
    assert circle_m.circle[1] == pytest.approx(2.0, abs=4 * step_mm + residual_um / 500)
    assert v.time_s > 0


def test_valcnc_does_not_move_on_a_full_circle_in_one_block() -> None:
    """Munoz-22 §4.2: alpha = 2 asin(C / 2R) is 0 when start == end, so nothing moves (the
    valcnc dialect must split full circles, S004-R05); the verifier shows it."""
    program = Program((Rapid(5.0, 4.0), ArcMove(5.0, 4.0, 4.0, 4.0, True, 100.0)))
    v = verify_program(program, profile("valcnc"))
    assert v.trace.block_steps[1].tolist() == [0, 0, 0]
    assert v.contours[0].size_error_um == pytest.approx((-2000.0, -2000.0))
