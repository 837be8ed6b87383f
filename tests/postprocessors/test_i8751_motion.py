"""Tests of the Intf8751 i8751 ramp timing model (camtool_postprocessors.i8751.motion).

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import UsageError
from camtool_postprocessors.i8751.motion import (
    I8751Timing,
    i8751_block_time_s,
    i8751_cruise_x,
    i8751_delay_s,
    i8751_move_time_s,
    i8751_step_delays_s,
)
from tests.kinematics import assert_seconds, blocks


def test_model_calls_its_function():
    # the timing model's dataclass runs its block-time function (the
    # other models: tests/verify/test_timing.py::test_models_call_their_functions)
    model, direct = (
        I8751Timing(wait_t1_s=1),
        lambda b: i8751_block_time_s(b.dominant_steps, b.steps[:, 2], wait_t1_s=1),
    )
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


@pytest.mark.parametrize(
    ("x", "ms", "digits"), [(0xF2, 125.0, 1), (0xED, 122.4, 1), (0x11, 9.58, 2)]
)
def test_i8751_delay_formula(x, ms, digits):
    # Intf8751 R12: t(F2H) = 125.0 ms, t(EDH) = 122.4 ms, t(11H) = 9.58 ms
    assert round(float(i8751_delay_s(x)) * 1000, digits) == ms


def test_i8751_firmware_ramp():
    # Intf8751 §4.4: 45 acceleration steps, X −= 5 from F2H (2.565 ms less per step),
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
    # Intf8751 §4.4: fewer than 90 steps run entirely at F2H (8 Hz)
    assert i8751_step_delays_s(89) == pytest.approx(np.full(89, 0.125002))
    assert float(i8751_step_delays_s(90).max()) == pytest.approx(0.125002)
    assert len(i8751_step_delays_s(0)) == 0


def test_i8751_design_cruise_is_70_hz():
    # Intf8751 §4.4 design intent: 8 Hz → 70 Hz (14.28 ms), 2.46 ms less per step
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
    # Intf8751 R11: X/Y, then T1 s, then Z, then T2 s; Z is its own ramped routine
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
