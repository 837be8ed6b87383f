"""Tests of the generic machining-time library and of timing-model lookup by name.

Each target's own timing model is tested in tests/postprocessors/test_<name>_motion.py.

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import InputError, UsageError
from camtool.post.registry import load_machine
from camtool.verify.motion import timing_model_from_table
from camtool.verify.timing import (
    BlockKinematics,
    TrapezoidTiming,
    trapezoid_block_time_s,
    trapezoid_time_s,
)
from camtool_postprocessors.flashcut.motion import FlashcutTiming
from tests.kinematics import FALSE, assert_seconds, blocks

# ------------------------------------------------------------- rest-to-rest trapezoid, analytic


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
    t = trapezoid_block_time_s([10, 10, 10], [600, 6000, 0], [False, False, True])
    v = 500 / 60
    assert t == pytest.approx([10 / v + v / 10] * 3)
    with pytest.raises(UsageError, match="speed 0"):
        trapezoid_block_time_s([1.0], [0.0], FALSE)


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


# ----------------------------------------------------------------- models and profiles


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
        (TrapezoidTiming(), lambda b: trapezoid_block_time_s(b.length_mm, b.feed_mm_min,
                                                             b.is_rapid)),
    ],
)  # fmt: skip
def test_models_call_their_functions(model, direct):
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


def test_timing_model_from_table():
    """A profile names its own target's models; another target's are named qualified."""
    lmm = load_machine("mmh-lmm")  # the flashcut target's profile
    m = timing_model_from_table({"model": "flashcut", "half_period_ms": 20}, where="t", machine=lmm)
    assert m == FlashcutTiming(half_period_ms=20)
    m = timing_model_from_table({"model": "flashcut:flashcut", "half_period_ms": 20}, where="t")
    assert m == FlashcutTiming(half_period_ms=20)
    assert timing_model_from_table({"model": "linuxcnc:linuxcnc"}, where="t") == TrapezoidTiming()
    i8751 = timing_model_from_table({"model": "i8751:i8751", "cruise": "design"}, where="t")
    assert i8751.model == "i8751"
    with pytest.raises(InputError, match="unknown timing model 'valcnc'; valid: trapezoid, grbl"):
        timing_model_from_table({"model": "valcnc"}, where="t", machine=load_machine("grbl"))
    bad = [
        ({"model": "fanuc"}, "unknown timing model 'fanuc'; valid: trapezoid .*<target>:<name>"),
        ({"model": "flashcut"}, "unknown timing model 'flashcut'"),
        ({"model": "nosuch:flashcut"}, "unknown timing model 'nosuch:flashcut'"),
        ({"model": "valcnc:valcnc", "feed": 1}, "unknown valcnc:valcnc timing key"),
        ({"model": "flashcut:flashcut", "half_period_ms": 2}, "half_period_ms"),
        ({"model": "grbl:grbl", "max_rate_mm_min": "fast"}, "must be a number"),
        ({"model": "i8751:i8751", "cruise": "warp"}, "valid: firmware, design"),
    ]
    for table, message in bad:
        with pytest.raises(InputError, match=message) as err:
            timing_model_from_table(table, where="t.toml [timing]")
        assert "t.toml [timing]" in str(err.value)
