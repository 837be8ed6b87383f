"""Simulate a program on a step-motor machine: interpolator, compensation, backlash.

The program is what the target's reader got back from the emitted code, so
rounding and field widths are already in it. For each block the controller:

1. converts the end point (and arc centre) to integer steps with its nominal
   steps/mm and rounding, absolutely (no drift, seed-001 §4.5);
2. runs its line or arc interpolator from its logical position
   (:mod:`camtool.verify.interpolators`): one row per iteration;
3. on a reversal of an axis adds the backlash compensation steps in the new
   direction, not counted in its logical position (seed-000 §5.1, seed-001 §5):
   before the move for a line (and before each chord of a chord arc), where the
   reversal happens for a native arc (seed-000: "for arcs it also runs during
   interpolation"); X's compensation before Y's when both reverse at once.

The mechanics then move the carriage: a reversal takes up the true backlash
before the carriage follows (a play operator per axis, the band width taken
from the region the carriage is in at the reversal, seed-000 Tabla 13), and a
motor step moves it by the *true* step length. The machine starts at the
program origin with every axis's backlash taken up in the direction of its
first move (seed-001 §5: "approach the start point moving in the same direction
as the first line"), so only reversals inside the program cost accuracy.

Z moves are counted in steps and time but not traced (the trace is the XY
tool-centre path); Z backlash is not modelled.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Move, Program
from camtool.model.shapes import Point, chord_count, distance
from camtool.verify.interpolators import (
    accumulator_dda_line,
    bresenham_line,
    circular_dda_arc,
    corte_recto_line,
    dda_line,
    dsm_arc,
    flashcut_arc_points,
    grbl_arc_points,
    staircase_arc,
    valcnc_arc_points,
)
from camtool.verify.interpolators_timer import timer_line
from camtool.verify.quantize import Rounding, steps_from_mm
from camtool.verify.steparray import STEP_DTYPE, StepArray, read_only

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class StepTrace:
    """What the motors and the carriage did, row by row.

    Attributes:
        rows: ``(N, 2) int8`` motor steps per iteration, compensation included.
        compensation: ``(N,) bool``, True for a backlash-compensation row.
        block_of_row: ``(N,) int64``, index of the program move each row belongs to.
        block_start: ``(B + 1,) int64`` row offsets: move ``b`` owns rows
            ``block_start[b]:block_start[b + 1]``.
        carriage_mm: ``(N, 2) float64``, carriage (tool-centre) position after each
            row, mm, machine coordinates.
        start_mm: carriage position before the first row, mm.
        logical_end: ``(B, 2) int64``, the controller's logical position after each
            move, steps.
        block_steps: ``(B, 3) int64``, motor steps (pulses) per move and axis, without
            compensation: ``(x, y, z)``.
        block_dominant: ``(B,) int64``, steps of the dominant axis of each executed line
            (summed over the chords of a chord arc; iterations for a native arc), what
            per-step time models count (seed-001 R15).
        block_compensation: ``(B,) int64``, compensation steps inserted in each move.
        reversals: reversals of the commanded X and Y directions.
        compensations: compensation events (axis reversals the controller
            compensated; 0 when the profile compensates nothing).
        block_time_s: ``(B,) float64`` time of each move when the simulation itself
            gives it (the servo router), else ``None`` (the timing model decides).
    """

    rows: StepArray
    compensation: npt.NDArray[np.bool_]
    block_of_row: IntArray
    block_start: IntArray
    carriage_mm: FloatArray
    start_mm: Point
    logical_end: IntArray
    block_steps: IntArray
    block_dominant: IntArray
    block_compensation: IntArray
    reversals: tuple[int, int]
    compensations: int
    block_time_s: FloatArray | None = None


_LINES: dict[str, Callable[[int, int], StepArray]] = {
    "dda": dda_line,
    "accumulator-dda": accumulator_dda_line,
    "bresenham": bresenham_line,
    "corte-recto": corte_recto_line,
}
_ARCS = {"dsm": dsm_arc, "staircase": staircase_arc, "circular-dda": circular_dda_arc}


def simulate_steps(program: Program, machine: Machine) -> StepTrace:
    """Run ``program`` through ``machine``'s controller and mechanics.

    Args:
        program: moves in mm (as read back from the emitted code).
        machine: profile: nominal and true steps/mm, interpolators, backlash.

    Returns:
        The :class:`StepTrace`.

    Raises:
        UsageError: the profile names a line model that needs parameters it lacks.
        InputError: an arc whose start is its centre (radius 0 steps).
    """
    sim = _Controller(machine, program.origin)
    start = program.origin
    for move in program.moves:
        sim.block(start, move)
        start = (move.x, move.y)
    return sim.finish(len(program.moves))


class _Controller:
    """The controller's state while it walks the blocks (local to one simulation)."""

    def __init__(self, machine: Machine, origin: Point) -> None:
        self.machine = machine
        self.spm = machine.steps_per_mm
        self.rounding: Rounding = machine.motion.rounding  # type: ignore[assignment]
        self.pos = (self.to_steps(origin[0], 0), self.to_steps(origin[1], 1))
        self.z_pos: int | None = None
        self.origin_steps = self.pos
        self.direction = [0, 0]
        self.comp_steps = tuple(
            round(machine.backlash.compensation_um[a] / 1000.0 * self.spm[a]) for a in (0, 1)
        )
        self.parts: list[StepArray] = []
        self.comp_parts: list[npt.NDArray[np.bool_]] = []
        self.counts: list[int] = []
        self.logical: list[tuple[int, int]] = []
        self.steps: list[tuple[int, int, int]] = []
        self.dominant: list[int] = []
        self.block_comp: list[int] = []
        self.reversals = [0, 0]
        self.compensations = 0
        self.line = self._line_interpolator()

    def to_steps(self, value_mm: float, axis: int) -> int:
        return steps_from_mm(value_mm, 1.0 / self.spm[axis], self.rounding)

    def _line_interpolator(self) -> Callable[[int, int], StepArray]:
        name = self.machine.motion.line
        if name == "timer":
            from camtool.verify.timing import FlashcutTiming, timing_model_from_table

            where = f"machine {self.machine.name!r} [machine.timing]"
            model = timing_model_from_table(self.machine.timing, where=where)
            if not isinstance(model, FlashcutTiming):
                raise UsageError(
                    f"{where}: line = 'timer' steps by the seed-001 half period; "
                    "it needs model = 'flashcut'"
                )
            period = model.half_period_ms
            return lambda dx, dy: timer_line(dx, dy, period)
        return _LINES[name]

    def block(self, start_mm: Point, move: Move) -> None:
        end = (self.to_steps(move.x, 0), self.to_steps(move.y, 1))
        z = move.z
        z_steps = 0
        if z is not None:
            zs = self.to_steps(z, 2)
            z_steps = abs(zs - self.z_pos) if self.z_pos is not None else 0
            self.z_pos = zs
        if isinstance(move, ArcMove):
            rows, line_starts, dominant = self._arc(start_mm, move, end)
        else:
            dx, dy = end[0] - self.pos[0], end[1] - self.pos[1]
            rows, line_starts, dominant = self.line(dx, dy), [0], max(abs(dx), abs(dy))
        pulses = np.abs(rows).sum(axis=0, dtype=np.int64) if len(rows) else (0, 0)
        self.steps.append((int(pulses[0]), int(pulses[1]), z_steps))
        self.dominant.append(dominant)
        rows, comp = self._compensate(rows, line_starts)
        self.parts.append(rows)
        self.comp_parts.append(comp)
        self.counts.append(len(rows))
        self.block_comp.append(int(comp.sum()))
        self.logical.append(end)
        self.pos = end

    def _arc(
        self, start_mm: Point, move: ArcMove, end: tuple[int, int]
    ) -> tuple[StepArray, list[int], int]:
        motion = self.machine.motion
        if motion.arc in _ARCS:
            centre = (self.to_steps(move.cx, 0), self.to_steps(move.cy, 1))
            full = distance(start_mm, (move.x, move.y)) <= 1e-9
            if end == self.pos and not full:  # an arc shorter than a step: a line
                return self.line(0, 0), [0], 0
            rows = _ARCS[motion.arc](*self.pos, *end, *centre, move.clockwise)
            return rows, [], len(rows)
        points = self._chord_points(start_mm, move)
        lattice = [self.pos] + [(self.to_steps(x, 0), self.to_steps(y, 1)) for x, y in points]
        lattice[-1] = end
        parts, starts, offset, dominant = [], [], 0, 0
        for (x0, y0), (x1, y1) in itertools.pairwise(lattice):
            rows = self.line(x1 - x0, y1 - y0)
            parts.append(rows)
            starts.append(offset)
            offset += len(rows)
            dominant += max(abs(x1 - x0), abs(y1 - y0))
        joined = np.concatenate(parts) if parts else np.zeros((0, 2), STEP_DTYPE)
        return joined, starts, dominant

    def _chord_points(self, start_mm: Point, move: ArcMove) -> FloatArray:
        motion = self.machine.motion
        end, centre = (move.x, move.y), (move.cx, move.cy)
        pts: FloatArray | list[Point]
        if motion.chords == "grbl":
            pts = grbl_arc_points(
                start_mm, end, centre, move.clockwise, arc_tolerance_mm=motion.chord_tolerance_mm
            )
        elif motion.chords == "flashcut":
            pts = flashcut_arc_points(
                start_mm, end, centre, move.clockwise, segments=motion.chord_segments
            )
        elif motion.chords == "valcnc":
            beta = math.radians(motion.chord_angle_deg)
            pts = valcnc_arc_points(start_mm, end, centre, move.clockwise, beta_rad=beta)
        else:
            pts = sagitta_chord_points(start_mm, move, motion.chord_tolerance_mm)
        return np.asarray(pts, dtype=np.float64).reshape(-1, 2)

    def _compensate(
        self, rows: StepArray, line_starts: list[int]
    ) -> tuple[StepArray, npt.NDArray[np.bool_]]:
        """Insert compensation rows at this block's reversals; update the direction state."""
        inserts: list[tuple[int, int, int]] = []  # (row, axis, sign)
        for axis in (0, 1):
            column = rows[:, axis]
            nz = np.flatnonzero(column)
            if nz.size == 0:
                continue
            signs = column[nz].astype(np.int64)
            previous = np.concatenate(([self.direction[axis]], signs[:-1]))
            at = np.flatnonzero((signs != previous) & (previous != 0))
            self.reversals[axis] += int(at.size)
            self.direction[axis] = int(signs[-1])
            if self.comp_steps[axis] == 0:
                continue
            for i in at:
                row = int(nz[i])
                if line_starts:
                    row = line_starts[int(np.searchsorted(line_starts, row, side="right")) - 1]
                inserts.append((row, axis, int(signs[i])))
        flags = np.zeros(len(rows), dtype=np.bool_)
        if not inserts:
            return rows, flags
        self.compensations += len(inserts)
        inserts.sort()
        pieces, flag_pieces, last = [], [], 0
        for row, axis, sign in inserts:
            pieces.append(rows[last:row])
            flag_pieces.append(flags[last:row])
            comp = np.zeros((self.comp_steps[axis], 2), dtype=STEP_DTYPE)
            comp[:, axis] = sign
            pieces.append(comp)
            flag_pieces.append(np.ones(len(comp), dtype=np.bool_))
            last = row
        pieces.append(rows[last:])
        flag_pieces.append(flags[last:])
        return np.concatenate(pieces), np.concatenate(flag_pieces)

    def finish(self, blocks: int) -> StepTrace:
        rows = np.concatenate(self.parts) if self.parts else np.zeros((0, 2), STEP_DTYPE)
        comp = np.concatenate(self.comp_parts) if self.comp_parts else np.zeros(0, np.bool_)
        counts = np.asarray(self.counts, dtype=np.int64)
        block_start = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
        block_of_row = np.repeat(np.arange(blocks, dtype=np.int64), counts)
        carriage = _carriage(rows, self.origin_steps, self.machine)
        return StepTrace(
            rows=read_only(rows),
            compensation=read_only(comp),
            block_of_row=read_only(block_of_row),
            block_start=read_only(block_start),
            carriage_mm=read_only(carriage),
            start_mm=_start_mm(self.origin_steps, self.machine),
            logical_end=read_only(np.asarray(self.logical, dtype=np.int64).reshape(-1, 2)),
            block_steps=read_only(np.asarray(self.steps, dtype=np.int64).reshape(-1, 3)),
            block_dominant=read_only(np.asarray(self.dominant, dtype=np.int64)),
            block_compensation=read_only(np.asarray(self.block_comp, dtype=np.int64)),
            reversals=(self.reversals[0], self.reversals[1]),
            compensations=self.compensations,
        )


