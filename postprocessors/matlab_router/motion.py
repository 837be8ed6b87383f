"""Motion model of the Angel-11 DC-servo router (``matlab-router``): its ``servo`` simulator.

Design notes: docs/internals.md, ``postprocessors/matlab_router/motion.py``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Move, Program
from camtool.model.shapes import distance
from camtool.verify.contour_measures import contour_runs
from camtool.verify.interpolators import sagitta_chord_points
from camtool.verify.motion import MotionHooks, StepTrace
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import STEP_DTYPE, read_only
from camtool_postprocessors.matlab_router.arrays import points_01mm
from camtool_postprocessors.matlab_router.servo import (
    RouterMachine,
    apply_backlash,
    simulate_job,
)

REVERSAL_DEADBAND_MM = 0.001
"""Travel back from an axis's furthest point that counts as a reversal, mm (1 µm, 25.6
encoder counts): below it a servo's settling wobble is not a change of direction."""


def count_reversals(positions_mm: npt.ArrayLike, deadband_mm: float = REVERSAL_DEADBAND_MM) -> int:
    """Changes of direction of one axis along a sampled position, with a dead band.

    The axis reverses when it comes back more than ``deadband_mm`` from the
    furthest point of its current run (a hysteresis counter), so a stop at a
    vertex or a servo's wobble of less than the band is no reversal. The first
    run's direction is free: a program that only moves one way has 0.

    Args:
        positions_mm: ``(M,)`` positions of one axis, mm.
        deadband_mm: hysteresis, mm, ``> 0``.
    """
    values = np.asarray(positions_mm, dtype=np.float64)
    if len(values) < 2:
        return 0
    direction, low, high, count = 0, float(values[0]), float(values[0]), 0
    for x in values.tolist():
        if direction >= 0 and x > high:
            high = x
        if direction <= 0 and x < low:
            low = x
        if direction >= 0 and x < high - deadband_mm:
            count += direction > 0
            direction, low = -1, x
        elif direction <= 0 and x > low + deadband_mm:
            count += direction < 0
            direction, high = 1, x
    return count


def router_backlash_mm(machine: Machine) -> tuple[float, float]:
    """The X and Y dead bands the profile asks of the router, mm.

    Raises:
        InputError: the profile asks for what the router model cannot do: a
            compensation (the firmware has none) or backlash regions.
    """
    lash = machine.backlash
    where = f"machine {machine.name!r} [machine.backlash]"
    if any(lash.compensation_um[:2]):
        raise InputError(
            f"{where} compensation_um = {list(lash.compensation_um)}: the matlab-router "
            "firmware compensates no backlash (Angel-11 R15); set compensation_um to 0 in "
            "the --machine file (true_um alone is simulated as a dead band)"
        )
    if lash.regions:
        raise InputError(
            f"{where} regions: the matlab-router model has one dead band per axis "
            "(Angel-11 R15), not regions; give true_um = [x, y, 0] instead in the --machine file"
        )
    return (lash.true_um[0] / 1000.0, lash.true_um[1] / 1000.0)


