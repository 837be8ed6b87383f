"""Tests of the Munoz-22 valcnc motion model: timing and β chords
(camtool_postprocessors.valcnc.motion).

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camtool.model.shapes import chord_count
from camtool.verify.interpolators import accumulator_dda_line, chord_sagitta, polyline_steps
from camtool.verify.quantize import steps_from_mm
from camtool.verify.steparray import positions
from camtool_postprocessors.valcnc.motion import (
    ValcncTiming,
    serial_time_s,
    valcnc_arc_points,
    valcnc_block_time_s,
)
from tests.kinematics import assert_seconds, blocks


def test_model_calls_its_function():
    # the timing model's dataclass runs its block-time function (the
    # other models: tests/verify/test_timing.py::test_models_call_their_functions)
    model, direct = ValcncTiming(), lambda b: valcnc_block_time_s(b.iterations)
    b = blocks()
    t = model.block_time_s(b)
    assert_seconds(t, 3)
    assert np.array_equal(t, direct(b))


def test_valcnc_ten_mm_is_41_7_ms():
    # Munoz-22 S004-R13: 10 mm at 25 steps/mm = 250 steps = 41.7 ms, and the 10×10
    # diagonal (250 accumulator-DDA iterations) takes the same time
    n = steps_from_mm(10.0, 0.04)
    iterations = [len(accumulator_dda_line(n, 0)), len(accumulator_dda_line(n, n))]
    t = valcnc_block_time_s(iterations)
    assert_seconds(t, 2)
    assert t == pytest.approx([0.0417, 0.0417], abs=5e-5)


def test_valcnc_serial_time_at_9600_baud():
    # Munoz-22 S004-R13: ≈ 1.04 ms per byte at 9600 baud; a 27-byte block ≈ 28 ms
    assert float(serial_time_s([1], baud=9600)[0]) == pytest.approx(1.04e-3, abs=5e-6)
    t = valcnc_block_time_s([25], block_bytes=[27], serial_baud=9600)
    assert float(t[0]) == pytest.approx(27 * 10 / 9600 + 25 * 166.667e-6)
    assert float(valcnc_block_time_s([25], block_bytes=[27])[0]) == pytest.approx(25 * 166.667e-6)


# ------------------------------------------------------------------------ chords


def test_valcnc_arc_points():
    # Munoz-22 §4.2: θ0 = atan2(−j, −i); α = 2·asin(C/2R); G02 subtracts β, G03 adds it
    beta = math.radians(10)
    pts = valcnc_arc_points((10.0, 0.0), (0.0, 10.0), (0.0, 0.0), False, beta_rad=beta)
    assert len(pts) == 9  # 90° in 10° chords: 8 interior points + the end
    assert pts[0] == pytest.approx((10 * math.cos(beta), 10 * math.sin(beta)))
    assert tuple(pts[-1]) == (0.0, 10.0)
    # Munoz-22 §4.2 Consideración 2: the same end point clockwise is a reflex 270° sweep
    assert len(valcnc_arc_points((10.0, 0.0), (0.0, 10.0), (0.0, 0.0), True, beta_rad=beta)) == 27
    # Munoz-22 §4.2 pitfall: start == end gives C = 0, α = 0, nothing moves
    full = valcnc_arc_points((10.0, 0.0), (10.0, 0.0), (0.0, 0.0), True, beta_rad=beta)
    assert full.tolist() == [[10.0, 0.0]]


def test_valcnc_quarter_arc_through_the_line_dda():
    # Munoz-22 §8 S004-R12: quarter arc R = 10 mm, β for sagitta ≤ 0.02 mm, chords run
    # by the line DDA at 0.04 mm/step stay within 0.02 + 0.04 mm of the true circle
    n = chord_count(10.0, math.pi / 2, 0.02)
    beta = (math.pi / 2) / n
    assert chord_sagitta(10.0, beta) <= 0.02
    pts = valcnc_arc_points((10.0, 0.0), (0.0, 10.0), (0.0, 0.0), False, beta_rad=beta)
    lattice = [[250, 0]] + [[steps_from_mm(x, 0.04), steps_from_mm(y, 0.04)] for x, y in pts]
    steps = polyline_steps(np.array(lattice), accumulator_dda_line)
    pos_mm = positions(steps, (250, 0)) * 0.04
    assert np.abs(np.hypot(pos_mm[:, 0], pos_mm[:, 1]) - 10.0).max() <= 0.06


def test_a_serial_speed_is_refused_while_block_bytes_are_not_counted() -> None:
    # The verifier builds no per-block byte counts, so a serial_baud in a profile would add
    # 0 s and look honoured; it is refused with the reason instead (the function above
    # takes both when a caller has the bytes).
    from camtool.model.errors import InputError
    from camtool.verify.motion import timing_model_from_table

    with pytest.raises(InputError, match="serial_baud = 9600 is not modelled yet"):
        timing_model_from_table({"model": "valcnc:valcnc", "serial_baud": 9600}, where="v.toml")
    assert timing_model_from_table({"model": "valcnc:valcnc", "serial_baud": 0}, where="v")
