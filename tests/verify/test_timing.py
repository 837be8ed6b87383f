"""Tests of the machining-time models against the thesis notes and analytic facts.

Every expected value names its source: a section/requirement of
../shared/reference/seed-00N.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import InputError, UsageError
from camtool.verify.interpolators import accumulator_dda_line, dda_iterations, steps_from_mm
from camtool.verify.timing import (
    BlockKinematics,
    FlashcutTiming,
    I8751Timing,
    PicMmhTiming,
    TrapezoidTiming,
    ValcncTiming,
    flashcut_block_time_s,
    grbl_block_time_s,
    grbl_junction_speed_mm_s,
    i8751_block_time_s,
    i8751_cruise_x,
    i8751_delay_s,
    i8751_move_time_s,
    i8751_step_delays_s,
    pic_mmh_block_time_s,
    pic_mmh_step_rate_hz,
    serial_time_s,
    timer_period_ms,
    timing_model_from_table,
    trapezoid_time_s,
    valcnc_block_time_s,
)

FALSE = np.array([False])
TRUE = np.array([True])


def assert_seconds(t: np.ndarray, b: int) -> None:
    assert t.dtype == np.float64 and t.shape == (b,)
    assert not t.flags.writeable


# ------------------------------------------------------------------ pic-mmh, seed-000

MMH_STEP_MM = 140e-6  # seed-000 S000-12: 140 nm/step


def test_pic_mmh_f08_is_95_hz():
    # seed-000 §4.9: F08 = 0.8 mm/min at 140 nm/step → f = 7142.857·0.8/60 = 95.2 Hz
    rate = pic_mmh_step_rate_hz([0.8], FALSE)
    assert_seconds(rate, 1)
    assert round(float(rate[0]), 1) == 95.2


@pytest.mark.parametrize(("feed_word", "capped"), [(13, False), (14, True), (99, True)])
def test_pic_mmh_cap_at_166_hz(feed_word, capped):
    # seed-000 S000-05: with F in 0.1 mm/min units only F <= 13 stays under 166 Hz
    rate = float(pic_mmh_step_rate_hz([feed_word * 0.1], FALSE)[0])
    assert (rate == 166.0) is capped
    assert rate <= 166.0


def test_pic_mmh_x_backlash_take_up_is_8_8_s():
    # seed-000 §5.1 / S000-17: X 204 µm ≈ 1457 steps, one take-up at 166 Hz ≈ 8.8 s;
    # a rapid runs at the cap, and so does a feed move whose F exceeds it
    take_up = steps_from_mm(0.204, MMH_STEP_MM)
    assert take_up == 1457
    t = pic_mmh_block_time_s([0, 0], [take_up, take_up], [0.0, 9.9], [True, False])
    assert_seconds(t, 2)
    assert t == pytest.approx([8.8, 8.8], abs=0.05)


def test_pic_mmh_compensation_runs_at_the_block_rate():
    # seed-000 §5.1 ("at the current step rate"): at F08 (95.2 Hz) the same take-up
    # lasts 1457/95.238 s, and DDA iterations of (3, 4) (6 of them, §4.2) add 6 periods
    it = dda_iterations(3, 4)
    t = pic_mmh_block_time_s([it], [1457], [0.8], FALSE)
    assert float(t[0]) == pytest.approx((it + 1457) * 60 / (0.8 / MMH_STEP_MM), rel=1e-12)


def test_pic_mmh_feed_move_without_feed_is_refused():
    # analytic: f = 0 would take forever; rapids and empty blocks need no feed
    with pytest.raises(UsageError, match="block 1"):
        pic_mmh_block_time_s([0, 5], [0, 0], [0.0, 0.0], [False, False])
    assert pic_mmh_block_time_s([0, 5], [0, 0], [0.0, 0.0], [False, True])[0] == 0.0


# ----------------------------------------------------------------- flashcut, seed-001

LMM_STEP_MM = 0.0019  # seed-001 §4.5: the software converts with 1.9 µm/step
BACKLASH = (348, 161)  # seed-001 §5: measured X/Y backlash, steps


def rectangle_blocks(w_mm: float, h_mm: float) -> tuple[list[int], list[int]]:
    """Edges +X, +Y, −X, −Y: the −X edge reverses X, the −Y edge reverses Y."""
    nx, ny = steps_from_mm(w_mm, LMM_STEP_MM), steps_from_mm(h_mm, LMM_STEP_MM)
    return [nx, ny, nx, ny], [0, 0, BACKLASH[0], BACKLASH[1]]


@pytest.mark.parametrize(
    ("w", "h", "total_steps", "measured_s"),
    [
        (10, 10, 21052, 173),  # seed-001 §6.1 Table 4.1: square 2:53
        (10, 5, 15790, 130),  # Table 4.1: rectangle 10×5 2:10
        (3, 10, 13684, 113),  # Table 4.1: rectangle 3×10 1:53
    ],
)
def test_flashcut_table_4_1_times_at_3_ms(w, h, total_steps, measured_s):
    # seed-001 R15: within 5 % of Table 4.1 at P = 3 ms, backlash steps included
    dom, comp = rectangle_blocks(w, h)
    assert sum(dom) == total_steps  # §4.7 step counts
    t = flashcut_block_time_s(dom, comp, [False] * 4, half_period_ms=3)
    assert_seconds(t, 4)
    assert float(t.sum()) == pytest.approx(measured_s, rel=0.05)
    assert float(t.sum()) == pytest.approx((total_steps + 509) * 0.008)  # §4.7: 8 ms per step


@pytest.mark.parametrize(("p_ms", "measured_s"), [(20, 658), (40, 1300)])
def test_flashcut_circle_times(p_ms, measured_s):
    # seed-001 §4.7 / §6.2 Table 4.2: Ø10 circle, Σ max(|dx|,|dy|) = 8·r·sin 45° = 14886
    # steps plus 2 × 509 backlash steps; 10:58 at P = 20 ms and 21:40 at P = 40 ms (R15: 5 %)
    dominant = steps_from_mm(8 * 5.0 * math.sin(math.pi / 4), LMM_STEP_MM)
    assert dominant == 14886
    quadrants = [dominant // 4] * 3 + [dominant - 3 * (dominant // 4)]
    comp = [BACKLASH[0], BACKLASH[1], BACKLASH[0], BACKLASH[1]]  # one reversal per quadrant
    t = flashcut_block_time_s(quadrants, comp, [False] * 4, half_period_ms=p_ms)
    assert float(t.sum()) == pytest.approx(measured_s, rel=0.05)


def test_flashcut_half_period_per_block_diagonal_rectangle():
    # seed-001 §6.2 / §4.7: 10×5 edges at P = 3 ms and both diagonals at P = 40 ms come
    # to ≈ 989 s before an unknown repositioning move; measured 16:56 = 1016 s
    dom, _ = rectangle_blocks(10, 5)
    diag = steps_from_mm(10, LMM_STEP_MM)
    t = flashcut_block_time_s(
        [*dom, diag, diag], [0] * 6, [False] * 6, half_period_ms=[3, 3, 3, 3, 40, 40]
    )
    assert float(t.sum()) == pytest.approx(989, abs=1)
    assert float(t.sum()) < 1016


def test_flashcut_rapids_run_at_the_minimum_half_period():
    # seed-001 R3 + R21: G00 at the maximum rate = half-period 3 ms, whatever P is
    t = flashcut_block_time_s([1000, 1000], [0, 0], [True, False], half_period_ms=40)
    assert t == pytest.approx([1000 * 2 * (3 + 1) / 1000, 1000 * 2 * (40 + 1) / 1000])


def test_flashcut_half_period_below_3_ms_is_refused():
    # seed-001 R21: half-period >= 3 ms
    with pytest.raises(UsageError, match="half_period_ms"):
        flashcut_block_time_s([1], [0], FALSE, half_period_ms=2)
    with pytest.raises(UsageError):
        FlashcutTiming(half_period_ms=2.5)


@settings(max_examples=40, deadline=None)
@given(st.integers(min_value=3, max_value=200), st.integers(min_value=0, max_value=10_000))
def test_flashcut_delta_is_the_timer_firing_rule(p_ms, n):
    # seed-001 §4.7: for whole-ms P, P + δ (δ = 1 ms) is the floor(P) + 1 firing period
    t = flashcut_block_time_s([n], [0], FALSE, half_period_ms=p_ms)
    assert float(t[0]) == pytest.approx(n * 2 * timer_period_ms(p_ms) / 1000, rel=1e-12)


# ------------------------------------------------------------------- i8751, seed-003


@pytest.mark.parametrize(
    ("x", "ms", "digits"), [(0xF2, 125.0, 1), (0xED, 122.4, 1), (0x11, 9.58, 2)]
)
def test_i8751_delay_formula(x, ms, digits):
    # seed-003 R12: t(F2H) = 125.0 ms, t(EDH) = 122.4 ms, t(11H) = 9.58 ms
    assert round(float(i8751_delay_s(x)) * 1000, digits) == ms


def test_i8751_firmware_ramp():
    # seed-003 §4.4: 45 acceleration steps, X −= 5 from F2H (2.565 ms less per step),
    # ≈ 3.09 s in all; cruise at X = 11H ≈ 104 Hz; then 45 deceleration steps
    d = i8751_step_delays_s(100)
    assert_seconds(d, 100)
    accel, cruise, decel = d[:45], d[45:55], d[55:]
    assert round(float(accel.sum()), 2) == 3.09
    assert np.diff(accel) == pytest.approx(np.full(44, -5 * 6156 / 12e6))
    assert float(accel[0]) == float(i8751_delay_s(0xF2))
    assert 1 / cruise == pytest.approx(np.full(10, 104.4), abs=0.1)
    assert np.diff(decel) == pytest.approx(np.full(44, 5 * 6156 / 12e6))
    assert float(decel[0]) == float(i8751_delay_s(0x11))  # "X inicia con un valor de 11H"
    assert np.all(decel >= cruise[-1]) and np.all(accel <= accel[0])


def test_i8751_short_moves_run_at_minimum_speed():
    # seed-003 §4.4: fewer than 90 steps run entirely at F2H (8 Hz)
    assert i8751_step_delays_s(89) == pytest.approx(np.full(89, 0.125002))
    assert float(i8751_step_delays_s(90).max()) == pytest.approx(0.125002)
    assert len(i8751_step_delays_s(0)) == 0


def test_i8751_design_cruise_is_70_hz():
    # seed-003 §4.4 design intent: 8 Hz → 70 Hz (14.28 ms), 2.46 ms less per step
    assert 1 / float(i8751_delay_s(i8751_cruise_x("design"))) == pytest.approx(70.0)
    d = i8751_step_delays_s(200, cruise="design")
    assert round(float(d[100]) * 1000, 2) == 14.29
    assert np.diff(d[:45]) == pytest.approx(np.full(44, -2.46e-3), abs=5e-6)


@settings(max_examples=40, deadline=None)
@given(st.integers(min_value=0, max_value=400), st.sampled_from(["firmware", "design"]))
def test_i8751_closed_form_equals_step_sum(n, cruise):
    # analytic: the closed-form move time is the sum of the per-step delays
    t = i8751_move_time_s([n], cruise=cruise)
    assert float(t[0]) == pytest.approx(float(i8751_step_delays_s(n, cruise=cruise).sum()))


def test_i8751_block_sequence_xy_wait_z_wait():
    # seed-003 R11: X/Y, then T1 s, then Z, then T2 s; Z is its own ramped routine
    xy, z = 120, 30
    t = i8751_block_time_s([xy, 0], [z, -z], wait_t1_s=2, wait_t2_s=[0, 1])
    assert_seconds(t, 2)
    expected_xy = float(i8751_step_delays_s(xy).sum())
    assert float(t[0]) == pytest.approx(expected_xy + 2 + z * 0.125002)
    assert float(t[1]) == pytest.approx(2 + z * 0.125002 + 1)


def test_i8751_unknown_cruise_is_refused():
    with pytest.raises(UsageError, match="firmware, design"):
        i8751_step_delays_s(10, cruise="fast")  # type: ignore[arg-type]
    with pytest.raises(UsageError):
        I8751Timing(cruise="fast")  # type: ignore[arg-type]


# ------------------------------------------------------------------- valcnc, seed-004


def test_valcnc_ten_mm_is_41_7_ms():
    # seed-004 S004-R13: 10 mm at 25 steps/mm = 250 steps = 41.7 ms, and the 10×10
    # diagonal (250 accumulator-DDA iterations) takes the same time
    n = steps_from_mm(10.0, 0.04)
    iterations = [len(accumulator_dda_line(n, 0)), len(accumulator_dda_line(n, n))]
    t = valcnc_block_time_s(iterations)
    assert_seconds(t, 2)
    assert t == pytest.approx([0.0417, 0.0417], abs=5e-5)


def test_valcnc_serial_time_at_9600_baud():
    # seed-004 S004-R13: ≈ 1.04 ms per byte at 9600 baud; a 27-byte block ≈ 28 ms
    assert float(serial_time_s([1], baud=9600)[0]) == pytest.approx(1.04e-3, abs=5e-6)
    t = valcnc_block_time_s([25], block_bytes=[27], serial_baud=9600)
    assert float(t[0]) == pytest.approx(27 * 10 / 9600 + 25 * 166.667e-6)
    assert float(valcnc_block_time_s([25], block_bytes=[27])[0]) == pytest.approx(25 * 166.667e-6)


# ------------------------------------------------------------- grbl / linuxcnc, analytic


def test_trapezoid_case():
    # analytic: 10 mm at 5 mm/s, 10 mm/s²: 1.25 mm up, 7.5 mm cruise, 1.25 mm down
    t = trapezoid_time_s([10.0], [5.0], 10.0)
    assert_seconds(t, 1)
    assert float(t[0]) == pytest.approx(0.5 + 1.5 + 0.5)


def test_triangle_case():
    # analytic: 1 mm, nominal 10 mm/s never reached at 10 mm/s²: t = 2·√(L/a)
    assert float(trapezoid_time_s([1.0], [10.0], 10.0)[0]) == pytest.approx(2 * math.sqrt(0.1))


def test_trapezoid_meets_triangle_at_the_boundary():
    # analytic: at L = v²/a both branches give 2v/a
    v, a = 6.0, 4.0
    lengths = [v * v / a * (1 - 1e-9), v * v / a, v * v / a * (1 + 1e-9)]
    assert trapezoid_time_s(lengths, [v] * 3, a) == pytest.approx([2 * v / a] * 3)


def test_entry_and_exit_speeds():
    # analytic: entering and leaving at cruise speed is pure cruise; from 2 to 4 mm/s
    # at 1 mm/s² over 6 mm (exactly the acceleration distance) takes 2 s
    assert float(trapezoid_time_s([3.0], [5.0], 1.0, entry_mm_s=5, exit_mm_s=5)[0]) == 0.6
    t = trapezoid_time_s([6.0], [4.0], 1.0, entry_mm_s=2.0, exit_mm_s=4.0)
    assert float(t[0]) == pytest.approx(2.0)
    with pytest.raises(UsageError, match="cannot go"):
        trapezoid_time_s([1.0], [4.0], 1.0, entry_mm_s=0.0, exit_mm_s=4.0)


def test_grbl_feed_cap_and_rapids():
    # GRBL: feed capped at $110, G00 at $110 whatever F; 10 mm at 8.333 mm/s, 10 mm/s²
    t = grbl_block_time_s([10, 10, 10], [600, 6000, 0], [False, False, True])
    v = 500 / 60
    assert t == pytest.approx([10 / v + v / 10] * 3)
    with pytest.raises(UsageError, match="speed 0"):
        grbl_block_time_s([1.0], [0.0], FALSE)


@settings(max_examples=60, deadline=None)
@given(
    st.floats(min_value=0.001, max_value=500),
    st.floats(min_value=0.01, max_value=200),
    st.floats(min_value=0.1, max_value=5000),
    st.floats(min_value=0.0, max_value=1.0),
)
def test_trapezoid_properties(length, v, a, split):
    # analytic: never faster than cruising the whole way, never slower than a stop-start
    # triangle bound; stopping halfway never saves time; blending at a junction helps
    t = float(trapezoid_time_s([length], [v], a)[0])
    assert t >= length / v * (1 - 1e-12)
    assert t <= length / v + v / a + 1e-9
    parts = trapezoid_time_s([length * split, length * (1 - split)], [v, v], a)
    assert float(parts.sum()) >= t * (1 - 1e-9)
    vj = min(v, math.sqrt(a * length))  # reachable from rest within the block
    blended = float(trapezoid_time_s([length], [v], a, entry_mm_s=vj, exit_mm_s=0.0)[0])
    assert blended <= t * (1 + 1e-9)


def test_grbl_junction_speed():
    # GRBL planner.c: v² = a·δ·s/(1 − s), s = cos(turn/2); straight on is unlimited,
    # a 90° corner gives √(a·δ·(√2/2)/(1 − √2/2)) = √(2.414·a·δ), a reversal stops
    v = grbl_junction_speed_mm_s([0.0, math.pi / 2, math.pi], acceleration_mm_s2=100)
    assert math.isinf(v[0]) and v[2] == 0.0
    assert float(v[1]) == pytest.approx(math.sqrt((1 + math.sqrt(2)) * 100 * 0.010))


# ----------------------------------------------------------------- models and profiles


def blocks() -> BlockKinematics:
    return BlockKinematics.build(
        dominant_steps=[100, 2000, 0],
        is_rapid=[False, True, False],
        feed_mm_min=[0.8, 0.0, 0.0],
        length_mm=[0.5, 3.0, 0.0],
        iterations=[120, 2000, 0],
        steps=[[100, -40, 0], [-2000, 300, 0], [0, 0, -250]],
        compensation_steps=[1457, 0, 0],
    )


def test_flashcut_z_block_counts_its_z_steps():
    # seed-001 §4.3: a Z-only block (funcionZH) steps Z at the same period; 250 steps
    # at P = 20 ms take 250·2·21 ms
    t = FlashcutTiming(half_period_ms=20).block_time_s(blocks())
    assert float(t[2]) == pytest.approx(250 * 2 * 21 / 1000)


def test_block_kinematics_validates_and_freezes():
    b = blocks()
    assert len(b) == 3 and b.steps.shape == (3, 3) and not b.steps.flags.writeable
    two = BlockKinematics.build(
        dominant_steps=[3], is_rapid=[0], feed_mm_min=[1], length_mm=[1], steps=[[3, -1]]
    )
    assert two.steps.tolist() == [[3, -1, 0]]
    assert not b.iterations.flags.writeable
    with pytest.raises(UsageError, match="differ in length"):
        BlockKinematics.build(dominant_steps=[1, 2], is_rapid=[0], feed_mm_min=[1], length_mm=[1])
    with pytest.raises(UsageError, match="block 1"):
        BlockKinematics.build(
            dominant_steps=[1, -2], is_rapid=[0, 0], feed_mm_min=[1, 1], length_mm=[1, 1]
        )
    with pytest.raises(UsageError, match="whole numbers"):
        BlockKinematics.build(dominant_steps=[1.5], is_rapid=[0], feed_mm_min=[1], length_mm=[1])


@pytest.mark.parametrize(
    ("model", "direct"),
    [
        (PicMmhTiming(), lambda b: pic_mmh_block_time_s(b.iterations, b.compensation_steps,
                                                        b.feed_mm_min, b.is_rapid)),
        (FlashcutTiming(half_period_ms=20), lambda b: flashcut_block_time_s(
            np.maximum(b.dominant_steps, np.abs(b.steps[:, 2])), b.compensation_steps,
            b.is_rapid, half_period_ms=20)),
        (I8751Timing(wait_t1_s=1), lambda b: i8751_block_time_s(
            b.dominant_steps, b.steps[:, 2], wait_t1_s=1)),
        (ValcncTiming(), lambda b: valcnc_block_time_s(b.iterations)),
        (TrapezoidTiming(), lambda b: grbl_block_time_s(b.length_mm, b.feed_mm_min, b.is_rapid)),
    ],
)  # fmt: skip
def test_models_call_their_functions(model, direct):
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


def test_timing_model_from_table():
    m = timing_model_from_table({"model": "flashcut", "half_period_ms": 20}, where="t.toml")
    assert m == FlashcutTiming(half_period_ms=20)
    assert timing_model_from_table({"model": "linuxcnc"}, where="t") == TrapezoidTiming()
    assert timing_model_from_table({"model": "i8751", "cruise": "design"}, where="t").model == (
        "i8751"
    )
    bad = [
        ({"model": "fanuc"}, "unknown timing model 'fanuc'; valid: pic-mmh"),
        ({"model": "valcnc", "feed": 1}, "unknown valcnc timing key"),
        ({"model": "flashcut", "half_period_ms": 2}, "half_period_ms"),
        ({"model": "grbl", "max_rate_mm_min": "fast"}, "must be a number"),
        ({"model": "i8751", "cruise": "warp"}, "valid: firmware, design"),
    ]
    for table, message in bad:
        with pytest.raises(InputError, match=message) as err:
            timing_model_from_table(table, where="t.toml [timing]")
        assert "t.toml [timing]" in str(err.value)