def simulate_servo(program: Program, machine: Machine, *, sources: Sources = ALL) -> StepTrace:
    """Simulate ``program`` stroke by stroke on the Angel-11 router model.

    Args:
        program: moves in mm (rapids separate strokes).
        machine: a profile with ``[motion] line = "servo"``; its X steps/mm is the
            encoder's counts/mm; its ``[machine.backlash] true_um`` (X, Y) the dead
            bands applied to the positions (R15).
        sources: ``backlash`` off leaves the dead bands out (the error budget).

    Returns:
        A :class:`StepTrace` whose rows are servo samples and whose
        ``block_time_s`` holds each move's simulated time; ``reversals`` counted
        from the positions (:func:`count_reversals`).

    Raises:
        InputError: the profile asks for a backlash compensation or regions
            (:func:`router_backlash_mm`).
    """
    backlash = router_backlash_mm(machine)
    if not sources.backlash:
        backlash = (0.0, 0.0)
    router = RouterMachine(counts_per_mm=round(machine.steps_per_mm[0]))
    ts = router.ts_s
    first_speed_mm_s = router.first_point_speed * 200.0 / router.counts_per_mm
    points: list[np.ndarray] = []
    blocks: list[np.ndarray] = []
    times = np.zeros(len(program.moves))
    steps = np.zeros((len(program.moves), 3), dtype=np.int64)
    position = np.asarray(program.origin, dtype=np.float64)
    for first, last in _strokes(program):
        start = (
            (program.moves[first - 1].x, program.moves[first - 1].y) if first else program.origin
        )
        vertices, owner = _vertices(start, program.moves[first : last + 1], machine)
        owner = [first + o for o in owner]
        xy = points_01mm(np.asarray(vertices))
        if len(xy) < 2:
            continue
        for i, block in enumerate(owner):
            steps[block, :2] += np.abs(xy[i + 1] - xy[i]) * round(router.counts_per_mm / 10)
        trace = simulate_job(xy, router)
        if first:
            rapid = np.abs(trace.first_point_mm - position)
            times[first - 1] += float(rapid.sum()) / first_speed_mm_s  # X, then Y (R13)
            # where the positioning left the carriage: the rapid's one trace row, so the
            # stroke's measures start there (not at the end of the stroke before)
            points.append(np.asarray(trace.first_point_mm, dtype=np.float64).reshape(1, 2))
            blocks.append(np.full(1, first - 1, dtype=np.int64))
        for i, block in enumerate(owner):
            hi = int(trace.segment_end_sample[i])
            lo = int(trace.segment_end_sample[i - 1]) if i else 0
            points.append(trace.positions_mm[lo + 1 : hi + 1])
            blocks.append(np.full(hi - lo, block, dtype=np.int64))
            times[block] += (hi - lo) * ts
        position = trace.positions_mm[-1]
    carriage = np.vstack(points) if points else np.zeros((0, 2))
    if any(backlash) and len(carriage):
        carriage = np.asarray(apply_backlash(carriage, backlash), dtype=np.float64)
    block_of_row = np.concatenate(blocks) if blocks else np.zeros(0, dtype=np.int64)
    counts = np.bincount(block_of_row, minlength=len(program.moves)).astype(np.int64)
    n = len(carriage)
    return StepTrace(
        rows=read_only(np.zeros((n, 2), dtype=STEP_DTYPE)),
        compensation=read_only(np.zeros(n, dtype=np.bool_)),
        block_of_row=read_only(block_of_row),
        block_start=read_only(np.concatenate(([0], np.cumsum(counts))).astype(np.int64)),
        carriage_mm=read_only(carriage),
        start_mm=program.origin,
        logical_end=read_only(np.zeros((len(program.moves), 2), dtype=np.int64)),
        block_steps=read_only(steps),
        block_dominant=read_only(np.zeros(len(program.moves), dtype=np.int64)),
        block_compensation=read_only(np.zeros(len(program.moves), dtype=np.int64)),
        reversals=(count_reversals(carriage[:, 0]), count_reversals(carriage[:, 1])),
        compensations=0,
        block_time_s=read_only(times),
    )


def _strokes(program: Program) -> list[tuple[int, int]]:
    """``(first, last)`` indices of the runs of cutting moves."""
    return contour_runs(program)


def _vertices(
    start: tuple[float, float], moves: tuple[Move, ...], machine: Machine
) -> tuple[list[tuple[float, float]], list[int]]:
    """The stroke's vertices (arcs as chords) and, per segment, the move it belongs to."""
    vertices, owner = [start], []
    here = start
    for index, move in enumerate(moves):
        if isinstance(move, ArcMove):
            chords = sagitta_chord_points(here, move, machine.motion.chord_tolerance_mm)
        else:
            chords = [(move.x, move.y)]
        for point in chords:
            if distance(point, vertices[-1]) > 0:
                vertices.append(point)
                owner.append(index)
        here = (move.x, move.y)
    return vertices, owner


MOTION = MotionHooks(simulators={"servo": simulate_servo}, honours={"servo": ("backlash",)})
"""What ``matlab-router`` adds to the verifier: the ``servo`` line, a whole simulator (it
models the ``backlash`` error source)."""
