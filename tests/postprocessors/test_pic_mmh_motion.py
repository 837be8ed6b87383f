"""Tests of the UNAM-GMM pic-mmh timing model (camtool_postprocessors.pic_mmh.motion).

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import numpy as np
import pytest

from camtool.model.errors import UsageError
from camtool.verify.dda import dda_iterations
from camtool.verify.quantize import steps_from_mm
from camtool_postprocessors.pic_mmh.motion import (
    PicMmhTiming,
    pic_mmh_block_time_s,
    pic_mmh_step_rate_hz,
)
from tests.kinematics import FALSE, assert_seconds, blocks


def test_model_calls_its_function():
    # the timing model's dataclass runs its block-time function (the
    # other models: tests/verify/test_timing.py::test_models_call_their_functions)
    model, direct = (
        PicMmhTiming(),
        lambda b: pic_mmh_block_time_s(
            b.iterations, b.compensation_steps, b.feed_mm_min, b.is_rapid
        ),
    )
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


MMH_STEP_MM = 140e-6  # UNAM-GMM S000-12: 140 nm/step


def test_pic_mmh_f08_is_95_hz():
    # UNAM-GMM §4.9: F08 = 0.8 mm/min at 140 nm/step → f = 7142.857·0.8/60 = 95.2 Hz
    rate = pic_mmh_step_rate_hz([0.8], FALSE)
    assert_seconds(rate, 1)
    assert round(float(rate[0]), 1) == 95.2


@pytest.mark.parametrize(("feed_word", "capped"), [(13, False), (14, True), (99, True)])
def test_pic_mmh_cap_at_166_hz(feed_word, capped):
    # UNAM-GMM S000-05: with F in 0.1 mm/min units only F <= 13 stays under 166 Hz
    rate = float(pic_mmh_step_rate_hz([feed_word * 0.1], FALSE)[0])
    assert (rate == 166.0) is capped
    assert rate <= 166.0


def test_pic_mmh_x_backlash_take_up_is_8_8_s():
    # UNAM-GMM §5.1 / S000-17: X 204 µm ≈ 1457 steps, one take-up at 166 Hz ≈ 8.8 s;
    # a rapid runs at the cap, and so does a feed move whose F exceeds it
    take_up = steps_from_mm(0.204, MMH_STEP_MM)
    assert take_up == 1457
    t = pic_mmh_block_time_s([0, 0], [take_up, take_up], [0.0, 9.9], [True, False])
    assert_seconds(t, 2)
    assert t == pytest.approx([8.8, 8.8], abs=0.05)


def test_pic_mmh_compensation_runs_at_the_block_rate():
    # UNAM-GMM §5.1 ("at the current step rate"): at F08 (95.2 Hz) the same take-up
    # lasts 1457/95.238 s, and DDA iterations of (3, 4) (6 of them, §4.2) add 6 periods
    it = dda_iterations(3, 4)
    t = pic_mmh_block_time_s([it], [1457], [0.8], FALSE)
    assert float(t[0]) == pytest.approx((it + 1457) * 60 / (0.8 / MMH_STEP_MM), rel=1e-12)


def test_pic_mmh_feed_move_without_feed_is_refused():
    # analytic: f = 0 would take forever; rapids and empty blocks need no feed
    with pytest.raises(UsageError, match="block 1"):
        pic_mmh_block_time_s([0, 5], [0, 0], [0.0, 0.0], [False, False])
    assert pic_mmh_block_time_s([0, 5], [0, 0], [0.0, 0.0], [False, True])[0] == 0.0
