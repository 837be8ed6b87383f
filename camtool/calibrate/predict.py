"""The verifier's prediction of every coupon measure, measured as the sheet says.

Design notes: docs/internals.md, ``camtool/calibrate/predict.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camtool.calibrate.coupon import Coupon, Feature, Measure, translated
from camtool.model.errors import DialectError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Move, Program
from camtool.model.shapes import Point, distance
from camtool.verify.motion import StepTrace
from camtool.verify.trace_sources import simulate

if TYPE_CHECKING:
    from camtool.post.base import Target


@dataclass(frozen=True, eq=False)
class ReadBack:
    """A feature as the controller reads it.

    Attributes:
        feature: the feature.
        program: the feature's code read back with the target's reader.
        spans: ``(first, stop)`` read-back move indices of each move of
            :attr:`Feature.moves` (lead then strokes): a dialect may split a move
            (a full circle into two arcs, an arc into chords).
    """

    feature: Feature
    program: Program
    spans: tuple[tuple[int, int], ...]

    def stroke_span(self, strokes: Sequence[int]) -> tuple[int, int]:
        """Read-back move range of the strokes ``strokes`` (consecutive indices)."""
        lead = len(self.feature.lead)
        return self.spans[lead + min(strokes)][0], self.spans[lead + max(strokes)][1]


def read_back(coupon: Coupon, target: Target) -> tuple[ReadBack, ...]:
    """Every feature of ``coupon`` posted through ``target`` and read back.

    Raises:
        DialectError: the target cannot write a feature, or its code does not keep a
            feature's moves (names the feature).
    """
    out = []
    for feature in coupon.features:
        program = feature.program()
        code = target.emit(program).code
        back = _aligned(feature, target.parse(code, source=f"coupon feature {feature.id}"))
        out.append(ReadBack(feature, back, _spans(feature, back)))
    return tuple(out)


def _aligned(feature: Feature, back: Program) -> Program:
    """``back`` starting where the feature starts.

    A reader does not know where the tool stood before the code (it reads from (0, 0)), and a
    relative dialect (or a block that moves Z alone) reads its positions from there: such a
    read-back is translated onto the feature's first point.
    """
    if not back.moves:
        return back
    first, got = feature.moves[0], back.moves[0]
    tol = 0.25 * _extent(feature.origin_mm, None, first)
    dx, dy = first.x - got.x, first.y - got.y
    if any(distance((m.x, m.y), (first.x, first.y)) <= tol for m in back.moves):
        dx = dy = 0.0  # absolute positions (the reader may add a move to the first point)
    moves = tuple(translated(m, dx, dy) for m in back.moves)
    return dataclasses.replace(back, moves=moves, origin=feature.origin_mm)


def _spans(feature: Feature, back: Program) -> tuple[tuple[int, int], ...]:
    """Which read-back moves make each move of the feature (matched by end point, in order)."""
    spans = []
    here: Point = feature.origin_mm
    z_here: float | None = None
    i = 0
    moves = back.moves
    for move in feature.moves:
        extent = _extent(here, z_here, move)
        if extent <= 4e-6:  # a move to where the tool is (Z 0 before a Z feature): may be dropped
            spans.append((i, i))
            z_here = move.z if move.z is not None else z_here
            continue
        tol = 0.25 * extent
        sweep = _Sweep(here, move)
        j = i
        z_back = _z_before(moves, i)
        while j < len(moves):
            z_back = moves[j].z if moves[j].z is not None else z_back
            if sweep.done(moves[j]) and _ends_at(moves[j], z_back, move, tol):
                break
            j += 1
        if j == len(moves):
            raise DialectError(
                f"coupon feature {feature.id}: the code read back does not reach "
                f"({move.x:g}, {move.y:g}) mm; this target cannot cut the coupon as drawn"
            )
        spans.append((i, j + 1))
        i = j + 1
        here = (move.x, move.y)
        z_here = move.z if move.z is not None else z_here
    return tuple(spans)


class _Sweep:
    """How far round an arc's centre the read-back moves have gone.

    A chorded full circle passes near its end point at its first chord.
    """

    def __init__(self, start: Point, move: Move) -> None:
        self.arc = move if isinstance(move, ArcMove) else None
        self.need = 0.0
        self.swept = 0.0
        if self.arc is not None:
            a0 = self._angle(start)
            a1 = self._angle((self.arc.x, self.arc.y))
            turn = (a0 - a1) if self.arc.clockwise else (a1 - a0)
            turn %= 2 * math.pi
            self.need = (turn or 2 * math.pi) - 0.05
            self.last = a0

    def _angle(self, p: Point) -> float:
        assert self.arc is not None
        return math.atan2(p[1] - self.arc.cy, p[0] - self.arc.cx)

    def done(self, back: Move) -> bool:
        if self.arc is None:
            return True
        a = self._angle((back.x, back.y))
        if isinstance(back, ArcMove):  # its own sense decides (a half circle is ±π)
            turn = ((self.last - a) if back.clockwise else (a - self.last)) % (2 * math.pi)
            turn = turn or 2 * math.pi
            self.swept += turn if back.clockwise == self.arc.clockwise else -turn
        else:
            step = (a - self.last + math.pi) % (2 * math.pi) - math.pi
            self.swept += -step if self.arc.clockwise else step
        self.last = a
        return self.swept >= self.need


def _z_before(moves: Sequence[Move], index: int) -> float | None:
    for move in reversed(moves[:index]):
        if move.z is not None:
            return move.z
    return None


def _extent(here: Point, z_here: float | None, move: Move) -> float:
    """How far a move goes (a full circle: its diameter), mm; 4e-6 for a move to nowhere.

    A first Z move from an unknown height counts as a move to nowhere.
    """
    if isinstance(move, ArcMove):
        return 2.0 * distance((move.cx, move.cy), here)
    dz = 0.0 if move.z is None or z_here is None else abs(move.z - z_here)
    return max(distance(here, (move.x, move.y)), dz, 4e-6)


def _ends_at(back: Move, z_back: float | None, move: Move, tol: float) -> bool:
    if distance((back.x, back.y), (move.x, move.y)) > tol:
        return False
    return move.z is None or (z_back is not None and abs(z_back - move.z) <= tol)


def predict(read: Sequence[ReadBack], machine: Machine) -> dict[str, float]:
    """Every measure of the read-back features simulated on ``machine``, mm, by measure id.

    Raises:
        InputError, UsageError: the machine profile cannot be simulated (the verifier's).
    """
    out: dict[str, float] = {}
    for item in read:
        trace = simulate(item.program, machine)
        for measure in item.feature.measures:
            out[measure.id] = measure_trace(item, trace, measure, machine)
    return out


def measure_trace(item: ReadBack, trace: StepTrace, measure: Measure, machine: Machine) -> float:
    """One measure on a feature's simulation, mm (see the module docstring)."""
    first, stop = item.stroke_span(measure.strokes)
    if measure.axis == 2:
        return _z_travel(item.program, trace, first, stop, machine)
    rows = slice(int(trace.block_start[first]), int(trace.block_start[stop]))
    before = _before(trace, rows.start)
    points = np.vstack([before[None, :], trace.carriage_mm[rows]])
    if measure.kind == "diameter":
        widths = []
        for angle in measure.angles_deg:
            u = np.array([math.cos(math.radians(angle)), math.sin(math.radians(angle))])
            p = points @ u
            widths.append(float(p.max() - p.min()))
        return float(np.mean(widths))
    along = points[:, measure.axis]
    if measure.kind == "length":
        return float(along.max() - along.min())
    return float(along[-1] - along[0])


def _before(trace: StepTrace, row: int) -> np.ndarray:
    if row > 0:
        return np.asarray(trace.carriage_mm[row - 1], dtype=np.float64)
    return np.asarray(trace.start_mm, dtype=np.float64)


def _z_travel(program: Program, trace: StepTrace, first: int, stop: int, machine: Machine) -> float:
    """Signed Z travel of read-back moves ``first:stop``: steps over the true Z steps/mm, mm."""
    total = 0
    z = _z_before(program.moves, first)
    for index in range(first, stop):
        new = program.moves[index].z
        if new is not None and z is not None and new < z:
            total -= int(trace.block_steps[index, 2])
        else:
            total += int(trace.block_steps[index, 2])
        z = new if new is not None else z
    return total / machine.real_steps_per_mm[2]