def sagitta_chord_points(start: Point, move: ArcMove, tolerance_mm: float) -> list[Point]:
    """End points of equal chords of an arc within ``tolerance_mm`` (the last is its end)."""
    cx, cy = move.cx, move.cy
    radius = math.hypot(start[0] - cx, start[1] - cy)
    a0 = math.atan2(start[1] - cy, start[0] - cx)
    a1 = math.atan2(move.y - cy, move.x - cx)
    sweep = a1 - a0
    turn = -math.tau if move.clockwise else math.tau
    sweep = sweep % turn or turn
    if distance(start, (move.x, move.y)) > 1e-9 and abs(abs(sweep) - math.tau) < 1e-12:
        sweep = 0.0
    n = chord_count(radius, abs(sweep), tolerance_mm) if radius > 0 else 1
    points = [
        (cx + radius * math.cos(a0 + sweep * k / n), cy + radius * math.sin(a0 + sweep * k / n))
        for k in range(n + 1)
    ]
    points[-1] = (move.x, move.y)
    return points[1:]


def _start_mm(origin_steps: tuple[int, int], machine: Machine) -> Point:
    """Carriage start: the program origin as the controller rounded it, in real mm."""
    true = machine.real_steps_per_mm
    return (origin_steps[0] / true[0], origin_steps[1] / true[1])


