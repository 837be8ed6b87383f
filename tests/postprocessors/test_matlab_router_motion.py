"""Tests of the Angel-11 DC-servo router model (camtool_postprocessors.matlab_router.motion*).

Every expected value names its source: a section/table of reference/Angel-11.md, or
"analytic" when it follows from the model's own equations.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camtool.model.errors import UsageError
from camtool_postprocessors.matlab_router.arrays import router_arrays
from camtool_postprocessors.matlab_router.plant import (
    TABLE_4_1,
    THESIS_PLANT,
    FirmwareIP,
    Plant,
    closed_loop_step,
    design_ip,
    digital_gains,
    open_loop_step,
    per_axis_plants,
    plant_from_gains,
)
from camtool_postprocessors.matlab_router.servo import (
    RouterMachine,
    ServoTrace,
    apply_backlash,
    backlash_effect_mm,
    chunk_closure_mm,
    chunked_increments,
    closure_mm,
    segment_deviation_mm,
    simulate_job,
    tracking_deviation_mm,
)
from tests.shapes import STAR_XY_01MM

STAR = np.array(STAR_XY_01MM).T  # Angel-11 §3, L3196–L3200, (N, 2) in 0.1 mm
CPM = 25_600  # counts per mm on X/Y (Angel-11 §2.2, R8)


def settling(w: np.ndarray, ref: float, band: float = 0.02) -> tuple[float, float]:
    """(overshoot %, 2 % settling time in s) of a speed response sampled every 5 ms."""
    outside = np.nonzero(np.abs(w - ref) > band * ref)[0]
    return (w.max() - ref) / ref * 100.0, (outside[-1] + 1) * 0.005


# -- R8 constants --------------------------------------------------------------------------


def test_r8_counts_follow_from_the_mechanics() -> None:
    # Angel-11 §2.2: 1024 counts/rev × 75 (gear) / 3 mm (lead) = 25 600 counts/mm; a
    # 0.2 mm chunk is the firmware's RefP = 5120 (L5601); one GUI unit (0.1 mm) is 2560.
    m = RouterMachine()
    assert m.counts_per_mm == 1024 * 75 // 3
    assert m.chunk_counts == round(0.2 * m.counts_per_mm)
    assert m.counts_per_01mm == 2560


def test_default_decel_table_meets_the_cruise_speed() -> None:
    # Analytic (eq. 4.14 with the default β = 480²/2000): Tabla[1000] = 480, so the
    # reference enters the table without a jump; Tabla is increasing and 0 at q = 0.
    m = RouterMachine()
    assert m.tabla(m.decel_start_counts) == m.cruise_speed
    assert m.tabla(0) == 0 and m.tabla(1) >= 1
    assert all(m.tabla(q) <= m.tabla(q + 1) for q in range(1000))


@pytest.mark.parametrize(
    "kwargs",
    [{"chunking": "exact"}, {"stop": "brake"}, {"qei": "x4"}, {"decel": "none"},
     {"controller": "pid"}, {"start_skew_s": 0.005}, {"decel_beta": 0.1},
     {"qei_start_angle": (0, 1024)}, {"counts_per_mm": 25_601}],
)  # fmt: skip
def test_machine_rejects_bad_options(kwargs: dict[str, object]) -> None:
    with pytest.raises(UsageError):
        RouterMachine(**kwargs)  # type: ignore[arg-type]


def test_unknown_choice_lists_the_valid_ones() -> None:
    with pytest.raises(UsageError, match="valid: faithful, fixed"):
        RouterMachine(chunking="exact")  # type: ignore[arg-type]


# -- R11 gain design ---------------------------------------------------------------------


def test_design_ip_natural_frequency() -> None:
    # Angel-11 §5.2 and R11: xi = 0.707, ts = 0.25 s -> wn = 22.63 rad/s.
    g = design_ip(9.715, 0.067, 0.25, 0.707, 0.005)
    assert g.wn == pytest.approx(22.63, abs=0.005)


@pytest.mark.parametrize("row", TABLE_4_1, ids=["X", "Y", "Z"])
def test_table_4_1_analog_gains_give_its_digital_columns(row) -> None:  # type: ignore[no-untyped-def]
    # Angel-11 Table 4.1 and R11: Kid = Ki·T, Kpd = Kp − Kid/2 reproduce the printed columns.
    kid, kpd = digital_gains(row.ki, row.kp, 0.005)
    assert abs(kid - row.kid) <= 1e-4
    assert abs(kpd - row.kpd) <= 1e-4


@pytest.mark.parametrize(
    ("row", "a", "tau"),
    [(TABLE_4_1[0], 8.90, 0.0610), (TABLE_4_1[1], 5.60, 0.0615), (TABLE_4_1[2], 9.77, 0.0620)],
    ids=["X", "Y", "Z"],
)
def test_back_solved_plants(row, a: float, tau: float) -> None:  # type: ignore[no-untyped-def]
    # Angel-11 §5.2 (D) table of back-solved per-axis plants (printed to 3 significant digits).
    got_a, got_tau = plant_from_gains(row.ki, row.kp)
    assert got_a == pytest.approx(a, abs=0.005)
    assert got_tau == pytest.approx(tau, abs=0.0001)


@given(st.floats(1.0, 20.0), st.floats(0.02, 0.2), st.floats(0.1, 1.0), st.floats(0.5, 1.0))
def test_plant_from_gains_inverts_design_ip(a: float, tau: float, ts: float, xi: float) -> None:
    # Analytic: eqs. 4.39–4.40 and their inverse are a round trip.
    g = design_ip(a, tau, ts, xi)
    if g.kp <= 0:  # a plant faster than the spec needs Kp < 0: no first-order inverse
        return
    back_a, back_tau = plant_from_gains(g.ki, g.kp, settling_s=ts, xi=xi)
    assert back_a == pytest.approx(a, rel=1e-9)
    assert back_tau == pytest.approx(tau, rel=1e-9)


def test_design_ip_rejects_non_positive() -> None:
    with pytest.raises(UsageError):
        design_ip(9.7, 0.067, 0.0, 0.707)


# -- R9 plant, R10 speed loop ---------------------------------------------------------------


def test_thesis_pole_is_the_zoh_pole_of_alpha_14_88() -> None:
    # Angel-11 §5.1: G_p(s) = 145/(s + 14.88) and G_p(z) = 0.6986/(z − 0.9283) at Ts = 5 ms.
    assert Plant.from_analog(9.715, 1 / 14.88).pole == pytest.approx(THESIS_PLANT.pole, abs=1e-4)


def test_open_loop_u70_step() -> None:
    # Angel-11 §5.1 and R9: u = 70 reaches 680 counts/Ts (±1 %) with 63.2 % at ≈ 67 ms (τ).
    w = open_loop_step(THESIS_PLANT, 70, 200)
    assert w[-1] == pytest.approx(680, rel=0.01)
    t63 = float(np.interp(0.632 * w[-1], w, np.arange(len(w)))) * 0.005
    assert t63 == pytest.approx(0.067, abs=0.0025)
    assert not w.flags.writeable


@pytest.mark.parametrize(
    ("plant", "gains"),
    [(THESIS_PLANT, design_ip(9.715, 0.067, 0.25, 0.707)), (per_axis_plants()[0], TABLE_4_1[0])],
    ids=["thesis-plant+designed-gains", "X-plant+Table-4.1-X"],
)
def test_ideal_closed_loop_to_682(plant: Plant, gains) -> None:  # type: ignore[no-untyped-def]
    # R10 / Angel-11 §5.2–5.3: designed for ts = 250 ms (2 %) and < 5 % overshoot (xi = 0.707).
    # 4/(xi·wn) is the envelope estimate; the sampled 2 % band is left at 260 ms, so ±30 ms.
    w = closed_loop_step(plant, 682, 400, law="ideal", gains=gains)
    overshoot, ts = settling(w, 682)
    assert 0 < overshoot < 5
    assert ts == pytest.approx(0.25, abs=0.03)


@pytest.mark.parametrize(("axis", "t98_ms"), [(0, 105), (1, 135)], ids=["X", "Y"])
def test_firmware_law_on_back_solved_plants(axis: int, t98_ms: float) -> None:
    # Angel-11 §5.2 (D) rough simulation: firmware law (28/159), ref 480, time to 98 %
    # speed X ≈ 105 ms, Y ≈ 135 ms (one 5 ms sample of tolerance each way, plus one).
    w = closed_loop_step(per_axis_plants()[axis], 480, 400)
    t98 = (np.argmax(w >= 0.98 * 480)) * 5
    assert abs(t98 - t98_ms) <= 10
    assert w[-100:].mean() == pytest.approx(480, abs=1.0)


def test_firmware_law_integer_arithmetic() -> None:
    # Angel-11 §4.5 (C), L5538–L5582, by hand: tick 1 from rest, Ref = -480:
    # INTE = 480·28 = 13440, u = (0 + 13440 − 0)/1000 = 13 -> -13 (sign of Ref).
    ctrl = FirmwareIP()
    assert ctrl.step(-480, 0, 0.0) == -13
    # tick 2, velAc = 9: INTE = 13440 + 471·28 = 26628; u = (-13 + 26628 − 1431)/1000 = 25.
    assert ctrl.step(-480, 9, -9.0) == -25
    # Ref = 0 switches the drive off (X listing L5574) but INTE keeps integrating.
    assert ctrl.step(0, 30, -30.0) == 0
    assert ctrl.inte == 26628 - 30 * 28
    # C division truncates towards zero and negative u is clamped to 0.
    ctrl.inte = -5000
    assert ctrl.step(100, 0, 0.0) == 0


def test_ideal_law_needs_gains() -> None:
    with pytest.raises(UsageError, match="gains"):
        closed_loop_step(THESIS_PLANT, 100, 10, law="ideal")
    with pytest.raises(UsageError, match="valid: firmware, ideal"):
        closed_loop_step(THESIS_PLANT, 100, 10, law="pid")  # type: ignore[arg-type]


# -- R12/R14 chunk arithmetic and the full simulation ---------------------------------------


def test_star_closure_by_chunk_arithmetic() -> None:
    # Angel-11 §4.2 (D)1 and R14 test: floor(d/2) chunks give (+0.4, −0.2) mm.
    assert chunk_closure_mm(STAR).tolist() == pytest.approx([0.4, -0.2], abs=1e-12)


def test_fixed_chunking_executes_what_was_written() -> None:
    # Analytic: exact d·2560 counts per axis; the star's written net is (+0.2, 0) mm (§3).
    m = RouterMachine(chunking="fixed")
    assert chunk_closure_mm(STAR, m).tolist() == pytest.approx([0.2, 0.0], abs=1e-12)


@settings(max_examples=50)
@given(st.lists(st.tuples(st.integers(0, 2000), st.integers(0, 2000)), min_size=2, max_size=8))
def test_chunk_rule_loses_under_0_2_mm_per_axis_and_segment(points: list) -> None:  # type: ignore[type-arg]
    # Analytic (R12): floor(d/2)·0.2 mm is within [d·0.1 − 0.1, d·0.1] mm, same sign.
    arrays = router_arrays(points)
    # an axis that moves at a speed rounded to 0 never ends its move (the job hangs, Angel-11
    # §4.2): the writer cuts such a segment into pieces, so it is not the chunk rule's case
    assume(not np.any((arrays.lxy != 0) & (arrays.velxy == 0)))
    inc = chunked_increments(arrays, RouterMachine())
    written = arrays.increments.T * 2560
    assert np.all(np.abs(inc) <= np.abs(written))
    assert np.all(np.abs(written) - np.abs(inc) <= 2560)


@pytest.fixture(scope="module")
def star_trace():  # type: ignore[no-untyped-def]
    return simulate_job(STAR, RouterMachine())


def test_star_closure_from_the_servo_simulation(star_trace) -> None:  # type: ignore[no-untyped-def]
    # R14 test through the full simulation: with stop="count" each axis stops at the integer
    # count the firmware waits for, so only float rounding separates it from (+0.4, −0.2) mm.
    assert closure_mm(star_trace).tolist() == pytest.approx([0.4, -0.2], abs=1e-9)
    first = star_trace.first_point_mm
    inc = chunked_increments(router_arrays(STAR), RouterMachine())
    expected = first + np.cumsum(inc, axis=0) / CPM
    np.testing.assert_allclose(star_trace.executed_end_mm, expected, atol=1e-9)
    np.testing.assert_allclose(star_trace.commanded_end_mm, STAR[1:] / 10)


def test_star_cruise_and_job_time(star_trace) -> None:  # type: ignore[no-untyped-def]
    # R14e: Σ max(|Δx|,|Δy|) = 2956 units -> 2956·2560/480·5 ms = 78.83 s ("≈ 79 s").
    assert star_trace.cruise_time_s == pytest.approx(2956 * 2560 / 480 * 0.005)
    assert star_trace.cruise_time_s == pytest.approx(78.8, abs=0.05)
    # Simulated: cruise + 10 × 150 ms handshakes + per segment the speed loop's lag
    # (≈ 2ξ/ωn ≈ 50 ms) less the chunk-rule savings: between 0 and 100 ms per segment.
    extra = star_trace.time_s - star_trace.cruise_time_s - 10 * 0.150
    assert 0.0 < extra < 10 * 0.100


def test_star_simulates_one_row_per_sample() -> None:
    # work done, not wall time: the job is simulated once, one
    # position row per 5 ms sample of its simulated time (plus the first point)
    trace = simulate_job(STAR, RouterMachine(stop="coast", qei="firmware"))
    assert len(trace.positions_mm) == round(trace.time_s / trace.ts_s) + 1


def test_trace_layout(star_trace) -> None:  # type: ignore[no-untyped-def]
    tr = star_trace
    m = len(tr.positions_mm)
    assert tr.positions_mm.shape == (m, 2) and tr.positions_mm.dtype == np.float64
    assert tr.positions_mm[0].tolist() == [15.1, 8.6]
    assert tr.time_s == pytest.approx((m - 1) * 0.005)
    for arr in (tr.positions_mm, tr.segment_end_sample, tr.executed_end_mm, tr.speeds):
        assert not arr.flags.writeable
    assert tr.segment_start_sample.shape == tr.segment_end_sample.shape == (10,)
    assert np.all(tr.segment_start_sample[1:] - tr.segment_end_sample[:-1] == 30)  # 150 ms
    assert np.all(tr.axis_done_sample.max(axis=1) == tr.segment_end_sample)
    assert tr.warnings == ()


@pytest.mark.parametrize("controller", ["firmware", "ideal"])
def test_closure_is_the_chunk_rule_for_both_laws(controller: str) -> None:
    m = RouterMachine(controller=controller, plants=per_axis_plants())  # type: ignore[arg-type]
    assert closure_mm(simulate_job(STAR, m)).tolist() == pytest.approx([0.4, -0.2], abs=1e-9)


# -- R14b deviation from the line -----------------------------------------------------------


def test_segment_1_tracking_deviation_per_axis_vs_identical_plants() -> None:
    # Angel-11 §5.2 (D) rough simulation, star segment 1 (X 480, Y 345), no start skew:
    # ≈ 0.03 mm with the back-solved per-axis plants, ≈ 0.0003 mm with identical plants.
    # This model: 0.0318 mm and 0.00026 mm.
    x, y, z = per_axis_plants()
    per_axis = simulate_job(STAR, RouterMachine(plants=(x, y, z), start_skew_s=0.0))
    same = simulate_job(STAR, RouterMachine(plants=(x, x, z), start_skew_s=0.0))
    d_per_axis = tracking_deviation_mm(per_axis)[0]
    d_same = tracking_deviation_mm(same)[0]
    assert 0.02 < d_per_axis < 0.045
    assert 0.0001 < d_same < 0.001


def test_start_skew_adds_its_analytic_offset() -> None:
    # Analytic (R13): Y δ = 0.4 ms late offsets the path by |vx·vy|/|v|·δ/Ts counts
    # = 480·345/591.1·0.08 = 22.4 counts = 0.00088 mm off the line of segment 1.
    base = tracking_deviation_mm(simulate_job(STAR, RouterMachine(start_skew_s=0.0)))[0]
    skew = tracking_deviation_mm(simulate_job(STAR, RouterMachine(start_skew_s=0.0004)))[0]
    expected = 480 * 345 / math.hypot(480, 345) * 0.08 / CPM
    assert skew - base == pytest.approx(expected, abs=0.0003)


def test_segment_deviation_of_a_known_path() -> None:
    # Analytic: a path (0,0) -> (5,1) -> (10,0) is 1 mm off its chord at most; the same
    # samples measured along speeds (1, 0) before the first axis is done give 1 mm too.
    pos = np.array([[0.0, 0.0], [5.0, 1.0], [10.0, 0.0], [10.0, 0.0]])
    trace = ServoTrace(
        positions_mm=pos,
        segment_start_sample=np.array([0]),
        segment_end_sample=np.array([2]),
        axis_done_sample=np.array([[3, 3]]),
        commanded_end_mm=np.array([[10.0, 0.0]]),
        executed_end_mm=np.array([[10.0, 0.0]]),
        speeds=np.array([[480, 0]]),
        first_point_mm=np.array([0.0, 0.0]),
        time_s=0.015,
        cruise_time_s=0.0,
        ts_s=0.005,
    )
    assert segment_deviation_mm(trace).tolist() == pytest.approx([1.0])
    assert tracking_deviation_mm(trace).tolist() == pytest.approx([1.0])


def test_carried_integrator_makes_a_slow_axis_lurch() -> None:
    # Angel-11 §4.5 (C): INTE is never reset. Star segment 3 (X at −77) after segment 2
    # (X at +480) starts with X's integrator wound up: u = 100 % for a few samples, and the
    # path is offset ≈ 0.14 mm; the same segment as the first of a job is off < 0.001 mm.
    m = RouterMachine(start_skew_s=0.0)
    after = tracking_deviation_mm(simulate_job(STAR[:4], m))[2]
    alone = tracking_deviation_mm(simulate_job(STAR[2:4], m))[0]
    assert after > 0.1
    assert alone < 0.001


# -- model switches -------------------------------------------------------------------------


def test_coast_overrun_is_the_plant_geometric_series() -> None:
    # Analytic (R9 with u = 0): after the count the drive is off, so an axis moving w_done
    # counts/Ts coasts w_done·p·(1 − p^N)/(1 − p) counts in the N samples to the next start.
    tr = simulate_job([(0, 0), (100, 0), (100, 100)], RouterMachine(stop="coast"))
    done, nxt = int(tr.axis_done_sample[0, 0]), int(tr.segment_start_sample[1])
    x = tr.positions_mm[:, 0] * CPM
    w_done, p = x[done] - x[done - 1], THESIS_PLANT.pole
    coast = w_done * p * (1 - p ** (nxt - done)) / (1 - p)
    assert x[nxt] - x[done] == pytest.approx(coast, rel=1e-9)
    assert x[done] - x[0] >= 50 * 5120  # the count was reached
    assert coast / CPM > 0.15  # Angel-11 §4.2 (D)5: coasting is not compensated


def test_qei_bookkeeping_loses_the_start_angle_on_reversal() -> None:
    # Angel-11 §4.2 (D)3–4 with the listing's loops (L5625–L5711), analytic:
    # Posi = conv + 1023·k exits a `<= 5120` chunk at counter advance S = 5126 and the
    # final `< 5120` loop at S = 5125. +X 1.0 mm from angle 0: 5126 + 3·5120 + (5125 − 6)
    # = 25605 counts, ending at angle 5. −X 1.0 mm: Posi starts at 1023 − 5 = 1018, so it
    # travels 25605 − 1018 = 24587; net +1018 counts (0.04 mm lost on the reversal).
    tr = simulate_job([(0, 0), (10, 0), (0, 0)], RouterMachine(qei="firmware"))
    ends = (tr.executed_end_mm - tr.first_point_mm) * CPM
    assert ends[:, 0].tolist() == pytest.approx([25605, 1018], abs=1e-6)


def test_listing_decel_speeds_up_a_slow_axis() -> None:
    # Angel-11 L5703: Ref = Tabla[q] whatever the segment speed; star segment 3 moves X at
    # -77 counts/Ts, and the table (up to 480) drives it faster over its last 1000 counts.
    def last_x_speeds(decel: str) -> np.ndarray:
        tr = simulate_job(STAR[:4], RouterMachine(decel=decel))  # type: ignore[arg-type]
        done = int(tr.axis_done_sample[2, 0])
        return np.abs(np.diff(tr.positions_mm[done - 6 : done, 0])) * CPM

    assert last_x_speeds("listing").max() > 120
    assert last_x_speeds("capped").max() < 80


def test_underflow_and_zero_speed_are_warned() -> None:
    # Angel-11 §4.2 (D)2: d = 1 underflows factor − 1 (runaway); a minor speed that rounds
    # to 0 (480·2/2000 = 0.48) leaves Ref = 0 and the move never ends.
    tr = simulate_job([(0, 0), (1, 100), (2001, 102)])
    assert len(tr.warnings) == 2
    assert "segment 1, axis X" in tr.warnings[0] and "underflow" in tr.warnings[0]
    assert "segment 2, axis Y" in tr.warnings[1] and "speed 0" in tr.warnings[1]
    fixed = simulate_job([(0, 0), (1, 100)], RouterMachine(chunking="fixed"))
    assert fixed.warnings == ()
    assert fixed.executed_end_mm[0].tolist() == pytest.approx([0.1, 10.0], abs=1e-9)


# -- R15 backlash -----------------------------------------------------------------------------


def test_play_operator_by_hand() -> None:
    # Analytic: band 0.2, motor 0 -> 1 -> 0.5 -> 1 -> 0.9: the table follows +, waits
    # for the band after each reversal.
    motor = np.array([[0, 0], [1, 0], [0.5, 0], [1, 0], [0.9, 0]])
    table = apply_backlash(motor, (0.2, 0.0))
    assert table[:, 0].tolist() == pytest.approx([0, 1, 0.7, 1, 1])
    assert not table.flags.writeable


def test_backlash_effect_on_star_closure(star_trace) -> None:  # type: ignore[no-untyped-def]
    # Analytic: the band starts taken up in + (approach +X, +Y, §2.8); the star's last
    # segment moves −X and −Y (velxy −94, −480), so the table ends one band short in +.
    assert backlash_effect_mm(star_trace, (0.05, 0.03)).tolist() == pytest.approx([0.05, 0.03])
    assert closure_mm(star_trace, backlash_mm=(0.05, 0.03)).tolist() == pytest.approx([0.45, -0.17])


def test_backlash_has_no_effect_when_the_job_ends_moving_plus() -> None:
    tr = simulate_job([(0, 0), (100, 0), (0, 0), (100, 100)])
    assert backlash_effect_mm(tr, (0.05, 0.03)).tolist() == pytest.approx([0.0, 0.0], abs=1e-12)


def test_negative_backlash_is_rejected(star_trace) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(UsageError):
        closure_mm(star_trace, backlash_mm=(-0.01, 0.0))


def test_each_strokes_measures_start_where_the_positioning_left_the_carriage() -> None:
    """Two squares 30 mm apart: the second's closure and size are its own, not the gap.

    The router moves to each job's first point X then Y (Angel-11 R13); that point,
    not the end of the stroke before, is where the second contour starts.
    """
    from camtool.model.program import Linear, Program, Rapid
    from camtool.post.registry import load_machine
    from camtool.verify.verifier import verify_program

    def square(x: float) -> list[Rapid | Linear]:
        corners = [(x + 10, 10.0), (x + 10, 20.0), (x, 20.0), (x, 10.0)]
        return [Rapid(x, 10.0), *(Linear(cx, cy, 225.0) for cx, cy in corners)]

    v = verify_program(Program((*square(10.0), *square(40.0))), load_machine("router-2011"))
    assert len(v.contours) == 2
    for contour in v.contours:
        assert contour.closure_um is not None
        assert max(abs(c) for c in contour.closure_um) <= 800.0  # 4 sides, ≤ 0.2 mm floor each
        assert max(abs(e) for e in contour.size_error_um) <= 400.0
