"""A streamed trace's rows are counted without being made where a closed form says how many.

Issue 17: the streamed verify needs every move's row offsets before it measures, and
counted them by simulating the whole program once more (0.6 s of a 66 M-step program).
:func:`camtool.verify.chunked.count_rows` counts a line of the A.3 DDA as
``floor(HIPO) + 1`` rows plus a compensation at a reversal. The judges: the rows the
interpolator makes, and the offsets the full simulation gives.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest

from camtool.model.machine import Backlash, Machine
from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify import chunked, streamed
from camtool.verify import simulate as sim
from camtool.verify.dda import dda_line, dda_line_numpy, dda_line_rows
from camtool.verify.interpolators import bresenham_line, bresenham_line_rows, bresenham_reference
from camtool.verify.report import build_report
from camtool.verify.sources import ALL
from camtool.verify.verifier import verify_program
from tests.verify.programs import TARGETS, mixed_program

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")


@pytest.mark.parametrize("seed", range(4))
def test_a_dda_line_has_the_rows_its_count_says_each_pulse_its_axis_way(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pairs = [(0, 0), (1, 0), (0, -1), (3, 4), (-3, 4), (7, 7), (1, 1000)]
    pairs += [tuple(int(v) for v in rng.integers(-5000, 5000, 2)) for _ in range(200)]
    pairs += [tuple(int(v) for v in rng.integers(-(10**6), 10**6, 2)) for _ in range(5)]
    for dx, dy in pairs:
        for line in (dda_line, dda_line_numpy):
            rows = line(dx, dy)
            assert len(rows) == dda_line_rows(dx, dy), (dx, dy)
            for axis, d in ((0, dx), (1, dy)):
                column = rows[:, axis].astype(np.int64)
                assert int(np.abs(column).sum()) == abs(d)
                assert set(np.sign(column[column != 0]).tolist()) <= {int(math.copysign(1, d))}


@pytest.mark.parametrize("amass", [True, False])
def test_a_bresenham_line_has_the_rows_its_count_says_each_pulse_its_axis_way(
    amass: bool,
) -> None:
    """The judge: GRBL's counter loop (``stepper.c``), one row per step event. Without
    AMASS the counter starts at ``count >> 1`` and a one-step minor axis may never pulse:
    only the rows are counted then (the closed form serves the AMASS build alone)."""
    rng = np.random.default_rng(7)
    pairs = [(0, 0), (1, 0), (0, -1), (3, 4), (-3, 4), (7, 7), (1, 1000)]
    pairs += [tuple(int(v) for v in rng.integers(-3000, 3000, 2)) for _ in range(100)]
    for dx, dy in pairs:
        for line in (bresenham_line, bresenham_reference):
            rows = line(dx, dy, amass=amass)
            assert len(rows) == bresenham_line_rows(dx, dy), (dx, dy)
            for axis, d in ((0, dx), (1, dy)):
                column = rows[:, axis].astype(np.int64)
                assert set(np.sign(column[column != 0]).tolist()) <= {int(math.copysign(1, d))}
                if amass:
                    assert int(np.abs(column).sum()) == abs(d)


def test_grbl_lines_and_chord_arcs_are_counted_without_their_rows(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """GRBL's lines and the chords of its arcs, with a backlash compensation at the
    reversals, are counted in closed form (the count simulated every arc before: 120 s
    of a 12 MB program's verify); the judge is the simulation of every move."""
    base = load_target("grbl").machine
    machine = dataclasses.replace(
        base, backlash=Backlash(true_um=(30.0, 20.0, 0.0), compensation_um=(30.0, 20.0, 0.0))
    )
    made: list[int] = []
    real = sim.StepController.block

    def spy(self: sim.StepController, *args: object) -> None:
        made.append(1)
        real(self, *args)  # type: ignore[arg-type]

    for seed in range(3):
        program = mixed_program(seed)
        want = chunked.simulate_or_count(program, machine, 0)
        assert not isinstance(want, sim.StepTrace)
        with monkeypatch.context() as patch:
            patch.setattr(sim.StepController, "block", spy)
            assert np.array_equal(chunked.count_rows(program, machine), want)
        assert made == []


def _zigzag(seed: int) -> Program:
    """Lines and rapids that reverse both axes, stand still, and move Z (pic-mmh's area)."""
    rng = np.random.default_rng(seed)
    moves: list[Linear | Rapid] = [Rapid(1.0, 1.0, z=1.0)]
    for k in range(40):
        x = round(float(rng.uniform(0.5, 9.5)), 3)
        y = round(float(rng.uniform(0.5, 6.5)), 3)
        if k % 7 == 3:
            moves.append(Rapid(x, y, z=1.0))
        elif k % 11 == 5:
            moves.append(Linear(moves[-1].x, moves[-1].y, 300.0, z=-0.5))  # Z only
        else:
            moves.append(Linear(x, y, 300.0, z=-0.5 if k % 2 else None))
    return Program(tuple(moves), origin=(0.0, 0.0))


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(3))
def test_counted_offsets_are_the_simulated_ones(name: str, seed: int) -> None:
    """pic-mmh's lines counted in closed form, arcs and other machines simulated: the same."""
    machine = load_target(name).machine
    for program in (mixed_program(seed), _zigzag(seed)):
        want = chunked.simulate_or_count(program, machine, 0)
        assert not isinstance(want, sim.StepTrace)
        assert np.array_equal(chunked.count_rows(program, machine), want)


