"""Motion model of the seed-002 DC-servo router (``matlab-router``): its ``servo`` simulator.

The router has no coordinated interpolator (seed-002 §4): each stroke is a job
of straight segments between vertices in whole 0.1 mm, every axis at its own
pre-scaled speed, moves floored to 0.2 mm chunks, a stop at every vertex
(:func:`camtool.verify.servo.simulate_job`). Here a program is cut into strokes
at its rapids; arcs (which the router's dialect never writes) become chords
within ``[motion] chord_tolerance_mm``. The result has the shape of a
:class:`~camtool.verify.motion.StepTrace` so that the same measures apply: one
"row" per 5 ms servo sample (no motor steps: ``rows`` are zeros, ``iterations``
counts samples), positions from the simulated encoders.

The move from home to each stroke's first point (homing, the X-then-Y dog-leg at
speed 500) is not simulated: a stroke starts at rest on its first vertex, and
its rapid is timed as that dog-leg (R13).
"""

from __future__ import annotations

import numpy as np

from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Move, Program
from camtool.model.shapes import distance
from camtool.verify.interpolators import sagitta_chord_points
from camtool.verify.metrics import contour_runs
from camtool.verify.motion import MotionHooks, StepTrace
from camtool.verify.steparray import STEP_DTYPE, read_only
from camtool_postprocessors.matlab_router_arrays import points_01mm
from camtool_postprocessors.matlab_router_motion_servo import RouterMachine, simulate_job


def simulate_servo(program: Program, machine: Machine) -> StepTrace:
    """Simulate ``program`` stroke by stroke on the seed-002 router model.

    Args:
        program: moves in mm (rapids separate strokes).
        machine: a profile with ``[motion] line = "servo"``; its X steps/mm is the
            encoder's counts/mm.

    Returns:
        A :class:`StepTrace` whose rows are servo samples and whose
        ``block_time_s`` holds each move's simulated time.
    """
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
        reversals=(0, 0),
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


MOTION = MotionHooks(simulators={"servo": simulate_servo})
"""What ``matlab-router`` adds to the verifier: the ``servo`` line, a whole simulator."""
