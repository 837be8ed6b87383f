"""Time of a program on a profile without a timing model: at the programmed feed."""

from __future__ import annotations

import dataclasses

import pytest

from camtool.model.errors import InputError
from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import load_machine
from camtool.verify.verifier import verify_program


def no_timing():
    return dataclasses.replace(load_machine("grbl"), timing={})


def test_without_a_timing_model_moves_take_length_over_feed() -> None:
    # analytic: 6 mm at 60 mm/min = 6 s, then 8 mm at 120 mm/min = 4 s; the rapid back
    # (10 mm) at the program's fastest feed, 120 mm/min: 5 s
    program = Program(
        (Linear(6.0, 0.0, 60.0), Linear(6.0, 8.0, 120.0), Rapid(0.0, 0.0)),
    )
    v = verify_program(program, no_timing())
    assert v.time_s == pytest.approx(15.0, abs=1e-9)


def test_a_cut_without_a_feed_is_named_not_divided_by() -> None:
    # a dialect without an F word reads cutting moves at feed 0: the time is unknown
    program = Program((Linear(5.0, 1.0, 0.0),))
    with pytest.raises(InputError, match=r"no \[machine.timing\] table.*without a feed"):
        verify_program(program, no_timing())
