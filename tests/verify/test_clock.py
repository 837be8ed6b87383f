"""Time of a program on a profile without a timing model: at the programmed feed."""

from __future__ import annotations

import dataclasses
import math

import pytest

from camtool.model.errors import InputError
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_machine, load_target
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


def test_z_moves_are_timed_by_their_length() -> None:
    """A 25 mm Z feed at F100 on GRBL: the trapezoid of its own length, never 0 s.

    Rest to rest at v = 100/60 mm/s and GRBL's default a = 10 mm/s² ($122): the ramps
    take v/a and cover v²/a, so t = L/v + v/a = 15 s + 1/6 s (analysis, not camtool).
    """
    from camtool.verify.verifier import verify_code

    v = verify_code("G21 G90 G94\nG1 Z-25 F100\nM2\n", load_target("grbl"), source="z.ngc")
    assert v.time_s == pytest.approx(25 / (100 / 60) + (100 / 60) / 10.0, rel=1e-6)


def test_a_helix_is_as_long_as_its_arc_and_its_drop() -> None:
    quarter = ArcMove(0.0, 10.0, 0.0, 0.0, False, 60.0, z=-3.0)
    program = Program((Rapid(10.0, 0.0, 0.0), quarter))
    arc = math.pi / 2 * 10.0
    assert program.path_lengths() == pytest.approx([10.0, math.hypot(arc, 3.0)])


def test_a_rest_to_rest_estimate_says_it_is_an_upper_bound() -> None:
    """grbl's and linuxcnc's trapezoids stop at every block, which their planners do not:
    the summary says so; pic-mmh's step clock and a profile without a timing table (the
    programmed feeds) add nothing."""
    from camtool.verify.report import summary_lines

    program = Program((Linear(6.0, 0.0, 60.0), Linear(6.0, 8.0, 120.0), Rapid(0.0, 0.0)))

    def time_line(machine: object) -> str:
        v = verify_program(program, machine)  # type: ignore[arg-type]
        return next(ln for ln in summary_lines(v) if "estimated time" in ln)

    for name in ("grbl", "linuxcnc"):
        assert time_line(load_machine(name)).endswith(
            " (every block from rest to rest: an upper bound)"
        )
    assert time_line(no_timing()).endswith(" s")
    pic = Program((Linear(0.5, 0.0, 0.8), Linear(0.5, 0.4, 0.8)))
    v = verify_program(pic, load_target("pic-mmh").machine)
    assert next(ln for ln in summary_lines(v) if "estimated time" in ln).endswith(" s")
