"""A trace simulated a chunk of whole moves at a time, and its rows counted without it.

:class:`ChunkedSimulation` runs the step simulator's controllers
(:mod:`camtool.verify.simulate`) a chunk at a time, carrying the backlash play from one
chunk to the next, so a big program's trace is never held whole; :func:`count_rows` and
:func:`simulate_or_count` give every move's row offsets first.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Program
from camtool.verify.dda import compiled, dda_line, dda_line_rows
from camtool.verify.interpolators import bresenham_line, bresenham_line_rows
from camtool.verify.motion import StepTrace
from camtool.verify.simulate import (
    IdealController,
    StepController,
    at_move,
    origin_mm,
    run_bands,
    switched_machine,
)
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import STEP_DTYPE, StepArray, read_only

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclasses.dataclass(frozen=True, eq=False)
class TraceChunk:
    """Whole moves' worth of a streamed simulation (:class:`ChunkedSimulation`).

    Attributes:
        first_block: index of the chunk's first move.
        block_start: ``(b + 1,) int64`` row offsets of its moves, global (row numbers
            of the whole trace): move ``first_block + i`` owns rows
            ``block_start[i]:block_start[i + 1]``.
        rows: ``(n, 2) int8`` motor steps of the chunk's rows, compensation included.
        compensation: ``(n,) bool``, True for a compensation row.
        carriage_mm: ``(n, 2) float64`` carriage after each row, mm: the same floats as
            the whole trace's rows ``block_start[0]:block_start[-1]``.
    """

    first_block: int
    block_start: IntArray
    rows: StepArray
    compensation: npt.NDArray[np.bool_]
    carriage_mm: FloatArray

    @property
    def row0(self) -> int:
        """Global number of the chunk's first row."""
        return int(self.block_start[0])

    def block_of_row(self) -> IntArray:
        """``(n,) int64`` move index of each of the chunk's rows."""
        counts = np.diff(self.block_start)
        return np.repeat(np.arange(self.first_block, self.first_block + len(counts)), counts)


def simulate_or_count(program: Program, machine: Machine, limit: int) -> StepTrace | IntArray:
    """:func:`simulate_steps` (all sources) when the trace has at most ``limit`` rows.

    Otherwise the rows are dropped as the moves are simulated (never more than one move's
    rows held) and the ``(B + 1,) int64`` row offsets of the moves are returned: what
    :class:`ChunkedSimulation` needs to stream the same trace in chunks.
    """
    sim = StepController(machine, program.origin, ALL)
    start = program.origin
    rows = 0
    for k, move in enumerate(program.moves):
        try:
            sim.block(start, move)
        except InputError as exc:
            raise at_move(program, k, exc) from exc
        start = (move.x, move.y)
        rows += sim.counts[-1]
        if rows > limit:
            sim.parts.clear()
            sim.comp_parts.clear()
    if rows <= limit:
        return sim.finish(len(program.moves))
    return sim.block_start()


LINE_ROWS: dict[Callable[[int, int], StepArray], Callable[[int, int], int]] = {
    dda_line: dda_line_rows,
    bresenham_line: bresenham_line_rows,
}
"""Line interpolators whose rows :func:`count_rows` counts in closed form, and the count."""


def count_rows(
    program: Program, machine: Machine, *, sources: Sources = ALL, closed_form: bool = True
) -> IntArray:
    """The ``(B + 1,) int64`` row offsets of the moves of ``program``'s step trace.

    What :func:`simulate_or_count` returns for a trace over its limit, without making the
    rows of a line or rapid whose interpolator counts them in closed form
    (:data:`LINE_ROWS`: the A.3 DDA's ``floor(HIPO) + 1``, GRBL's Bresenham's
    ``max(|dx|, |dy|)``, and a compensation's rows at a reversal), the chords of an arc
    such a controller cuts as chords, and the ideal controller's lines, chords and,
    where it inserts no compensation, native arcs (:meth:`IdealController.count_block`);
    other moves (native arcs, other interpolators, a line whose piece models dynamics, the
    ideal controller's arcs with compensation) are simulated, their rows dropped.
    ``sources``: the trace of :func:`simulate_steps` with these sources;
    ``closed_form=False`` simulates every move.
    :class:`ChunkedSimulation` makes the same offsets again from the rows themselves,
    and the verifier compares the two.

    Raises:
        InputError: as :func:`simulate_or_count` (naming the block).
    """
    machine = switched_machine(machine, sources)
    kind = StepController if sources.interpolation else IdealController
    sim = kind(machine, program.origin, sources)
    exact = closed_form and sources.interpolation and not sim.inexact
    rows_of = LINE_ROWS.get(sim.line) if exact else None
    ideal = sim if isinstance(sim, IdealController) else None
    if not closed_form or sim.inexact:
        ideal = None
    start = program.origin
    for k, move in enumerate(program.moves):
        try:
            if ideal is not None:
                ideal.count_block(start, move)
            elif rows_of is not None and not isinstance(move, ArcMove):
                sim.count_line(move, rows_of)
            elif rows_of is not None and sim.arc is None and isinstance(move, ArcMove):
                sim.count_chords(start, move, rows_of)
            else:
                sim.block(start, move)
                sim.parts.clear()
                sim.comp_parts.clear()
        except InputError as exc:
            raise at_move(program, k, exc) from exc
        start = (move.x, move.y)
    return sim.block_start()