def test_pic_mmh_lines_are_counted_without_their_rows(monkeypatch: pytest.MonkeyPatch) -> None:
    """The closed form is what counts pic-mmh's lines: its interpolator is never asked."""
    machine = load_target("pic-mmh").machine
    program = _zigzag(5)
    want = chunked.simulate_or_count(program, machine, 0)
    monkeypatch.setitem(chunked.LINE_ROWS, dda_line, dda_line_rows)
    made: list[int] = []
    real = sim.StepController.block

    def spy(self: sim.StepController, *args: object) -> None:
        made.append(1)
        real(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(sim.StepController, "block", spy)
    assert np.array_equal(chunked.count_rows(program, machine), want)
    assert made == []


def test_a_wrong_count_is_found_and_counted_again(monkeypatch: pytest.MonkeyPatch) -> None:
    """Were a closed form wrong, the streamed report is still the whole trace's."""
    pytest.importorskip("camtool.accel.kernels")  # a trace streams only with them
    machine = load_target("pic-mmh").machine
    program = _zigzag(2)
    whole = build_report(verify_program(program, machine, name="pic-mmh", budget=False))
    monkeypatch.setitem(chunked.LINE_ROWS, dda_line, lambda dx, dy: dda_line_rows(dx, dy) + 1)
    recounted: list[int] = []
    real = streamed.simulate_or_count

    def spy(*args: object) -> object:
        recounted.append(1)
        return real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(streamed, "simulate_or_count", spy)
    v = verify_program(
        program, machine, name="pic-mmh", budget=False, chunk_rows=500, stream_above=10
    )
    assert isinstance(v.trace, chunked.StreamedTrace)
    assert recounted == [1]
    got = build_report(v)
    for report in (got, whole):
        report["deviation_um"].pop("rms")  # summed exactly when streamed (test_stream.py)
    assert got == whole


def _no_compensation(name: str) -> Machine:
    """``name``'s machine without backlash: its ideal controller inserts no compensation."""
    return dataclasses.replace(load_target(name).machine, backlash=Backlash())


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("seed", range(3))
def test_the_ideal_controller_s_rows_are_counted_as_it_makes_them(name: str, seed: int) -> None:
    """Interpolation off, no compensation: lines, native and chord arcs counted, the same.

    The judge: the offsets of the whole simulation (its rows made), and of the count that
    simulates every move.
    """
    sources = ALL.without("interpolation")
    for machine in (_no_compensation(name), load_target(name).machine):
        for program in (mixed_program(seed), _zigzag(seed)):
            want = sim.simulate_steps(program, machine, sources=sources).block_start
            assert np.array_equal(chunked.count_rows(program, machine, sources=sources), want)
            counted = chunked.count_rows(program, machine, sources=sources, closed_form=False)
            assert np.array_equal(counted, want)


@pytest.mark.parametrize(
    ("name", "backlash", "lines_only"),
    [("pic-mmh", False, False), ("grbl", False, False), ("pic-mmh", True, True)],
)
def test_the_ideal_controller_counts_without_making_rows(
    name: str, backlash: bool, lines_only: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No ideal line or arc is made to count the rows: without compensation, pic-mmh's
    direct-search arcs and GRBL's chords (0.49 s of the 40 half circles' budget before);
    with it, lines (their compensation at their first row: 0.24 s of 40 DDA lines')."""
    machine = load_target(name).machine if backlash else _no_compensation(name)
    sources = ALL.without("interpolation")
    program = _zigzag(3) if lines_only else mixed_program(3)
    want = sim.simulate_steps(program, machine, sources=sources).block_start
    made: list[str] = []
    for method in ("_ideal_line", "_ideal_arc"):
        real = getattr(sim.IdealController, method)

        def spy(
            self: sim.IdealController, *args: object, _real: Any = real, _m: str = method
        ) -> Any:
            made.append(_m)
            return _real(self, *args)

        monkeypatch.setattr(sim.IdealController, method, spy)
    assert np.array_equal(chunked.count_rows(program, machine, sources=sources), want)
    assert made == []
