"""Per-contour measures of a trace: size errors, fitted circles, where each contour runs.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial

import numpy as np
import numpy.typing as npt

from camtool.model.program import Program, Rapid, segment_of
from camtool.model.shapes import Arc, BBox, Line, Point, Segment, bbox_union
from camtool.verify import deviations
from camtool.verify.circlefit import CircleFit

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class ContourMeasure:
    """One cut contour (a run of cutting moves between rapids), as machined.

    Attributes:
        number: 1-based, in cutting order.
        blocks: ``(first, last)`` program move indices.
        closed: the nominal contour ends where it starts.
        closure_um: ``(dx, dy)`` carriage end minus carriage start, µm (closed only).
        size_um: nominal bounding-box ``(width, height)``, µm.
        size_error_um: machined minus nominal ``(width, height)``, µm.
        circle: for a full circle, ``(nominal_diameter_mm, fitted_diameter_mm,
            horizontal_mm, vertical_mm)`` (least-squares fit, Kåsa 1976; extents
            as Yanez-07 R16 measures them), else ``None``.
    """

    number: int
    blocks: tuple[int, int]
    closed: bool
    closure_um: tuple[float, float] | None
    size_um: tuple[float, float]
    size_error_um: tuple[float, float]
    circle: tuple[float, float, float, float] | None


def contour_runs(program: Program) -> list[tuple[int, int]]:
    """``(first, last)`` move indices of each run of cutting moves between rapids."""
    runs: list[tuple[int, int]] = []
    first = None
    for i, move in enumerate(program.moves):
        if isinstance(move, Rapid):
            if first is not None:
                runs.append((first, i - 1))
            first = None
        elif first is None:
            first = i
    if first is not None:
        runs.append((first, len(program.moves) - 1))
    return runs


def measure_contours(
    points: FloatArray, block_start: IntArray, start_mm: Point, program: Program
) -> list[ContourMeasure]:
    """Closure, size error and circle fit of every cut contour.

    Args:
        points: ``(N, 2)`` float64 trace, mm.
        block_start: ``(B + 1,)`` offsets of each move's points in ``points``.
        start_mm: the carriage position before the first point.
        program: the program the trace executed.
    """
    measures = []
    starts = deviations.move_starts(program)
    for number, (first, last) in enumerate(contour_runs(program), start=1):
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        before = points[lo - 1] if lo > 0 else np.asarray(start_mm, dtype=np.float64)
        size = _extent(before, points, lo, hi)  # np.ptp of the run, without copying it
        last_point = points[hi - 1] if hi > lo else before
        radius_of = partial(_fitted_radius, before, points[lo:hi])
        measures.append(
            _contour_measure(
                program, starts, number, (first, last), before, last_point, size, radius_of
            )
        )
    return measures


def _contour_measure(
    program: Program,
    starts: Sequence[Point],
    number: int,
    blocks: tuple[int, int],
    before: FloatArray,
    last_point: FloatArray,
    size: tuple[float, float],
    radius_of: Callable[[Point], float | None],
) -> ContourMeasure:
    """One contour's :class:`ContourMeasure` from its trace's extent and ends.

    ``before`` is the carriage before the contour's first row, ``last_point`` after its
    last (``before`` without rows), ``size`` the trace's extent (:func:`_extent`) and
    ``radius_of(centre)`` the radius of the circle fitted to its whole trace about the
    nominal ``centre`` (:class:`~camtool.verify.circlefit.CircleFit`; asked only for a
    circle; ``None``: fewer than three points).
    """
    first, last = blocks
    segments = [segment_of(starts[i], program.moves[i]) for i in range(first, last + 1)]
    box: BBox = bbox_union(s.bbox() for s in segments)
    nominal_size = (box[2] - box[0], box[3] - box[1])
    closed = math.dist(starts[first], starts[last + 1]) <= 1e-6
    closure = (
        (
            float(last_point[0] - before[0]) * 1000.0,
            float(last_point[1] - before[1]) * 1000.0,
        )
        if closed
        else None
    )
    return ContourMeasure(
        number=number,
        blocks=(first, last),
        closed=closed,
        closure_um=closure,
        size_um=(nominal_size[0] * 1000.0, nominal_size[1] * 1000.0),
        size_error_um=(
            (size[0] - nominal_size[0]) * 1000.0,
            (size[1] - nominal_size[1]) * 1000.0,
        ),
        circle=_circle(segments, radius_of, size) if closed else None,
    )


def _circle_candidate(segments: list[Segment]) -> tuple[float, Point] | None:
    """Radius and centre of a contour made of arcs of one circle (:func:`_circle`), else None."""
    cuts = [s for s in segments if not (isinstance(s, Line) and s.length <= 1e-9)]
    if not cuts or not all(isinstance(s, Arc) for s in cuts):
        return None
    arcs = [s for s in cuts if isinstance(s, Arc)]
    c0, r0 = arcs[0].centre, arcs[0].radius
    same = all(math.dist(a.centre, c0) <= 1e-6 and abs(a.radius - r0) <= 1e-6 for a in arcs)
    turns = abs(sum(a.sweep for a in arcs)) / math.tau
    if not same or turns < 0.5 or abs(turns - round(turns)) > 1e-6:
        return None
    return r0, c0


def _fitted_radius(before: FloatArray, rows: FloatArray, centre: Point) -> float | None:
    """The radius of the circle fitted to ``before`` then ``rows`` (a contour's trace), mm."""
    fit = CircleFit(centre)
    fit.add(np.asarray(before, dtype=np.float64).reshape(1, 2))
    fit.add(rows)
    got = fit.result()
    return None if got is None else got[2]


def _extent(before: FloatArray, points: FloatArray, lo: int, hi: int) -> tuple[float, float]:
    """``np.ptp`` per axis of ``before`` followed by ``points[lo:hi]`` (max and min are exact)."""
    if hi <= lo:
        return (0.0, 0.0)
    out = []
    for axis in (0, 1):  # column by column: a reduction over axis 0 of (N, 2) is slow
        column = points[lo:hi, axis]
        top = max(float(column.max()), float(before[axis]))
        low = min(float(column.min()), float(before[axis]))
        out.append(top - low)
    return (out[0], out[1])


def _circle(
    segments: list[Segment],
    radius_of: Callable[[Point], float | None],
    size: tuple[float, float],
) -> tuple[float, float, float, float] | None:
    """Nominal and fitted diameter of a contour made of arcs of one circle, else None.

    ``radius_of(centre)`` gives the radius fitted to the contour's trace (the point
    before it first) about the nominal centre, asked only for a contour of arcs.

    Z-only moves (a plunge, a rise onto a tab: no XY length) do not count, and a circle
    cut in several depth passes (sweeps adding up to a whole number of turns) is one.
    """
    candidate = _circle_candidate(segments)
    if candidate is None:
        return None
    r0, centre = candidate
    radius = radius_of(centre)
    if radius is None:
        return None
    return (2.0 * r0, 2.0 * radius, size[0], size[1])