@dataclasses.dataclass(frozen=True, eq=False)
class StreamedTrace(StepTrace):
    """The trace of a streamed verification: per-move arrays whole, rows only thinned.

    ``rows``, ``compensation``, ``block_of_row`` and ``carriage_mm`` hold only the rows
    kept for the picture (:class:`camtool.verify.trace_measures.StreamedMeasures`: every k-th
    and the worst point), in trace order; ``block_start`` and the other per-move arrays
    are the whole trace's. The whole trace's counts are :attr:`row_count`,
    :attr:`iterations` and :attr:`compensation_steps`.

    Attributes:
        total_rows: rows of the whole trace.
        total_compensation_steps: compensation steps ``(x, y)`` of the whole trace.
    """

    total_rows: int = 0
    total_compensation_steps: tuple[int, int] = (0, 0)

    @property
    def row_count(self) -> int:
        """Rows of the whole trace."""
        return self.total_rows

    @property
    def iterations(self) -> int:
        """Iterations of the whole trace (rows less compensation rows)."""
        return self.total_rows - int(self.block_compensation.sum())

    @property
    def compensation_steps(self) -> tuple[int, int]:
        """Compensation steps per axis of the whole trace."""
        return self.total_compensation_steps


class NotStreamable(Exception):
    """The program cannot be simulated in chunks (rows that are not whole steps)."""


class ChunkedSimulation:
    """The step simulator run in chunks of whole moves, carriage included.

    :meth:`chunks` yields :class:`TraceChunk` s of at least ``chunk_rows`` rows (a move
    is never split: a longer move is one chunk), each with the carriage the whole
    simulation (:func:`simulate_steps` with the same ``sources``) would give: the
    backlash play is carried from chunk to chunk
    (:func:`camtool.accel.kernels.play_axis_from` for whole steps; for the ideal
    controller's fractional steps, ``interpolation`` off, the motor's running sum and
    the play by :class:`_FloatPlay`, whose chunk's ``rows`` are each sample's direction
    as the whole trace's are). Afterwards :meth:`trace_summary` is the trace's per-move
    arrays. Needs the compiled kernels (``numba``).
    """

    def __init__(
        self, program: Program, machine: Machine, chunk_rows: int, *, sources: Sources = ALL
    ) -> None:
        self.program = program
        self.machine = switched_machine(machine, sources)
        self.chunk_rows = max(1, int(chunk_rows))
        kind = StepController if sources.interpolation else IdealController
        self.sim = kind(self.machine, program.origin, sources)
        self.jit: Any = compiled()
        if self.jit is None:
            raise RuntimeError("the chunked simulation needs numba")  # callers check first

    def chunks(self) -> Any:
        """Yield the :class:`TraceChunk` s in order (an iterator).

        Raises:
            InputError: a block the controller cannot run (naming its line).
            NotStreamable: a move's rows are neither whole steps nor the ideal
                controller's fractional ones.
        """
        sim = self.sim
        ideal = isinstance(sim, IdealController)
        play: _StepPlay | _FloatPlay | _FloatPlayCompiled = _StepPlay(self)
        if ideal:
            play = _FloatPlayCompiled(sim.origin_steps, self.machine, self.jit)
        start = self.program.origin
        first, row0, pending = 0, 0, 0
        moves = self.program.moves
        for b, move in enumerate(moves):
            try:
                sim.block(start, move)
            except InputError as exc:
                raise at_move(self.program, b, exc) from exc
            start = (move.x, move.y)
            pending += sim.counts[-1]
            if pending < self.chunk_rows and b + 1 < len(moves):
                continue
            kind = np.float64 if ideal else STEP_DTYPE
            rows = np.concatenate(sim.parts) if sim.parts else np.zeros((0, 2), kind)
            if rows.dtype != kind:
                raise NotStreamable(f"rows of dtype {rows.dtype}")
            comp = np.concatenate(sim.comp_parts) if sim.comp_parts else np.zeros(0, np.bool_)
            counts = np.array(sim.counts[first:], dtype=np.int64)
            sim.parts.clear()
            sim.comp_parts.clear()
            rows, out = play.chunk(rows)
            block_start = np.concatenate(([row0], row0 + np.cumsum(counts))).astype(np.int64)
            yield TraceChunk(
                first_block=first,
                block_start=read_only(block_start),
                rows=read_only(rows),
                compensation=read_only(comp),
                carriage_mm=read_only(out),
            )
            first, row0, pending = b + 1, int(block_start[-1]), 0

    def trace_summary(self) -> dict[str, Any]:
        """The per-move arrays and counts of the whole trace (after :meth:`chunks`)."""
        sim = self.sim
        return {
            "block_start": read_only(sim.block_start()),
            "start_mm": origin_mm(sim.origin_steps, self.machine),
            "logical_end": read_only(np.array(sim.logical, dtype=np.int64).reshape(-1, 2)),
            "block_steps": read_only(np.array(sim.steps, dtype=np.int64).reshape(-1, 3)),
            "block_dominant": read_only(np.array(sim.dominant, dtype=np.int64)),
            "block_compensation": read_only(np.array(sim.block_comp, dtype=np.int64)),
            "reversals": (sim.reversals[0], sim.reversals[1]),
            "compensations": sim.compensations,
        }


