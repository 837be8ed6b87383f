"""Non-motion commands in the verifier: dwells count in the time, G28 is reported."""

from __future__ import annotations

import pytest

from camtool.model.program import Dwell, Home, Linear, Program, Rapid
from camtool.post.registry import load_machine
from camtool.verify.verifier import verify_program

SQUARE = (Rapid(1.0, 1.0), Linear(2.0, 1.0, 300.0), Linear(2.0, 2.0, 300.0))


def test_dwell_adds_its_seconds_to_the_time() -> None:
    machine = load_machine("grbl")
    plain = verify_program(Program(SQUARE), machine)
    dwelling = verify_program(Program(SQUARE, commands=((1, Dwell(2.5)), (3, Dwell(1.0)))), machine)
    assert dwelling.dwell_s == 3.5
    assert dwelling.time_s == pytest.approx(plain.time_s + 3.5, abs=1e-12)
    assert dwelling.max_error_um == plain.max_error_um


def test_return_to_machine_zero_is_reported_not_simulated() -> None:
    v = verify_program(Program(SQUARE, commands=((3, Home("XY")),)), load_machine("grbl"))
    assert any(
        "1 return(s) to a machine position (G28, G30, G53) not simulated" in w for w in v.warnings
    )
