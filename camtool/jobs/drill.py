"""A drill operation: the holes a selection names, drilled nearest first with a cycle each.

The holes are the circles of the selection (each as large as its drill, within the
operation's ``hole_tolerance``; a circle drawn in pieces, chained) and its points; each gets a
:class:`~camtool.model.program.DrillCycle` whose moves (:func:`camtool.model.drilling.expand`)
every dialect can write, and which LinuxCNC writes as its canned cycle.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

from camtool.geometry.chain import chain, joint_distance
from camtool.jobs.job import Operation, Tool
from camtool.model.drilling import expand
from camtool.model.errors import InputError
from camtool.model.program import Command, DrillCycle, Dwell, Move, Rapid
from camtool.model.shapes import Drawing, Point, circle_of
from camtool.toolpath.copies import one_way
from camtool.toolpath.options import PlanOptions


def drill_moves(
    drawing: Drawing,
    op: Operation,
    tool: Tool,
    options: PlanOptions,
    here: tuple[float, float, float | None],
    where: str,
) -> tuple[list[Move], list[tuple[int, Command]], int]:
    """A drill operation: a canned cycle at each hole, nearest first from ``here``.

    Returns the moves (a rise to the clearance first, then each cycle's moves expanded, the
    hole's number as their contour), the commands at move indices (each
    :class:`~camtool.model.program.DrillCycle` with its move count, its dwells) and the
    number of holes.

    Raises:
        InputError: a selected contour is no circle, or a hole's size is not the drill's
            within ``op.hole_tolerance``, naming ``where``, the contour and its layer.
    """
    holes = _holes(drawing, op, tool, joint_distance(options.chain_tolerance), where)
    assert options.depth is not None  # a drill operation's depth is required when loaded
    clearance = options.clearance
    moves: list[Move] = []
    commands: list[tuple[int, Command]] = []
    x, y, _ = here
    moves.append(Rapid(x, y, clearance))  # the rise (left out when the tool is up there)
    z = clearance
    peck = options.step_down if options.step_down is not None else None
    kind = (
        "drill"
        if peck is None or peck >= options.depth
        else ("peck" if op.peck == "retract" else "chip-break")
    )
    for n, (hx, hy) in enumerate(_nearest_first(holes, (x, y)), start=1):
        cycle = DrillCycle(
            kind,  # type: ignore[arg-type]
            hx,
            hy,
            -options.depth,
            options.safe_z,
            options.plunge_feed if options.plunge_feed_mm_min is not None else options.feed,
            peck_mm=None if kind == "drill" else peck,
            dwell_s=op.dwell_s if kind == "drill" else 0.0,
            retract="initial",
        )
        items = expand(cycle, (x, y, z))
        count = sum(1 for item in items if not isinstance(item, Dwell))
        commands.append((len(moves), dataclasses.replace(cycle, moves=count)))
        for item in items:
            if isinstance(item, Dwell):
                commands.append((len(moves), item))
            else:
                moves.append(dataclasses.replace(item, contour=n))
        x, y = hx, hy
        z = clearance
    return moves, commands, len(holes)


def _holes(drawing: Drawing, op: Operation, tool: Tool, joint_mm: float, where: str) -> list[Point]:
    """The centres of the holes a drill operation drills, each checked against its drill.

    The contours are chained first, ``joint_mm`` apart at most, as the planner chains
    them: a circle drawn as two ARCs is one hole, and so is a circle drawn twice (two
    copies of an ARC a hair short of 360° chain into a path out and back,
    :func:`~camtool.toolpath.copies.one_way`).
    """
    out: list[Point] = []
    for contour in one_way(chain(drawing.contours, joint_mm), joint_mm)[0]:
        circle = circle_of(contour)
        name = f"{contour.source or 'contour'} on layer {contour.layer!r}"
        if circle is None:
            raise InputError(
                f"{where} drills {name} at ({contour.start[0]:.4f}, {contour.start[1]:.4f}) "
                "mm, which is not a circle: a drill operation drills circles and points; cut "
                "it with a profile or pocket operation (or narrow the selection)"
            )
        (cx, cy), d = circle
        if abs(d - tool.diameter) > op.hole_tolerance + 1e-9:
            size = "larger" if d > tool.diameter else "smaller"
            raise InputError(
                f"{where}: hole {name} at ({cx:.4f}, {cy:.4f}) mm is {d:.4g} mm across, "
                f"{size} than the {tool.diameter:g} mm drill (hole_tolerance "
                f"{op.hole_tolerance:g} mm): "
                + (
                    'cut it with a profile operation (side = "inside") instead'
                    if d > tool.diameter
                    else "drill it with a smaller drill"
                )
            )
        out.append((cx, cy))
    out.extend(m.at for m in drawing.marks)
    return list(dict.fromkeys(out))


def _nearest_first(points: Sequence[Point], start: Point) -> list[Point]:
    """``points`` in nearest-neighbour order from ``start`` (ties: the earlier point)."""
    left = list(points)
    out: list[Point] = []
    here = start
    while left:
        k = min(range(len(left)), key=lambda i: (math.dist(here, left[i]), i))
        here = left.pop(k)
        out.append(here)
    return out
