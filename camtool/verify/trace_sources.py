"""A trace with some error sources switched off, and what each source does on a machine."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from camtool.accel.memo import LastAnswers
from camtool.model.errors import UsageError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Program, Rapid
from camtool.verify import budget as eb
from camtool.verify.contour_measures import ContourMeasure
from camtool.verify.deviations import move_starts
from camtool.verify.motion import StepTrace, library
from camtool.verify.simulate import (
    simulate_steps,
)
from camtool.verify.sources import ALL, Sources


def source_statuses(
    program: Program, machine: Machine, *, planned: Program | None = None
) -> list[eb.SourceStatus]:
    """Which error sources ``machine`` models for ``program`` (the budget's columns).

    The step simulator models interpolation always, chords when the profile cuts
    arcs into chords and the program has arcs, the scale when the true steps/mm
    differ from the nominal ones, backlash when the profile has some (true or
    compensated); ``dynamics`` when the machine's line piece models it. A target's
    whole simulator models what it honours (``MotionHooks.honours``). Rounding
    is known only with the unrounded plan.
    """
    lib = library(machine)
    line = machine.motion.line
    whole = lib.simulator(line) is not None
    honoured = set(lib.honours(line))
    arcs = any(isinstance(m, ArcMove) for m in program.moves)
    true = machine.real_steps_per_mm[:2]
    lash = machine.backlash
    present = {
        "interpolation": (True, ""),
        "chords": (
            arcs and machine.motion.arc == "chords",
            "no arcs in the program" if not arcs else "the controller runs arcs natively",
        ),
        "scale": (true != machine.steps_per_mm[:2], "the profile has no true steps/mm"),
        "backlash": (
            any(lash.true_um[:2]) or any(lash.compensation_um[:2]) or bool(lash.regions),
            "the profile has no backlash",
        ),
        "dynamics": (
            "dynamics" in honoured,
            f"the {line!r} motion models no timer overshoot or servo lag",
        ),
    }
    out = []
    for name, (there, why) in present.items():
        if whole and name not in honoured:
            out.append(eb.SourceStatus(name, "absent", f"not modelled by the {line!r} simulator"))
        elif there:
            out.append(eb.SourceStatus(name, "modelled"))
        else:
            out.append(eb.SourceStatus(name, "absent", why))
    if planned is None:
        out.append(eb.SourceStatus("rounding", "unknown", "not known from the code alone"))
    else:
        out.append(eb.SourceStatus("rounding", "modelled"))
    return out


EXACT_RADII_MM = 1e-9
"""Largest difference of an arc's start and end radius, mm, for which the controller with
``interpolation`` off runs the program's own circle (:func:`follows_program`); it blends
the two radii along the arc, which the program's circle does not (1e-9 mm is a thousandth
of the 0.0001 µm a report prints)."""


def follows_program(
    program: Program, machine: Machine, statuses: Sequence[eb.SourceStatus]
) -> bool:
    """Whether ``program`` simulated with ``interpolation`` off is the program itself.

    True when ``interpolation`` is the one source ``statuses`` model (no scale, backlash,
    chords, dynamics or rounding to leave in the trace), the machine's line runs on the
    step simulator (:func:`simulate`; a target's own simulator may model more), and every
    arc is a circle both in mm and in steps: equal steps/mm on X and Y, and its end on the
    circle of its start (:data:`EXACT_RADII_MM`). The ideal controller
    (:class:`~camtool.verify.simulate.IdealController`) then moves the carriage along the
    programmed lines and circles, unrounded, so that every figure of the budget is the
    program's own (:func:`ideal_figures`), with nothing to simulate.
    """
    modelled = [s.name for s in statuses if s.status == "modelled"]
    if modelled != ["interpolation"] or library(machine).simulator(machine.motion.line) is not None:
        return False
    arcs = [i for i, move in enumerate(program.moves) if isinstance(move, ArcMove)]
    if not arcs:
        return True
    if machine.steps_per_mm[0] != machine.steps_per_mm[1]:
        return False
    starts = move_starts(program)
    for i in arcs:
        move = program.moves[i]
        assert isinstance(move, ArcMove)
        x0, y0 = starts[i]
        r0 = math.hypot(x0 - move.cx, y0 - move.cy)
        r1 = math.hypot(move.x - move.cx, move.y - move.cy)
        if abs(r1 - r0) > EXACT_RADII_MM:
            return False
    return True


def ideal_figures(
    program: Program, contours: Sequence[ContourMeasure], *, along: bool
) -> eb.Figures:
    """The budget's figures of a program that its ideal trace follows exactly.

    The trace with ``interpolation`` off of a program that :func:`follows_program`: no
    deviation and no shortfall (the carriage is on the path and passes every point of
    it), each contour's extent and fitted circle the nominal ones (size and diameter
    errors 0), and a closed contour's closure gap the program's own (its end within 1e-6 mm
    of its start, :func:`~camtool.verify.contour_measures._contour_measure`). ``contours``
    are the verification's (the full model's), ``along``: whether it measured the
    shortfall. The re-simulation gives the same figures up to its sampling
    (:data:`~camtool.verify.simulate.IDEAL_SAMPLES_PER_STEP` rows a step: an arc's chords
    between them, ~0.01 µm on a 3 mm radius) and the rounding of its sums.
    """
    starts = move_starts(program)
    out: eb.Figures = {"max deviation": 0.0}
    if along:
        out["shortfall along the path"] = 0.0
    for c in contours[: eb.MAX_CONTOURS]:
        first, last = c.blocks
        if c.closure_um is not None:
            out[f"contour {c.number} closure gap"] = (
                math.dist(starts[first], starts[last + 1]) * 1000.0
            )
        out[f"contour {c.number} size error x"] = 0.0
        out[f"contour {c.number} size error y"] = 0.0
        if c.circle is not None:
            out[f"contour {c.number} diameter error"] = 0.0
    return out


def simulate(program: Program, machine: Machine, *, sources: Sources = ALL) -> StepTrace:
    """Simulate ``program`` on ``machine``: the simulator its ``line`` name selects.

    A ``line`` name that a target's ``MOTION.simulators`` holds runs that simulator
    (:meth:`camtool.verify.motion.Library.simulator`); any other runs the step
    simulator (:func:`camtool.verify.simulate.simulate_steps`) with the named
    interpolators.

    Args:
        program: moves in mm.
        machine: the machine profile.
        sources: the error sources modelled (:mod:`camtool.verify.sources`); a
            target's simulator gets them when it honours some
            (``MotionHooks.honours``), else only the full model can run on it.

    Raises:
        InputError: an unknown interpolator or chord rule name.
        UsageError: the profile lacks a parameter its line model needs, or
            ``sources`` switch off a source the machine's simulator does not model.
    """
    lib = library(machine)
    run = lib.simulator(machine.motion.line)
    if run is not None:
        if sources == ALL:
            return run(program, machine)
        honoured = lib.honours(machine.motion.line)
        if not set(sources.off) <= set(honoured):
            raise UsageError(
                f"the {machine.motion.line!r} simulator cannot switch off "
                f"{', '.join(sorted(set(sources.off) - set(honoured)))}"
            )
        return run(program, machine, sources=sources)  # type: ignore[call-arg]
    return simulate_steps(program, machine, sources=sources)


_NOMINAL: LastAnswers[tuple[np.ndarray, ...]] = LastAnswers(2)
"""The last two programs' :func:`_nominal_lines` (the code's and the plan's)."""


def _nominal_lines(program: Program) -> tuple[np.ndarray, ...]:
    """The programmed cutting path as polylines ``(M, 2)`` mm, one per run between rapids.

    The last two programs' lines are kept (read-only, the same tuple for the same
    program: the error budget compares the drawing once per source with the same program).
    """
    lines = _NOMINAL.get(program)
    if lines is None:
        lines = _nominal_lines_now(program)
        for line in lines:
            line.flags.writeable = False
        _NOMINAL.keep(lines, program)
    return lines


def _nominal_lines_now(program: Program) -> tuple[np.ndarray, ...]:
    """:func:`_nominal_lines` without the kept copy."""
    lines: list[list[tuple[float, float]]] = []
    fresh = True
    for move, seg in program.segments():
        if isinstance(move, Rapid):
            fresh = True
            continue
        pts = seg.points(0.0002)
        if fresh:
            lines.append(list(pts))
            fresh = False
        else:
            lines[-1].extend(pts[1:])
    return tuple(np.asarray(p, dtype=np.float64) for p in lines)
