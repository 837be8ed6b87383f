"""Tests of the Yanez-07 flashcut motion model: timing, timer stepping, chords
(camtool_postprocessors.flashcut.motion).

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import UsageError
from camtool.verify.quantize import steps_from_mm
from camtool_postprocessors.flashcut.motion import (
    FlashcutTiming,
    flashcut_arc_points,
    flashcut_block_time_s,
    flashcut_line_steps,
    timer_period_ms,
)
from tests.kinematics import FALSE, assert_seconds, blocks


def test_model_calls_its_function():
    # the timing model's dataclass runs its block-time function (the
    # other models: tests/verify/test_timing.py::test_models_call_their_functions)
    model, direct = (
        FlashcutTiming(half_period_ms=20),
        lambda b: flashcut_block_time_s(
            np.maximum(b.dominant_steps, np.abs(b.steps[:, 2])),
            b.compensation_steps,
            b.is_rapid,
            half_period_ms=20,
        ),
    )
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


LMM_STEP_MM = 0.0019  # Yanez-07 §4.5: the software converts with 1.9 µm/step
BACKLASH = (348, 161)  # Yanez-07 §5: measured X/Y backlash, steps


def rectangle_blocks(w_mm: float, h_mm: float) -> tuple[list[int], list[int]]:
    """Edges +X, +Y, −X, −Y: the −X edge reverses X, the −Y edge reverses Y."""
    nx, ny = steps_from_mm(w_mm, LMM_STEP_MM), steps_from_mm(h_mm, LMM_STEP_MM)
    return [nx, ny, nx, ny], [0, 0, BACKLASH[0], BACKLASH[1]]


@pytest.mark.parametrize(
    ("w", "h", "total_steps", "measured_s"),
    [
        (10, 10, 21052, 173),  # Yanez-07 §6.1 Table 4.1: square 2:53
        (10, 5, 15790, 130),  # Table 4.1: rectangle 10×5 2:10
        (3, 10, 13684, 113),  # Table 4.1: rectangle 3×10 1:53
    ],
)
def test_flashcut_table_4_1_times_at_3_ms(w, h, total_steps, measured_s):
    # Yanez-07 R15: within 5 % of Table 4.1 at P = 3 ms, backlash steps included
    dom, comp = rectangle_blocks(w, h)
    assert sum(dom) == total_steps  # §4.7 step counts
    t = flashcut_block_time_s(dom, comp, [False] * 4, half_period_ms=3)
    assert_seconds(t, 4)
    assert float(t.sum()) == pytest.approx(measured_s, rel=0.05)
    assert float(t.sum()) == pytest.approx((total_steps + 509) * 0.008)  # §4.7: 8 ms per step


@pytest.mark.parametrize(("p_ms", "measured_s"), [(20, 658), (40, 1300)])
def test_flashcut_circle_times(p_ms, measured_s):
    # Yanez-07 §4.7 / §6.2 Table 4.2: Ø10 circle, Σ max(|dx|,|dy|) = 8·r·sin 45° = 14886
    # steps plus 2 × 509 backlash steps; 10:58 at P = 20 ms and 21:40 at P = 40 ms (R15: 5 %)
    dominant = steps_from_mm(8 * 5.0 * math.sin(math.pi / 4), LMM_STEP_MM)
    assert dominant == 14886
    quadrants = [dominant // 4] * 3 + [dominant - 3 * (dominant // 4)]
    comp = [BACKLASH[0], BACKLASH[1], BACKLASH[0], BACKLASH[1]]  # one reversal per quadrant
    t = flashcut_block_time_s(quadrants, comp, [False] * 4, half_period_ms=p_ms)
    assert float(t.sum()) == pytest.approx(measured_s, rel=0.05)


def test_flashcut_half_period_per_block_diagonal_rectangle():
    # Yanez-07 §6.2 / §4.7: 10×5 edges at P = 3 ms and both diagonals at P = 40 ms come
    # to ≈ 989 s before an unknown repositioning move; measured 16:56 = 1016 s
    dom, _ = rectangle_blocks(10, 5)
    diag = steps_from_mm(10, LMM_STEP_MM)
    t = flashcut_block_time_s(
        [*dom, diag, diag], [0] * 6, [False] * 6, half_period_ms=[3, 3, 3, 3, 40, 40]
    )
    assert float(t.sum()) == pytest.approx(989, abs=1)
    assert float(t.sum()) < 1016


def test_flashcut_rapids_run_at_the_minimum_half_period():
    # Yanez-07 R3 + R21: G00 at the maximum rate = half-period 3 ms, whatever P is
    t = flashcut_block_time_s([1000, 1000], [0, 0], [True, False], half_period_ms=40)
    assert t == pytest.approx([1000 * 2 * (3 + 1) / 1000, 1000 * 2 * (40 + 1) / 1000])


def test_flashcut_half_period_below_3_ms_is_refused():
    # Yanez-07 R21: half-period >= 3 ms
    with pytest.raises(UsageError, match="half_period_ms"):
        flashcut_block_time_s([1], [0], FALSE, half_period_ms=2)
    with pytest.raises(UsageError):
        FlashcutTiming(half_period_ms=2.5)


@settings(max_examples=40, deadline=None)
@given(st.integers(min_value=3, max_value=200), st.integers(min_value=0, max_value=10_000))
def test_flashcut_delta_is_the_timer_firing_rule(p_ms, n):
    # Yanez-07 §4.7: for whole-ms P, P + δ (δ = 1 ms) is the floor(P) + 1 firing period
    t = flashcut_block_time_s([n], [0], FALSE, half_period_ms=p_ms)
    assert float(t[0]) == pytest.approx(n * 2 * timer_period_ms(p_ms) / 1000, rel=1e-12)


def test_flashcut_z_block_counts_its_z_steps():
    # Yanez-07 §4.3: a Z-only block (funcionZH) steps Z at the same period; 250 steps
    # at P = 20 ms take 250·2·21 ms
    t = FlashcutTiming(half_period_ms=20).block_time_s(blocks())
    assert float(t[2]) == pytest.approx(250 * 2 * 21 / 1000)


# ------------------------------------------------------------------ chords, timer model


def test_flashcut_arc_points_r2_examples():
    # Yanez-07 §10 R2: G01 X1.0 Y1.0 then G02 X3.0 Y3.0 I1.0 J1.0 → centre (2, 2),
    # r = √2, CW sweep −180°, passing through (2 − √2, 2)
    # (45° of sweep from the start at −135°, i.e. the first of four chords)
    pts = flashcut_arc_points((1.0, 1.0), (3.0, 3.0), (2.0, 2.0), True, segments=4)
    assert pts[0] == pytest.approx((2 - math.sqrt(2), 2.0))
    assert pts[-1] == pytest.approx((3.0, 3.0))
    # Yanez-07 §10 R2: G01 X2.0 Y1.0 then G03 X0.0 Y3.0 I-1.0 J1.0 → centre (1, 2),
    # CCW +180°, passing through (1 + √2, 2)
    pts = flashcut_arc_points((2.0, 1.0), (0.0, 3.0), (1.0, 2.0), False, segments=4)
    assert pts[0] == pytest.approx((1 + math.sqrt(2), 2.0))


def test_flashcut_full_circle_assumption():
    # Yanez-07 §4.4 (reconstructed routine): start == end is taken as a full circle
    pts = flashcut_arc_points((1.0, 0.0), (1.0, 0.0), (0.0, 0.0), True, segments=4)
    assert pts == pytest.approx(np.array([[0, -1], [-1, 0], [0, 1], [1, 0]]), abs=1e-12)
    with pytest.raises(UsageError):
        flashcut_arc_points((1.0, 0.0), (1.0, 0.0), (0.0, 0.0), True, segments=0)


@pytest.mark.parametrize(("period", "y_steps"), [(20, 2763), (30, 2719), (40, 2697)])
def test_flashcut_timer_model_table_3_8(period, y_steps):
    # Yanez-07 §4.7 Table 3.8 / §10 R11: 10 × 5 mm line, theoretical 5263 × 2632 steps
    assert flashcut_line_steps(5263, 2632, period) == y_steps


def test_flashcut_timer_model_rules():
    # Yanez-07 §4.7: "X differs by 1 ms" — dominant half-period P becomes P + 1
    assert timer_period_ms(3) == 4
    assert timer_period_ms(39.99) == 40  # non-dominant 2P − ε fires at 2P
    assert flashcut_line_steps(5263, 5263, 20) == 5263  # analytic: equal counts, same period
    assert flashcut_line_steps(5263, 0, 20) == 0
    with pytest.raises(UsageError):
        flashcut_line_steps(10, 11, 20)
