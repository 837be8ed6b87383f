"""Simulate a program on a step-motor machine: interpolator, compensation, backlash.

The program is what the target's reader got back from the emitted code, so
rounding and field widths are already in it. For each block the controller:

Design notes: docs/internals.md, ``camtool/verify/simulate.py``.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from array import array
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError
from camtool.model.machine import Backlash, Machine
from camtool.model.program import ArcMove, Move, Program
from camtool.model.shapes import Point, distance
from camtool.verify.dda import compiled
from camtool.verify.interpolators import bresenham_line, bresenham_lines, sagitta_chord_points
from camtool.verify.motion import StepTrace, library
from camtool.verify.quantize import Rounding, steps_from_mm
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import STEP_DTYPE, StepArray, read_only

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


IDEAL_SAMPLES_PER_STEP = 4
"""Samples per step of the dominant axis of the ideal controller (``interpolation`` off)."""

IDEAL_REST_STEPS = 8
"""Steps of the dominant axis a row of a line's straight rest may span, ideal controller
(:meth:`IdealController._line_shape`): longer rows would make fewer, but the nearest-segment
search of the shortfall slows where a few segments are much longer than the rest."""

LINES_AT_ONCE: dict[Callable[..., Any], Callable[..., tuple[StepArray, npt.NDArray[np.int64]]]] = {
    bresenham_line: bresenham_lines,
}
"""Line interpolators whose rows of many lines (an arc's chords) one call makes, and it."""

FINE_CHORD_STEPS = 0.1
"""Sagitta of the chords, in steps, when the ``chords`` source is off."""


def simulate_steps(program: Program, machine: Machine, *, sources: Sources = ALL) -> StepTrace:
    """Run ``program`` through ``machine``'s controller and mechanics.

    Args:
        program: moves in mm (as read back from the emitted code).
        machine: profile: nominal and true steps/mm, interpolators, backlash.
        sources: the error sources modelled (all by default; the error budget
            switches one off at a time, see the module docstring).

    Returns:
        The :class:`StepTrace`.

    Raises:
        UsageError: the profile names a line model that needs parameters it lacks.
        InputError: an unknown interpolator or chord rule name (listing the valid
            ones), or an arc whose start is its centre (radius 0 steps).
    """
    machine = switched_machine(machine, sources)
    kind = StepController if sources.interpolation else IdealController
    sim = kind(machine, program.origin, sources)
    start = program.origin
    for k, move in enumerate(program.moves):
        try:
            sim.block(start, move)
        except InputError as exc:
            raise at_move(program, k, exc) from exc
        start = (move.x, move.y)
    return sim.finish(len(program.moves))


def at_move(program: Program, index: int, exc: InputError) -> InputError:
    """``exc`` (a block the controller cannot run) with the block's source line in front."""
    line = program.line_of(index)
    return InputError(f"{'block' if line is None else 'line'} {line or index + 1}: {exc}")


def switched_machine(machine: Machine, sources: Sources) -> Machine:
    """``machine`` with the ``scale`` and ``backlash`` sources switched off as ``sources`` say.

    ``scale`` off: the true steps/mm are the nominal ones; ``backlash`` off: no
    true backlash and no compensation.
    """
    if not sources.scale and machine.true_steps_per_mm is not None:
        machine = dataclasses.replace(machine, true_steps_per_mm=None)
    if not sources.backlash:
        machine = dataclasses.replace(machine, backlash=Backlash())
    return machine


class StepController:
    """The controller's state while it walks the blocks (local to one simulation)."""

    def __init__(self, machine: Machine, origin: Point, sources: Sources = ALL) -> None:
        self.machine = machine
        self.sources = sources
        self.spm = machine.steps_per_mm
        self.rounding: Rounding = machine.motion.rounding  # type: ignore[assignment]
        self.pos = (self.to_steps(origin[0], 0), self.to_steps(origin[1], 1))
        self.z_pos: int | None = None
        self.origin_steps = self.pos
        self.direction = [0, 0]
        self.comp_steps = self.compensation_steps()
        self.parts: list[npt.NDArray[Any]] = []
        self.comp_parts: list[npt.NDArray[np.bool_]] = []
        # per move, 8 bytes a value (a list of tuples took ~390 bytes a move)
        self.counts = array("q")  # rows
        self.logical = array("q")  # x, y: the logical end, steps
        self.steps = array("q")  # x, y, z pulses
        self.dominant = array("q")
        self.block_comp = array("q")  # compensation rows
        self.reversals = [0, 0]
        self.compensations = 0
        lib = library(machine)
        self.line = lib.line(machine, sources=sources)
        # a line whose piece models dynamics may not reach its count (a timer's overshoot)
        self.inexact = sources.dynamics and "dynamics" in lib.honours(machine.motion.line)
        self.arc = lib.arc(machine)
        self.chord_rule = lib.chord_rule(machine) if self.arc is None else None

    def compensation_steps(self) -> tuple[float, float]:
        """Compensation per axis and reversal, whole steps (as the controller rounds)."""
        um = self.machine.backlash.compensation_um
        return (round(um[0] / 1000.0 * self.spm[0]), round(um[1] / 1000.0 * self.spm[1]))

    def to_steps(self, value_mm: float, axis: int) -> int:
        """``value_mm`` on ``axis`` in whole motor steps, rounded as the controller rounds."""
        return steps_from_mm(value_mm, 1.0 / self.spm[axis], self.rounding)

    def comp_rows(self, axis: int, sign: int) -> StepArray:
        """The rows of one compensation of ``axis`` in direction ``sign``."""
        comp = np.zeros((int(self.comp_steps[axis]), 2), dtype=STEP_DTYPE)
        comp[:, axis] = sign
        return comp

    def block(self, start_mm: Point, move: Move) -> None:
        """Run one move from ``start_mm``: its rows, compensations and step counts."""
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
        made = rows
        rows, comp, pulses = self._compensate(rows, line_starts)
        if pulses is None:  # not counted as the reversals were found
            x, y = (int(np.abs(made[:, k]).sum(dtype=np.int64)) for k in (0, 1))
            pulses = (x, y)
        self.steps.extend((int(pulses[0]), int(pulses[1]), z_steps))
        self.dominant.append(dominant)
        self.parts.append(rows)
        self.comp_parts.append(comp)
        self.counts.append(len(rows))
        self.block_comp.append(int(comp.sum()))
        self.logical.extend(end)
        self.pos = end

    def block_start(self) -> IntArray:
        """``(B + 1,) int64`` row offsets of the moves simulated or counted so far."""
        return np.concatenate(([0], np.cumsum(np.array(self.counts, dtype=np.int64))))

    def count_line(self, move: Move, rows_of: Callable[[int, int], int]) -> None:
        """:meth:`block` of a line or rapid, its rows counted by ``rows_of``, not made.

        ``rows_of``: the closed-form row count of this controller's line interpolator
        (:data:`LINE_ROWS`), one whose every pulse on an axis goes the way of that
        axis's move. Only the rows' count and the state the next block needs are kept:
        the position, Z, each axis's direction and its reversals and compensations.
        """
        end = (self.to_steps(move.x, 0), self.to_steps(move.y, 1))
        if move.z is not None:
            self.z_pos = self.to_steps(move.z, 2)
        self.counts.append(self._count_piece(end[0] - self.pos[0], end[1] - self.pos[1], rows_of))
        self.pos = end

    def count_chords(
        self, start_mm: Point, move: ArcMove, rows_of: Callable[[int, int], int]
    ) -> None:
        """:meth:`count_line` of an arc this controller cuts as chords (``arc = "chords"``).

        Each chord is a line of the line interpolator between lattice points, as
        :meth:`block` runs it, counted by ``rows_of``.
        """
        end = (self.to_steps(move.x, 0), self.to_steps(move.y, 1))
        if move.z is not None:
            self.z_pos = self.to_steps(move.z, 2)
        lattice = self._chord_lattice(start_mm, move, end)
        rows = 0
        for (x0, y0), (x1, y1) in itertools.pairwise(lattice):
            rows += self._count_piece(x1 - x0, y1 - y0, rows_of)
        self.counts.append(rows)
        self.pos = end

    def _count_piece(self, dx: int, dy: int, rows_of: Callable[[int, int], int]) -> int:
        """Rows of one line piece ``(dx, dy)`` steps with the compensation rows it needs.

        Updates each axis's direction, reversals and compensations (a piece reverses an
        axis at most once, at its first pulse on it).
        """
        rows = rows_of(dx, dy)
        for axis, d in ((0, dx), (1, dy)):
            if d == 0:
                continue
            sign = 1 if d > 0 else -1
            if self.direction[axis] not in (0, sign):  # reversed at its first pulse
                self.reversals[axis] += 1
                if self.comp_steps[axis] != 0:
                    self.compensations += 1
                    rows += int(self.comp_steps[axis])
            self.direction[axis] = sign
        return rows

    def _arc(
        self, start_mm: Point, move: ArcMove, end: tuple[int, int]
    ) -> tuple[StepArray, list[int], int]:
        if self.arc is not None:
            centre = (self.to_steps(move.cx, 0), self.to_steps(move.cy, 1))
            full = distance(start_mm, (move.x, move.y)) <= 1e-9
            if end == self.pos and not full:  # an arc shorter than a step: a line
                return self.line(0, 0), [0], 0
            rows = self.arc(*self.pos, *end, *centre, move.clockwise)
            return rows, [], len(rows)
        lattice = self._chord_lattice(start_mm, move, end)
        at_once = LINES_AT_ONCE.get(self.line)
        if at_once is not None:  # every chord's rows in one call
            chords = np.diff(np.asarray(lattice, dtype=np.int64), axis=0)
            joined, first = at_once(chords[:, 0], chords[:, 1])
            return joined, first.tolist(), int(np.abs(chords).max(axis=1, initial=0).sum())
        parts, starts, offset, dominant = [], [], 0, 0
        for (x0, y0), (x1, y1) in itertools.pairwise(lattice):
            rows = self.line(x1 - x0, y1 - y0)
            parts.append(rows)
            starts.append(offset)
            offset += len(rows)
            dominant += max(abs(x1 - x0), abs(y1 - y0))
        joined = np.concatenate(parts) if parts else np.zeros((0, 2), STEP_DTYPE)
        return joined, starts, dominant

    def _chord_lattice(
        self, start_mm: Point, move: ArcMove, end: tuple[int, int]
    ) -> list[tuple[int, int]]:
        """The chords' ends of an arc in whole steps, from the position to ``end``."""
        points = self._chord_points(start_mm, move)
        lattice: list[tuple[int, int]] = [self.pos]
        lattice += [(self.to_steps(x, 0), self.to_steps(y, 1)) for x, y in points]
        lattice[-1] = end
        return lattice

    def _chord_points(self, start_mm: Point, move: ArcMove) -> FloatArray:
        assert self.chord_rule is not None  # arc = "chords"
        if not self.sources.chords:  # chords far below a step: the arc itself
            tolerance = FINE_CHORD_STEPS / max(self.spm[:2])
            fine = sagitta_chord_points(start_mm, move, tolerance)
            return np.asarray(fine, dtype=np.float64).reshape(-1, 2)
        pts = self.chord_rule(start_mm, move, self.machine.motion)
        return np.asarray(pts, dtype=np.float64).reshape(-1, 2)

    def _compensate(
        self, rows: npt.NDArray[Any], line_starts: list[int]
    ) -> tuple[npt.NDArray[Any], npt.NDArray[np.bool_], tuple[int, int] | None]:
        """Insert compensation rows at this block's reversals; update the direction state.

        Returns the rows with the compensation rows, which rows those are, and each
        axis's pulses in ``rows`` (as given) when the compiled scan counted them as it
        found the reversals (``None`` on the numpy path).
        """
        inserts: list[tuple[int, int, int]] = []  # (row, axis, sign)
        jit = compiled(len(rows)) if rows.dtype == STEP_DTYPE else None
        pulses = [0, 0]
        for axis in (0, 1):
            if jit is not None:
                at_rows, at_signs, self.direction[axis], pulses[axis] = jit.reversals(
                    rows, axis, self.direction[axis]
                )
            else:
                at_rows, at_signs = self._reversals(rows[:, axis], axis)
            self.reversals[axis] += len(at_rows)
            if self.comp_steps[axis] == 0:
                continue
            for row, sign in zip(at_rows.tolist(), at_signs.tolist(), strict=True):
                if line_starts:
                    row = line_starts[int(np.searchsorted(line_starts, row, side="right")) - 1]
                inserts.append((row, axis, int(sign)))
        flags = np.zeros(len(rows), dtype=np.bool_)
        counted = None if jit is None else (pulses[0], pulses[1])
        if not inserts:
            return rows, flags, counted
        self.compensations += len(inserts)
        inserts.sort()
        pieces, flag_pieces, last = [], [], 0
        for row, axis, sign in inserts:
            pieces.append(rows[last:row])
            flag_pieces.append(flags[last:row])
            comp = self.comp_rows(axis, sign)
            pieces.append(comp)
            flag_pieces.append(np.ones(len(comp), dtype=np.bool_))
            last = row
        pieces.append(rows[last:])
        flag_pieces.append(flags[last:])
        return np.concatenate(pieces), np.concatenate(flag_pieces), counted

    def _reversals(
        self, column: npt.NDArray[Any], axis: int
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """Rows and signs of the reversals of one axis's column; updates its direction.

        (numpy; :func:`camtool.accel.kernels.reversals` is the compiled twin.)
        """
        nz = np.flatnonzero(column)
        if nz.size == 0:
            return nz, nz
        signs = np.sign(column[nz]).astype(np.int64)
        previous = np.concatenate(([self.direction[axis]], signs[:-1]))
        at = np.flatnonzero((signs != previous) & (previous != 0))
        self.direction[axis] = int(signs[-1])
        return nz[at], signs[at]

    def finish(self, blocks: int) -> StepTrace:
        """The trace of the ``blocks`` moves run (the rows handed over, not kept)."""
        rows = np.concatenate(self.parts) if self.parts else np.zeros((0, 2), STEP_DTYPE)
        comp = np.concatenate(self.comp_parts) if self.comp_parts else np.zeros(0, np.bool_)
        self.parts.clear()  # not held twice while the carriage is computed
        self.comp_parts.clear()
        block_start = self.block_start()
        block_of_row = _block_of_row(blocks, block_start)
        if rows.dtype == STEP_DTYPE:
            carriage = _carriage(rows, self.origin_steps, self.machine)
        else:  # the ideal controller's fractional steps: let go of them once summed
            motor = motor_positions(rows, self.origin_steps)
            rows = np.sign(rows).astype(STEP_DTYPE)  # each sample's direction
            carriage = carriage_of(rows, motor, self.origin_steps, self.machine)
            del motor
        return StepTrace(
            rows=read_only(rows),
            compensation=read_only(comp),
            block_of_row=read_only(block_of_row),
            block_start=read_only(block_start),
            carriage_mm=read_only(carriage),
            start_mm=origin_mm(self.origin_steps, self.machine),
            logical_end=read_only(np.array(self.logical, dtype=np.int64).reshape(-1, 2)),
            block_steps=read_only(np.array(self.steps, dtype=np.int64).reshape(-1, 3)),
            block_dominant=read_only(np.array(self.dominant, dtype=np.int64)),
            block_compensation=read_only(np.array(self.block_comp, dtype=np.int64)),
            reversals=(self.reversals[0], self.reversals[1]),
            compensations=self.compensations,
        )


class IdealController(StepController):
    """The controller with the ``interpolation`` source off: continuous, unrounded motion.

    Positions are fractional steps (no rounding), a line is a straight run of
    equal float rows (:data:`IDEAL_SAMPLES_PER_STEP` per step of its dominant
    axis), a native arc is sampled on its circle (the radius blended from the
    start's to the end's), a chord arc is its chords run as such lines, and a
    compensation is one row of the exact compensation. A line piece that models
    ``dynamics`` still runs on the rounded counts so that a line that does not
    reach its count (a timer's overshoot) keeps its net displacement per axis.
    The trace's ``rows`` then hold only each sample's direction.

    A programmed line (not a chord) longer than the true backlash can take up is made
    of its first samples and longer rows for the rest (:meth:`_line_shape`; not for a
    comparison with the drawing: ``Sources.sampled_lines``): past the
    take-up the carriage moves along a straight line, which those rows draw as its
    samples do (the same extent, end and distances to the path, which a straight run
    reaches at its ends), and a long program's trace is not tens of millions of rows.
    """

    def __init__(self, machine: Machine, origin: Point, sources: Sources = ALL) -> None:
        super().__init__(machine, origin, sources)
        lash, true = machine.backlash, machine.real_steps_per_mm
        self.takeup = tuple(
            max(
                [abs(lash.true_um[axis])] + [abs(r.true_um) for r in lash.regions if r.axis == name]
            )
            / 1000.0
            * true[axis]
            for axis, name in ((0, "x"), (1, "y"))
        )
        """The most motor travel per axis a reversal's take-up lasts, steps (the largest true
        backlash of the axis, anywhere)."""
        self.travel = [math.inf, math.inf]
        """Each axis's motor travel since its last reversal, steps: ``inf`` before its first
        run (which starts in contact), 0 after an arc (its reversals are not followed)."""

    def _line_shape(self, dx: float, dy: float, n: int) -> tuple[int, int]:
        """``(samples, rest)``: rows of an ``n``-sample line of ``(dx, dy)`` steps.

        A reversal's take-up lasts until the axis's motor has moved its :attr:`takeup`
        since the reversal (:attr:`travel`, kept here): the samples up to that point, and
        one more (a margin for the rounding of the sums), are made, and the rest of the
        line as ``rest`` equal rows of at most :data:`IDEAL_REST_STEPS` steps; ``(n, 0)``
        (every sample) when that would save no row. Call it once a line, before the
        line's reversals are taken.
        """
        dense = 1
        for axis, d in ((0, dx), (1, dy)):
            if not d:
                continue
            sign, before = (1 if d > 0 else -1), self.direction[axis]
            travel = self.travel[axis] if before == sign else (math.inf if before == 0 else 0.0)
            need = self.takeup[axis] - travel
            if need > 0:
                dense = max(dense, math.ceil(need * n / abs(d)) + 1)
            self.travel[axis] = travel + abs(d)
        rest = -(-(n - dense) // (IDEAL_SAMPLES_PER_STEP * IDEAL_REST_STEPS))
        return (n, 0) if dense + rest >= n else (dense, rest)

    def compensation_steps(self) -> tuple[float, float]:
        """Compensation per axis and reversal, fractional steps (nothing rounds them)."""
        um = self.machine.backlash.compensation_um
        return (um[0] / 1000.0 * self.spm[0], um[1] / 1000.0 * self.spm[1])

    def to_steps(self, value_mm: float, axis: int) -> float:  # type: ignore[override]
        """``value_mm`` on ``axis`` in fractional steps (unrounded)."""
        return value_mm * self.spm[axis]

    def comp_rows(self, axis: int, sign: int) -> StepArray:
        """One float row: the exact compensation of ``axis`` in direction ``sign``."""
        comp = np.zeros((1 if self.comp_steps[axis] else 0, 2), dtype=np.float64)
        comp[:, axis] = sign * self.comp_steps[axis]
        return comp  # type: ignore[return-value]

    def block(self, start_mm: Point, move: Move) -> None:
        """Run one move from ``start_mm`` continuously (samples, exact compensation)."""
        end = (self.to_steps(move.x, 0), self.to_steps(move.y, 1))
        rows: npt.NDArray[Any]
        if isinstance(move, ArcMove):
            self.travel = [0.0, 0.0]  # wherever the arc turns, a take-up may follow it
        if isinstance(move, ArcMove) and self.arc is not None:
            rows = self._ideal_arc(start_mm, move)
            line_starts: list[int] = []
        elif isinstance(move, ArcMove):
            lattice = self._lattice(start_mm, move, end)
            parts, line_starts, offset = [], [], 0
            for a, b in itertools.pairwise(lattice):
                part = self._ideal_line(a, b)
                parts.append(part)
                line_starts.append(offset)
                offset += len(part)
            rows = np.concatenate(parts) if parts else np.zeros((0, 2))
        else:
            rows, line_starts = (
                self._ideal_line(self.pos, end, whole=self.sources.sampled_lines),
                [0],
            )
        self.steps.extend((0, 0, 0))
        self.dominant.append(0)
        rows, comp, _ = self._compensate(rows, line_starts)
        self.parts.append(rows)
        self.comp_parts.append(comp)
        self.counts.append(len(rows))
        self.block_comp.append(int(comp.sum()))
        self.logical.extend((round(end[0]), round(end[1])))
        self.pos = end  # type: ignore[assignment]

    def _reversals(
        self, column: npt.NDArray[Any], axis: int
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """:meth:`StepController._reversals`, at once for a column of one value (a line's rows).

        Every row of a straight line moves the axis the same way: a reversal, if any, is
        at its first row (the same rows and signs as the row-by-row scan).
        """
        if not len(column):
            return super()._reversals(column, axis)
        lo, hi = column.min(), column.max()
        if not (lo > 0 or hi < 0 or lo == hi == 0):  # not one direction: scanned
            return super()._reversals(column, axis)
        none = np.zeros(0, dtype=np.int64)
        if column[0] == 0:
            return none, none
        sign = 1 if column[0] > 0 else -1
        before, self.direction[axis] = self.direction[axis], sign
        if before in (0, sign):
            return none, none
        return np.zeros(1, dtype=np.int64), np.full(1, sign, dtype=np.int64)

    def _lattice(
        self, start_mm: Point, move: ArcMove, end: tuple[float, float]
    ) -> list[tuple[float, float]]:
        """A chord arc's corners in fractional steps, from here to ``end``."""
        points = self._chord_points(start_mm, move)
        lattice = [self.pos] + [(x * self.spm[0], y * self.spm[1]) for x, y in points]
        lattice[-1] = end
        return lattice

    def count_block(self, start_mm: Point, move: Move) -> None:
        """:meth:`block` without its rows: their count, and the state the next one needs.

        For a controller whose lines reach their counts (not :attr:`inexact`): a line's
        or chord's rows are its ideal line's (:meth:`_line_rows`, as :meth:`_ideal_line`
        makes them) and one compensation row for each axis it reverses (its rows all go
        one way: the reversal is at its first row); a native arc's are its ideal arc's
        (:meth:`_arc_rows`) when no compensation can be inserted, else the arc is made
        (its reversals lie inside it) and its rows dropped. The position, each axis's
        direction and its reversals are kept as :meth:`block` keeps them.
        """
        assert not self.inexact
        end = (self.to_steps(move.x, 0), self.to_steps(move.y, 1))
        if isinstance(move, ArcMove):
            self.travel = [0.0, 0.0]  # as block() keeps it
        if isinstance(move, ArcMove) and self.arc is not None:
            if any(self.comp_steps):
                self.block(start_mm, move)
                self.parts.clear()
                self.comp_parts.clear()
                return
            rows = self._arc_rows(start_mm, move)[0]
        elif isinstance(move, ArcMove):
            lattice = self._lattice(start_mm, move, end)
            rows = sum(
                self._count_line(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(lattice)
            )
        else:
            dx, dy = end[0] - self.pos[0], end[1] - self.pos[1]
            rows = self._count_line(dx, dy, whole=self.sources.sampled_lines)
        self.counts.append(rows)
        self.pos = end  # type: ignore[assignment]

    def _count_line(self, dx: float, dy: float, *, whole: bool = True) -> int:
        """Rows of the ideal line of ``(dx, dy)`` with its compensations; the directions kept.

        ``whole``: every sample a row (a chord); else as :meth:`_ideal_line` makes a line.
        """
        rows = self._line_rows(dx, dy)
        if not whole and rows:
            rows = sum(self._line_shape(dx, dy, rows))
        if rows == 0:
            return 0
        for axis, d in ((0, dx), (1, dy)):
            step = d / rows  # the line's rows: one value (see _ideal_line)
            if step == 0:
                continue
            sign = 1 if step > 0 else -1
            if self.direction[axis] not in (0, sign):
                self.reversals[axis] += 1
                if self.comp_steps[axis]:
                    rows += 1  # one row of the exact compensation (comp_rows)
            self.direction[axis] = sign
        return rows

    @staticmethod
    def _line_rows(dx: float, dy: float) -> int:
        """Rows of an ideal line of ``(dx, dy)`` fractional steps (0 for none)."""
        if dx == 0 and dy == 0:
            return 0
        return max(1, math.ceil(IDEAL_SAMPLES_PER_STEP * max(abs(dx), abs(dy))))

    def _ideal_line(
        self, a: tuple[float, float], b: tuple[float, float], *, whole: bool = True
    ) -> FloatArray:
        """The rows of the ideal line from ``a`` to ``b`` (fractional steps).

        ``whole``: every sample a row (a chord); else as :meth:`_line_shape` says.
        """
        dx, dy = b[0] - a[0], b[1] - a[1]
        counted = (
            self.line(round(b[0]) - round(a[0]), round(b[1]) - round(a[1])) if self.inexact else ()
        )
        if len(counted):
            programmed = (round(b[0]) - round(a[0]), round(b[1]) - round(a[1]))
            net = np.asarray(counted, dtype=np.int64).sum(axis=0)
            dx *= float(net[0]) / programmed[0] if programmed[0] else 1.0
            dy *= float(net[1]) / programmed[1] if programmed[1] else 1.0
        n = self._line_rows(dx, dy)
        if n == 0:
            return np.zeros((0, 2), dtype=np.float64)
        sample = np.asarray([[dx / n, dy / n]], dtype=np.float64)
        dense, rest = (n, 0) if whole else self._line_shape(dx, dy, n)
        if not rest:
            return np.tile(sample, (n, 1))
        rows = np.empty((dense + rest, 2), dtype=np.float64)
        rows[:dense] = sample
        rows[dense:] = ((dx - dense * (dx / n)) / rest, (dy - dense * (dy / n)) / rest)
        return rows

    def _arc_rows(
        self, start_mm: Point, move: ArcMove
    ) -> tuple[int, tuple[float, float, float, float, float, float]]:
        """Rows of the ideal arc from here to ``move``'s end, and its circle in steps.

        ``(n, (cx, cy, r0, r1, a0, sweep))``: centre, start and end radius, start angle
        and signed sweep; ``n`` is 0 for an arc shorter than 1e-9 steps (not a full one).
        """
        sx, sy = self.spm[0], self.spm[1]
        cx, cy = move.cx * sx, move.cy * sy
        x0, y0 = self.pos
        x1, y1 = move.x * sx, move.y * sy
        r0, r1 = math.hypot(x0 - cx, y0 - cy), math.hypot(x1 - cx, y1 - cy)
        a0, a1 = math.atan2(y0 - cy, x0 - cx), math.atan2(y1 - cy, x1 - cx)
        turn = -math.tau if move.clockwise else math.tau
        sweep = (a1 - a0) % turn or turn
        full = distance(start_mm, (move.x, move.y)) <= 1e-9
        circle = (cx, cy, r0, r1, a0, sweep)
        if not full and math.hypot(x1 - x0, y1 - y0) < 1e-9:
            return 0, circle
        return max(1, math.ceil(IDEAL_SAMPLES_PER_STEP * abs(sweep) * max(r0, r1))), circle

    def _ideal_arc(self, start_mm: Point, move: ArcMove) -> FloatArray:
        n, (cx, cy, r0, r1, a0, sweep) = self._arc_rows(start_mm, move)
        if n == 0:
            return np.zeros((0, 2), dtype=np.float64)
        x0, y0 = self.pos
        x1, y1 = move.x * self.spm[0], move.y * self.spm[1]
        t = np.arange(1, n + 1, dtype=np.float64) / n
        radius = r0 + (r1 - r0) * t
        angle = a0 + sweep * t
        points = np.empty((n + 1, 2), dtype=np.float64)  # the start, then the samples
        points[0] = (x0, y0)
        points[1:, 0] = cx + radius * np.cos(angle)
        points[1:, 1] = cy + radius * np.sin(angle)
        points[-1] = (x1, y1)
        return points[1:] - points[:-1]


def _block_of_row(blocks: int, block_start: IntArray) -> IntArray:
    """``(N,) int64`` move index of each row: ``np.repeat(arange(B), counts)``, slice by slice."""
    if blocks > 10_000:  # many short blocks: numpy's repeat is quicker than a loop
        return np.repeat(np.arange(blocks, dtype=np.int64), np.diff(block_start))
    out = np.empty(int(block_start[-1]), dtype=np.int64)
    for b in range(blocks):
        out[block_start[b] : block_start[b + 1]] = b
    return out


def origin_mm(origin_steps: tuple[int, int], machine: Machine) -> Point:
    """Carriage start: the program origin as the controller rounded it, in real mm."""
    true = machine.real_steps_per_mm
    return (origin_steps[0] / true[0], origin_steps[1] / true[1])


def _carriage(rows: StepArray, origin: tuple[int, int], machine: Machine) -> FloatArray:
    """Carriage position after each row, mm: motor steps through the backlash play.

    ``rows`` are whole steps (int8) or, for the ideal controller, fractional ones (float64).
    """
    if rows.dtype == STEP_DTYPE and len(rows):
        jit = compiled(len(rows))
        if jit is not None:
            return _carriage_compiled(jit, rows, origin, machine)
    return _carriage_numpy(rows, origin, machine)


def _carriage_numpy(
    rows: npt.NDArray[Any], origin: tuple[int, int], machine: Machine
) -> FloatArray:
    """:func:`_carriage` with numpy (any row dtype); holds the motor positions whole."""
    return carriage_of(
        np.sign(rows).astype(np.int8), motor_positions(rows, origin), origin, machine
    )


def motor_positions(rows: npt.NDArray[Any], origin: tuple[int, int]) -> npt.NDArray[Any]:
    """``(N, 2)`` motor position after each row, steps (float64 for fractional rows)."""
    kind = np.float64 if rows.dtype.kind == "f" else np.int64
    motor = np.cumsum(rows, axis=0, dtype=kind)
    motor += np.asarray(origin, dtype=kind)
    return motor


def carriage_of(
    signs: npt.NDArray[np.int8],
    motor: npt.NDArray[Any],
    origin: tuple[int, int],
    machine: Machine,
) -> FloatArray:
    """:func:`_carriage_numpy` from the rows' signs ``(N, 2)`` and the motor positions."""
    true = machine.real_steps_per_mm
    out = np.empty((len(signs), 2), dtype=np.float64)
    for axis in (0, 1):
        np.divide(
            backlash_play(signs[:, axis], motor, axis, origin[axis], machine),
            true[axis],
            out=out[:, axis],
        )
    return out


def _carriage_compiled(
    jit: Any, rows: StepArray, origin: tuple[int, int], machine: Machine
) -> FloatArray:
    """:func:`_carriage_numpy` by the compiled loops, for whole steps: the same floats.

    Two passes over the rows, no motor array: the runs of each axis (their first row,
    sign and the motor position there, :func:`camtool.accel.kernels.play_runs`), the
    band of each run looked up as :func:`backlash_play` does, then the play operator.
    """
    true = machine.real_steps_per_mm
    runs = jit.play_runs(rows, int(origin[0]), int(origin[1]))
    out = np.empty((len(rows), 2), dtype=np.float64)
    for axis in (0, 1):
        starts, signs, at = runs[3 * axis : 3 * axis + 3]
        bands = run_bands(machine, axis, signs, at)
        fresh = np.zeros(5, dtype=np.float64)  # no run started yet: the whole trace is one chunk
        motor0, start, spm = int(origin[axis]), float(origin[axis]), float(true[axis])
        jit.play_axis_from(rows, axis, starts, signs, bands, fresh, motor0, start, spm, out)
    return out


def run_bands(
    machine: Machine, axis: int, signs: npt.NDArray[np.int8], at: npt.NDArray[np.int64]
) -> FloatArray:
    """The backlash band of each run of ``axis``, motor steps (0 for an up run).

    ``signs`` and ``at`` are the runs' directions and the motor position ``(x, y)`` in
    steps where each starts (:func:`camtool.accel.kernels.play_runs`); the band is the
    profile's true backlash there (``Backlash.true_at``, regions included), as
    :func:`backlash_play` takes it.
    """
    true = machine.real_steps_per_mm
    return np.asarray(
        [
            machine.backlash.true_at(axis, at[k, 0] / true[0], at[k, 1] / true[1])
            / 1000.0
            * true[axis]
            if signs[k] < 0
            else 0.0
            for k in range(len(signs))
        ],
        dtype=np.float64,
    )


def backlash_play(
    steps: npt.NDArray[np.int8],
    motor: npt.NDArray[Any],
    axis: int,
    start: float,
    machine: Machine,
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
    out -= c0  # in place: the same floats as ``out - c0 + start``
    out += start
    return out