class _StepPlay:
    """The carriage of whole-step rows chunk after chunk (:class:`ChunkedSimulation`).

    The compiled play operator (:func:`camtool.accel.kernels.play_axis_from`) resumed
    from the chunk before: the motor position, each axis's last run sign and its state.
    """

    def __init__(self, simulation: ChunkedSimulation) -> None:
        self.jit = simulation.jit
        self.machine = simulation.machine
        self.origin = simulation.sim.origin_steps
        self.motor = [int(self.origin[0]), int(self.origin[1])]
        self.last_sign = [0, 0]
        self.state = [np.zeros(5, dtype=np.float64), np.zeros(5, dtype=np.float64)]

    def chunk(self, rows: StepArray) -> tuple[StepArray, FloatArray]:
        """``rows`` and the carriage after each, ``(n, 2) float64`` mm."""
        machine, motor, origin = self.machine, self.motor, self.origin
        true = machine.real_steps_per_mm
        out = np.empty((len(rows), 2), dtype=np.float64)
        if not len(rows):
            return rows, out
        runs = self.jit.play_runs(rows, motor[0], motor[1])
        for axis in (0, 1):
            starts, signs, at = runs[3 * axis : 3 * axis + 3]
            if len(starts) and int(signs[0]) == self.last_sign[axis]:  # the run goes on
                starts, signs, at = starts[1:], signs[1:], at[1:]
            bands = run_bands(machine, axis, signs, at)
            if len(signs):
                self.last_sign[axis] = int(signs[-1])
            motor[axis] = int(
                self.jit.play_axis_from(
                    rows,
                    axis,
                    starts,
                    signs,
                    bands,
                    self.state[axis],
                    motor[axis],
                    float(origin[axis]),
                    float(true[axis]),
                    out,
                )
            )
        return rows, out


class _FloatPlayCompiled:
    """:class:`_FloatPlay` by the compiled loops: the same floats, three passes, no temporaries.

    :func:`camtool.accel.kernels.ideal_motor` sums the rows into the motor and takes
    their directions; :func:`camtool.accel.kernels.runs` finds where each axis's runs
    start, whose bands :func:`run_bands` looks up at the motor there, as
    :meth:`_FloatPlay._band` does; :func:`camtool.accel.kernels.ideal_play_axis` is the
    play operator, its state carried from chunk to chunk.
    """

    def __init__(self, origin: tuple[float, float], machine: Machine, jit: Any) -> None:
        self.machine = machine
        self.origin = np.asarray(origin, dtype=np.float64)
        self.jit = jit
        self.total = np.zeros(2, dtype=np.float64)  # the rows' running sum so far
        self.state = [np.zeros(5, dtype=np.float64), np.zeros(5, dtype=np.float64)]

    def chunk(self, rows: FloatArray) -> tuple[StepArray, FloatArray]:
        """Each row's direction ``(n, 2) int8`` and the carriage after it, ``(n, 2)`` mm."""
        n = len(rows)
        signs = np.empty((n, 2), dtype=STEP_DTYPE)
        out = np.empty((n, 2), dtype=np.float64)
        if not n:
            return signs, out
        motor = np.empty((n, 2), dtype=np.float64)
        rows = np.ascontiguousarray(rows, dtype=np.float64)
        self.jit.ideal_motor(rows, self.total, self.origin, motor, signs)
        true = self.machine.real_steps_per_mm
        found = []
        for axis in (0, 1):  # every band looked up before the motor is overwritten
            starts, run_signs = self.jit.runs(signs, axis, int(self.state[axis][4]))
            found.append(
                (starts, run_signs, run_bands(self.machine, axis, run_signs, motor[starts]))
            )
        for axis in (0, 1):
            starts, run_signs, bands = found[axis]
            origin, spm = float(self.origin[axis]), float(true[axis])
            self.jit.ideal_play_axis(
                motor, axis, starts, run_signs, bands, self.state[axis], origin, spm, out
            )
        return signs, out