def _carriage(rows: StepArray, origin: tuple[int, int], machine: Machine) -> FloatArray:
    """Carriage position after each row, mm: motor steps through the backlash play."""
    true = machine.real_steps_per_mm
    motor = np.cumsum(rows, axis=0, dtype=np.int64) + np.asarray(origin, dtype=np.int64)
    out = np.empty((len(rows), 2), dtype=np.float64)
    for axis in (0, 1):
        out[:, axis] = _play(rows[:, axis], motor, axis, origin[axis], machine) / true[axis]
    return out


def _play(
    steps: npt.NDArray[np.int8], motor: IntArray, axis: int, start: int, machine: Machine
) -> FloatArray:
    """One axis's carriage position in motor steps (play operator, band [M, M + B]).

    Pushing up the carriage sits at the motor (c = M); pushing down it sits B
    above (c = M + B). The start contact is the side of the first move, and the
    result is shifted so that the carriage starts at ``start``.
    """
    true_spm = machine.real_steps_per_mm
    column = motor[:, axis]
    nz = np.flatnonzero(steps)
    if nz.size == 0:
        return np.full(len(steps), float(start))
    signs = steps[nz]
    run_first = np.concatenate(([0], np.flatnonzero(signs[1:] != signs[:-1]) + 1))
    run_rows = nz[run_first]
    bounds = np.append(run_rows, len(steps))

    def band(row: int) -> float:
        x_mm = motor[row, 0] / true_spm[0]
        y_mm = motor[row, 1] / true_spm[1]
        return machine.backlash.true_at(axis, x_mm, y_mm) / 1000.0 * true_spm[axis]

    first_up = signs[0] > 0
    c0 = float(start) if first_up else float(start) + band(int(run_rows[0]))
    current = c0
    out = np.full(len(steps), c0)
    for r in range(len(run_rows)):
        lo, hi = int(bounds[r]), int(bounds[r + 1])
        segment = column[lo:hi]
        if signs[run_first[r]] > 0:
            values = np.maximum(current, segment)
        else:
            values = np.minimum(current, segment + band(lo))
        out[lo:hi] = values
        current = float(values[-1])
    return out - c0 + start
