"""A budget whose one source is the interpolation: the program's own figures, not re-simulated.

With ``interpolation`` the only modelled source (no backlash, scale, chords, dynamics or
plan), the ideal controller moves the carriage along the programmed lines and circles, so
the figures without it are the program's own (:func:`trace_sources.ideal_figures`). The
judge is the re-simulation those figures replace (:func:`budget_run.without_source`, the
ideal controller's trace measured as every trace is): the same figures up to its sampling
(four rows a step; an arc's chords between them stay within ~0.01 µm of a 3 mm radius).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from camtool.model.machine import Backlash, Machine
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify import budget_run, trace_sources
from camtool.verify.budget_run import BudgetInputs
from camtool.verify.verifier import verify_program

pytestmark = pytest.mark.usefixtures("accel_on")

SAMPLING_UM = 0.02
"""How far the re-simulation's figures may lie from the exact ones (its sampling), µm."""


def _bare() -> Machine:
    """pic-mmh without backlash: its one modelled source is the interpolation."""
    return dataclasses.replace(load_target("pic-mmh").machine, backlash=Backlash())


def _zigzag() -> Program:
    moves: list[Rapid | Linear | ArcMove] = [Rapid(0.5, 0.5, contour=1)]
    for k in range(6):
        moves.append(Linear(4.0 if k % 2 == 0 else 0.5, 0.5 + 0.21 * (k + 1), 300.0, contour=1))
    return Program(tuple(moves))


def _square_and_circle() -> Program:
    """A closed 2 mm square, then a ø3 mm circle in two half circles (two contours)."""
    return Program(
        (
            Rapid(1.0, 1.0, contour=1),
            Linear(3.0, 1.0, 300.0, contour=1),
            Linear(3.0, 3.0, 300.0, contour=1),
            Linear(1.0, 3.0, 300.0, contour=1),
            Linear(1.0, 1.0, 300.0, contour=1),
            Rapid(7.5, 4.0, contour=2),
            ArcMove(4.5, 4.0, 6.0, 4.0, True, 300.0, contour=2),
            ArcMove(7.5, 4.0, 6.0, 4.0, True, 300.0, contour=2),
        )
    )


def _open_arcs() -> Program:
    """An S of two arcs of different radii, not closed."""
    return Program(
        (
            Rapid(1.0, 2.0, contour=1),
            ArcMove(3.0, 2.0, 2.0, 2.0, True, 300.0, contour=1),
            ArcMove(6.0, 2.0, 4.5, 2.0, False, 300.0, contour=1),
        )
    )


@pytest.mark.parametrize("make", [_zigzag, _square_and_circle, _open_arcs])
def test_the_program_s_own_figures_are_the_re_simulated_ones(make: object) -> None:
    program = make()  # type: ignore[operator]
    machine = _bare()
    v = verify_program(program, machine, name="pic-mmh", budget=False)
    statuses = trace_sources.source_statuses(program, machine)
    assert trace_sources.follows_program(program, machine, statuses)
    exact = trace_sources.ideal_figures(program, v.contours, along=v.along is not None)
    inputs = BudgetInputs(program, machine, v.trace, None, None, 0.0, ())
    simulated = budget_run.without_source(inputs, "interpolation").values
    assert exact.keys() == simulated.keys()
    arcs = any(isinstance(m, ArcMove) for m in program.moves)
    within = SAMPLING_UM if arcs else 1e-6  # lines: any samples of a line are on it
    for name, value in exact.items():
        assert value == pytest.approx(simulated[name], abs=within), name


def test_a_verification_of_one_source_re_simulates_nothing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def never(*args: object) -> object:
        raise AssertionError("re-simulated")

    monkeypatch.setattr(budget_run, "without_source", never)
    v = verify_program(_square_and_circle(), _bare(), name="pic-mmh")
    budget = v.error_budget
    assert list(budget.without) == ["interpolation"]
    assert budget.without["interpolation"]["max deviation"] == 0.0
    assert budget.total["max deviation"] > 0.05  # the staircase: about a step (0.14 µm)
    assert budget.dominant("max deviation") == "interpolation"


def test_what_the_ideal_trace_does_not_follow_is_re_simulated() -> None:
    machine = _bare()
    lines, arcs = _zigzag(), _square_and_circle()

    def follows(program: Program, machine: Machine) -> bool:
        statuses = trace_sources.source_statuses(program, machine)
        return trace_sources.follows_program(program, machine, statuses)

    assert follows(lines, machine) and follows(arcs, machine)
    # backlash: a second source, and a trace off the path
    assert not follows(lines, load_target("pic-mmh").machine)
    # an arc whose end lies 0.04 nm off its start's circle: the ideal arc blends the radii
    start = (1.0, 1.0)
    off = Program(
        (Rapid(*start, contour=1), ArcMove(1.5, 1.5002, 1.0, 1.5, False, 300.0, contour=1))
    )
    r0, r1 = math.dist(start, (1.0, 1.5)), math.dist((1.5, 1.5002), (1.0, 1.5))
    assert abs(r1 - r0) > trace_sources.EXACT_RADII_MM
    assert not follows(off, machine)
    # unequal steps/mm: a circle in mm is an ellipse in steps (lines stay lines)
    spm = machine.steps_per_mm
    stretched = dataclasses.replace(machine, steps_per_mm=(spm[0], spm[1] * 1.5, spm[2]))
    assert follows(lines, stretched) and not follows(arcs, stretched)