class _FloatPlay:
    """The carriage of the ideal controller's fractional rows chunk after chunk.

    The same float operations, in the same order, as the whole trace's
    (:func:`motor_positions`, :func:`carriage_of`, :func:`backlash_play`): the motor is the running
    sum of the rows (``np.cumsum`` adds in order, so the sum is resumed from the chunk
    before's last, bit for bit) plus the origin; a run of one sign starts where a row's
    sign differs from the axis's last non-zero one, its band looked up at its first
    row; in an up run the carriage is ``max(c, M)``, in a down run ``min(c, M + band)``,
    ``c`` the carriage at the end of the run before; then ``(v − c0) + start``,
    divided by the true steps/mm. The rows returned are each row's direction (int8).
    """

    def __init__(self, origin: tuple[float, float], machine: Machine) -> None:
        self.machine = machine
        self.origin = origin
        self.total = np.zeros((1, 2), dtype=np.float64)  # the rows' running sum so far
        self.sign = [0, 0]  # each axis's last non-zero direction (0: none yet)
        self.c0 = [0.0, 0.0]  # the carriage before the first run (once one started)
        self.current = [0.0, 0.0]  # the carriage at the end of the run before this one
        self.value = [0.0, 0.0]  # the carriage after the last row
        self.band = [0.0, 0.0]  # the band of the run going on, steps

    def chunk(self, rows: FloatArray) -> tuple[StepArray, FloatArray]:
        """Each row's direction ``(n, 2) int8`` and the carriage after it, ``(n, 2)`` mm."""
        n = len(rows)
        if not n:
            return np.zeros((0, 2), dtype=STEP_DTYPE), np.empty((0, 2), dtype=np.float64)
        total = np.cumsum(np.concatenate((self.total, rows)), axis=0)[1:]
        self.total = total[-1:].copy()
        motor = total  # the motor: the running sum plus the origin, as motor_positions adds it
        motor += np.asarray(self.origin, dtype=np.float64)
        signs = np.sign(rows).astype(STEP_DTYPE)
        true = self.machine.real_steps_per_mm
        out = np.empty((n, 2), dtype=np.float64)
        for axis in (0, 1):
            values = self._play(signs[:, axis], motor, axis)
            np.divide(values, true[axis], out=out[:, axis])
        return signs, out

    def _band(self, motor: FloatArray, row: int, axis: int) -> float:
        """The true backlash at the motor's position after ``row``, steps."""
        true = self.machine.real_steps_per_mm
        x_mm, y_mm = motor[row, 0] / true[0], motor[row, 1] / true[1]
        return self.machine.backlash.true_at(axis, x_mm, y_mm) / 1000.0 * true[axis]

    def _play(self, steps: npt.NDArray[np.int8], motor: FloatArray, axis: int) -> FloatArray:
        """One axis's carriage in motor steps, ``(v − c0) + start`` (as :func:`backlash_play`)."""
        column = motor[:, axis]
        nz = np.flatnonzero(steps)
        signs = steps[nz]
        run_first = np.flatnonzero(signs != np.concatenate(([self.sign[axis]], signs[:-1])))
        bounds = np.append(nz[run_first], len(steps))
        out = np.empty(len(steps), dtype=np.float64)
        started = 0 if self.sign[axis] else int(bounds[0])  # rows from which a run has started
        if started:  # no run yet: c0 − c0
            out[:started] = 0.0
        else:  # the run going on from the chunk before
            self._run(column, 0, int(bounds[0]), axis, out)
        for r in range(len(run_first)):
            lo, hi = int(bounds[r]), int(bounds[r + 1])
            sign = int(signs[run_first[r]])
            band = self._band(motor, lo, axis) if sign < 0 else 0.0
            if self.sign[axis] == 0:  # the first run: the carriage's start contact
                start = float(self.origin[axis])
                self.value[axis] = self.c0[axis] = start if sign > 0 else start + band
            self.current[axis], self.band[axis], self.sign[axis] = self.value[axis], band, sign
            self._run(column, lo, hi, axis, out)
        if self.sign[axis]:
            out[started:] -= self.c0[axis]
        out += float(self.origin[axis])
        return out

    def _run(self, column: FloatArray, lo: int, hi: int, axis: int, out: FloatArray) -> None:
        """Rows ``lo:hi`` of the run going on: ``max(c, M)`` up, ``min(c, M + band)`` down."""
        if hi <= lo:
            return
        if self.sign[axis] > 0:
            np.maximum(self.current[axis], column[lo:hi], out=out[lo:hi])
        else:
            np.minimum(self.current[axis], column[lo:hi] + self.band[axis], out=out[lo:hi])
        self.value[axis] = float(out[hi - 1])
