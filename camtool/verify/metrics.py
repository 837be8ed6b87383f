"""Measure a simulated trace against the nominal toolpath and the drawing.

All inputs in mm, results in µm. A *trace* is the carriage (tool-centre)
position after each simulated iteration, ``(N, 2) float64``, with the index of
the program move each point belongs to. The nominal path of a move is its own
segment (line or arc) of the program read back from the code, so the
deviation of a point is its distance to the segment its block was cutting
(the contour error a machinist measures, UNAM-GMM §6 and Yanez-07 R16).
"""

from __future__ import annotations

import hashlib
import itertools
import math
import sys
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property, partial
from types import ModuleType
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from camtool import accel
from camtool.accel.pool import each_threaded
from camtool.model.program import ArcMove, Program, Rapid, segment_of
from camtool.model.shapes import Arc, BBox, Drawing, Line, Point, Segment, bbox_union
from camtool.model.units import fmt_num
from camtool.verify.circlefit import CircleFit

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class Deviation:
    """Largest and RMS distance of the trace from the nominal path.

    Attributes:
        max_um: largest distance, µm (0 when nothing was cut).
        rms_um: root mean square over the cutting points, µm.
        at_mm: ``(x, y)`` of the worst point, mm.
        block: index of the program move of the worst point (-1 when none).
        points: how many trace points were measured.
    """

    max_um: float
    rms_um: float
    at_mm: Point
    block: int
    points: int


@dataclass(frozen=True)
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


class _Starts(Sequence[Point]):
    """Where each move of a program starts, from one ``(B + 1, 2) float64`` array, mm.

    ``starts[i]`` is the point before move ``i`` (``starts[0]`` the program's origin,
    ``starts[B]`` the last move's end), as a tuple of floats: the moves' own values
    (a float64 holds a float exactly). 16 bytes a move, where a list of tuples took
    about 110.
    """

    def __init__(self, xy: FloatArray) -> None:
        self.xy = xy

    def __len__(self) -> int:
        return len(self.xy)

    def __getitem__(self, index: int) -> Point:  # type: ignore[override]
        return (float(self.xy[index, 0]), float(self.xy[index, 1]))


def move_starts(program: Program) -> Sequence[Point]:
    """The start of each move of ``program`` and the last one's end (see :class:`_Starts`)."""
    moves = program.moves
    xy = np.empty((len(moves) + 1, 2), dtype=np.float64)
    xy[0] = program.origin
    xy[1:, 0] = np.fromiter((m.x for m in moves), dtype=np.float64, count=len(moves))
    xy[1:, 1] = np.fromiter((m.y for m in moves), dtype=np.float64, count=len(moves))
    return _Starts(xy)


def nominal_arrays(program: Program) -> dict[str, FloatArray]:
    """Per-move nominal geometry as arrays of shape ``(B,)`` (mm; ``kind`` 0 line, 1 arc, 2 rapid).

    Keys: ``kind, x0, y0, x1, y1, cx, cy, r, a0, sweep``; ``a0`` is the start
    angle and ``sweep`` the signed sweep of arcs (radians, CCW positive).
    """
    rows = []
    start = program.origin
    for move in program.moves:
        end = (move.x, move.y)
        if isinstance(move, ArcMove):
            arc = segment_of(start, move)
            assert isinstance(arc, Arc)
            a0 = math.atan2(start[1] - move.cy, start[0] - move.cx)
            rows.append((1, *start, *end, move.cx, move.cy, arc.radius, a0, arc.sweep))
        else:
            kind = 2 if isinstance(move, Rapid) else 0
            rows.append((kind, *start, *end, 0.0, 0.0, 0.0, 0.0, 0.0))
        start = end
    table = np.asarray(rows, dtype=np.float64).reshape(-1, 10)
    names = ("kind", "x0", "y0", "x1", "y1", "cx", "cy", "r", "a0", "sweep")
    return {name: table[:, i] for i, name in enumerate(names)}


def point_distances(
    points: FloatArray, blocks: IntArray, nominal: dict[str, FloatArray]
) -> FloatArray:
    """Distance of each point to the nominal segment of its block, mm.

    Args:
        points: ``(N, 2)`` float64, mm.
        blocks: ``(N,)`` int64 move index of each point.
        nominal: :func:`nominal_arrays` of the program.

    Returns:
        ``(N,)`` float64 distances, mm (lines: to the segment; arcs: to the arc,
        i.e. the radial error inside the sweep, else to the nearer end point).
    """
    out = np.empty(len(points), dtype=np.float64)
    for lo in range(0, len(points), POINT_CHUNK):  # each point alone: the same floats
        part = slice(lo, lo + POINT_CHUNK)
        is_arc = nominal["kind"][blocks[part]] == 1
        for mask, measure in ((~is_arc, _to_lines), (is_arc, _to_arcs)):
            if mask.any():
                out[part][mask] = measure(points[part][mask], blocks[part][mask], nominal)
    return out


POINT_CHUNK = 1 << 16
"""Points :func:`point_distances` measures at once: its ~10 temporaries of ``N`` floats held
18 MB at the peak of the benchmark part's picture (369 000 cutting rows), now ~5 MB."""


def _to_lines(points: FloatArray, blocks: IntArray, nominal: dict[str, FloatArray]) -> FloatArray:
    """Distance of each point to its block's straight segment, mm."""
    x0, y0 = nominal["x0"][blocks], nominal["y0"][blocks]
    dx, dy = nominal["x1"][blocks] - x0, nominal["y1"][blocks] - y0
    px, py = points[:, 0] - x0, points[:, 1] - y0
    length2 = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(length2 > 0, (px * dx + py * dy) / length2, 0.0)
    np.clip(t, 0.0, 1.0, out=t)
    return np.hypot(px - t * dx, py - t * dy)


def _to_arcs(points: FloatArray, blocks: IntArray, nominal: dict[str, FloatArray]) -> FloatArray:
    """Distance of each point to its block's arc: radial inside the sweep, else to an end."""
    ux, uy = points[:, 0] - nominal["cx"][blocks], points[:, 1] - nominal["cy"][blocks]
    radial = np.abs(np.hypot(ux, uy) - nominal["r"][blocks])
    sweep = nominal["sweep"][blocks]
    angle = np.arctan2(uy, ux) - nominal["a0"][blocks]
    along = np.where(sweep >= 0, np.mod(angle, math.tau), np.mod(-angle, math.tau))
    inside = along <= np.abs(sweep) + 1e-12
    if inside.all():
        return radial
    px, py = points[:, 0], points[:, 1]
    ends = np.minimum(
        np.hypot(px - nominal["x0"][blocks], py - nominal["y0"][blocks]),
        np.hypot(px - nominal["x1"][blocks], py - nominal["y1"][blocks]),
    )
    return np.where(inside, radial, ends)


def deviation(points: FloatArray, blocks: IntArray, program: Program) -> Deviation:
    """Deviation of the cutting points of a trace from the program's nominal path.

    Points of rapid moves are not measured (a rapid has no nominal path). Rows are
    measured a block (or a run of short blocks) at a time, at most
    :data:`DEVIATION_CHUNK` rows at once, a long line with its segment's numbers as
    scalars: the same float operations per point as :func:`point_distances`, so the
    same distances (:func:`deviation_gathered` is the one-pass form, kept for
    comparison and for rows not in block order).

    Args:
        points: ``(N, 2)`` float64 trace, mm.
        blocks: ``(N,)`` int64 move index of each point.
        program: the program the trace executed.
    """
    nominal = nominal_arrays(program)
    bounds = _block_bounds(blocks, len(nominal["kind"]))
    if bounds is None:
        return _deviation_of(points, blocks, nominal)
    dist, pieces = _distances(points, blocks, nominal, bounds, 0)
    if len(dist) == 0:
        return Deviation(0.0, 0.0, (0.0, 0.0), -1, 0)
    worst = int(np.argmax(dist))
    row = _row_of(pieces, worst)
    max_mm = float(dist[worst])
    total = len(dist)
    np.multiply(dist, dist, out=dist)
    return Deviation(
        max_um=max_mm * 1000.0,
        rms_um=float(np.sqrt(np.mean(dist))) * 1000.0,
        at_mm=(float(points[row, 0]), float(points[row, 1])),
        block=int(blocks[row]),
        points=total,
    )


def _row_of(pieces: list[tuple[int, int]], index: int) -> int:
    """The row of ``dist[index]`` of :func:`_distances` (``pieces``: its measured pieces)."""
    piece = int(np.searchsorted([p[0] for p in pieces], index, side="right")) - 1
    return pieces[piece][1] + index - pieces[piece][0]


def _distances(
    points: FloatArray,
    blocks: IntArray,
    nominal: dict[str, FloatArray],
    bounds: IntArray,
    first: int,
    kernels: Any = None,
) -> tuple[FloatArray, list[tuple[int, int]]]:
    """Distances of the cutting rows of moves ``first, first + 1, ...`` to their moves, mm.

    ``bounds`` ``(b + 1,)`` are the row offsets (in ``points``) of the moves
    ``first .. first + b - 1``; every row of ``points`` belongs to one of them. Rows are
    measured a block (or a run of short blocks) at a time (see :func:`deviation`); with
    ``kernels`` (:mod:`camtool.accel.kernels`) a long line by the compiled
    :func:`camtool.accel.kernels.to_line` (the same floats as :func:`_to_line`).

    Returns:
        The distances of the cutting rows in row order, and the measured pieces
        ``(offset in the distances, first row)`` (:func:`_row_of`).
    """
    cutting = nominal["kind"][first : first + len(bounds) - 1] != 2
    kind = nominal["kind"]
    sizes = np.diff(bounds)
    total = int(sizes[cutting].sum())
    dist = np.empty(total, dtype=np.float64)
    pieces: list[tuple[int, int]] = []  # (offset in dist, first row) of each measured piece
    if total == 0:
        return dist, pieces
    at = 0
    pending = -1  # first row of a run of short cutting blocks not yet measured
    for i in range(len(sizes) + 1):
        b = first + i
        lo = int(bounds[i]) if i < len(sizes) else len(blocks)
        long_line = i < len(sizes) and cutting[i] and kind[b] == 0
        long_line = long_line and sizes[i] >= DEVIATION_LONG
        flush = i == len(sizes) or not cutting[i] or long_line
        if pending >= 0 and (flush or lo - pending >= DEVIATION_CHUNK):
            for c in range(pending, lo, DEVIATION_CHUNK):
                hi = min(lo, c + DEVIATION_CHUNK)
                dist[at : at + hi - c] = point_distances(points[c:hi], blocks[c:hi], nominal)
                pieces.append((at, c))
                at += hi - c
            pending = -1
        if i == len(sizes) or not cutting[i]:
            continue
        hi = int(bounds[i + 1])
        if long_line:
            ends = tuple(nominal[k][b] for k in ("x0", "y0", "x1", "y1"))
            for c in range(lo, hi, DEVIATION_CHUNK):
                top = min(hi, c + DEVIATION_CHUNK)
                if kernels is not None:
                    kernels.to_line(points[c:top], *ends, dist[at : at + top - c])
                else:
                    dist[at : at + top - c] = _to_line(points[c:top], *ends)
                pieces.append((at, c))
                at += top - c
        elif pending < 0 and hi > lo:
            pending = lo
    return dist, pieces


DEVIATION_CHUNK = 1 << 18
"""Most rows :func:`deviation` measures at once (about 100 bytes of temporaries each)."""
DEVIATION_LONG = 4096
"""Rows from which a line block is measured on its own, with scalar segment numbers."""


def _block_bounds(blocks: IntArray, count: int) -> IntArray | None:
    """Row offsets ``(count + 1,)`` of each block when ``blocks`` is in block order, else None."""
    if len(blocks) and (blocks[0] < 0 or blocks[-1] >= count):
        return None
    if len(blocks) > 1 and bool(np.any(blocks[1:] < blocks[:-1])):
        return None
    return np.searchsorted(blocks, np.arange(count + 1), side="left").astype(np.int64)


def _to_line(points: FloatArray, x0: float, y0: float, x1: float, y1: float) -> FloatArray:
    """:func:`_to_lines` for points of one block: its numbers as scalars, same floats."""
    dx, dy = x1 - x0, y1 - y0
    px, py = points[:, 0] - x0, points[:, 1] - y0
    length2 = dx * dx + dy * dy
    t = (px * dx + py * dy) / length2 if length2 > 0 else np.zeros(len(points))
    np.clip(t, 0.0, 1.0, out=t)
    return np.hypot(px - t * dx, py - t * dy)


def deviation_gathered(points: FloatArray, blocks: IntArray, program: Program) -> Deviation:
    """:func:`deviation` in one pass over gathered per-row segment numbers (the plain form).

    Same result; holds about 100 bytes per row at once.
    """
    return _deviation_of(points, blocks, nominal_arrays(program))


def _deviation_of(
    points: FloatArray, blocks: IntArray, nominal: dict[str, FloatArray]
) -> Deviation:
    cutting = nominal["kind"][blocks] != 2 if len(blocks) else np.zeros(0, dtype=bool)
    pts, blk = points[cutting], blocks[cutting]
    if len(pts) == 0:
        return Deviation(0.0, 0.0, (0.0, 0.0), -1, 0)
    dist = point_distances(pts, blk, nominal)
    worst = int(np.argmax(dist))
    return Deviation(
        max_um=float(dist[worst]) * 1000.0,
        rms_um=float(np.sqrt(np.mean(dist * dist))) * 1000.0,
        at_mm=(float(pts[worst, 0]), float(pts[worst, 1])),
        block=int(blk[worst]),
        points=len(pts),
    )


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
    starts = move_starts(program)
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


@dataclass(frozen=True)
class AlongPath:
    """The programmed path seen from the trace: what the tool never reached, where moves ended.

    :func:`deviation` measures how far the tool strays *from* the path; a move
    that stops short (an uncompensated backlash on a return leg) strays nowhere
    and is invisible to it. Here the path is sampled finely and each sample's
    distance to the trace of its own contour is taken (the directed Hausdorff
    distance from path to trace), and the carriage is compared with the
    programmed end of every cutting move and every contour.

    Attributes:
        shortfall_um: largest distance of the sampled cutting path from the
            trace of its contour, µm (0 when nothing was cut).
        shortfall_at_mm: the path point where it occurs, mm.
        shortfall_block: index of the move of that point (-1 when none).
        block_end_um: largest distance of the carriage, after a cutting move's
            last row, from the move's programmed end, µm.
        block_end_at_mm: the programmed end where it occurs, mm.
        block_end_block: index of that move (-1 when none).
        contour_end_um: ``(C,)`` the same at the end of each contour, µm.
        samples: path points measured.
    """

    shortfall_um: float
    shortfall_at_mm: Point
    shortfall_block: int
    block_end_um: float
    block_end_at_mm: Point
    block_end_block: int
    contour_end_um: tuple[float, ...]
    samples: int


NEAREST_TOLERANCE_MM = 1e-5
"""Largest error :func:`nearest_distances` accepts from its vertex bound, mm (0.01 µm)."""
NEAREST_ENDS = 4
"""Segment ends :func:`nearest_distances` looks at around each sample."""
NEAREST_CHUNK = 20_000
"""Samples :func:`nearest_distances` measures at once (memory ~ 1 kB each)."""
KD_WORKERS = -1
"""Threads of the k-d tree queries (scipy's ``workers``; -1: one per core). Each query is
answered alone, so the distances do not depend on it; only the wall time does."""


def _to_segments(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """``(N, K)`` distances of points ``p`` ``(N, 2)`` to segments ``a → b`` ``(N, K, 2)``."""
    ab = b - a
    ap = p[:, None, :] - a
    length2 = np.einsum("nkj,nkj->nk", ab, ab)
    t = np.divide(
        np.einsum("nkj,nkj->nk", ap, ab), length2, out=np.zeros_like(length2), where=length2 > 0
    )
    t = np.clip(t, 0.0, 1.0)
    off = ap - t[..., None] * ab
    return np.sqrt(np.einsum("nkj,nkj->nk", off, off))


def nearest_distances(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None = None
) -> FloatArray:
    """Distance of each sample to the nearest segment ``a[i] → b[i]``, mm.

    Exact to :data:`NEAREST_TOLERANCE_MM`. The segments owning the
    :data:`NEAREST_ENDS` nearest segment ends (a scipy k-d tree) give a distance
    ``d``; it is the true one when the k-th end lies farther than ``d + L/2``
    (``L`` the longest segment: a nearer segment has an end within that), or
    when the nearest end ``r`` bounds it tightly, ``sqrt(r² − L²/4) ≤ d``
    (a segment whose ends are both ``r`` or more away comes no nearer than
    that). Samples neither test settles get shapely's exact nearest query.

    With numba (:func:`near_kernels`), the nearest ends come from
    :func:`camtool.accel.nearkernels.knn`, the k-d tree's answer bit for bit
    (where it cannot say so, from the k-d tree itself); the plain form is
    :func:`nearest_distances_kd`, kept for comparison.

    Args:
        samples: ``(N, 2)`` query points, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm (``a[i] == b[i]``: a point).
        ends: the k-d tree of ``concatenate([a, b])`` when the caller measures several
            batches against the same segments (built here otherwise; the same answers).

    Returns:
        ``(N,)`` float64 distances, mm (``inf`` without segments).
    """
    return _nearest(samples, a, b, ends=ends, only_max=False)


def farthest_nearest(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None = None
) -> tuple[float, int]:
    """``max`` and first ``argmax`` of :func:`nearest_distances`, the same two numbers.

    Only the largest distance is wanted (the shortfall of a path from its trace), so a
    sample the cheap tests leave unsure is measured exactly only when it could reach
    the largest one settled (its distance to the segments of its nearest ends is an
    upper bound); the others cannot be the largest, nor tie with it.

    Args:
        samples: ``(N, 2)`` query points, mm, ``N >= 1``.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        ends: as for :func:`nearest_distances`.

    Returns:
        ``(distance mm, index)`` of the first sample farthest from the segments.
    """
    d = _nearest(samples, a, b, ends=ends, only_max=True)
    k = int(np.argmax(d))
    return float(d[k]), k


def _reaching(upper: FloatArray, settled: FloatArray, samples: FloatArray) -> npt.NDArray[np.bool_]:
    """Which unsure samples (distance at most ``upper``) may reach the largest ``settled``.

    A sample's exact distance is at most ``upper`` (the segments of its nearest ends)
    up to the rounding of two formulas for one distance: a few ulps of the distance,
    and near a segment a few ulps of the coordinates. The margin (a billionth, plus
    1e-12 mm and 64 ulps of the largest coordinate of ``samples``) covers both, so a
    sample left out is strictly below the largest settled distance, which is at most
    the largest of all.
    """
    if len(settled) == 0:
        return np.ones(len(upper), dtype=bool)
    top = float(np.max(settled))
    slack = 1e-12 + 64.0 * float(np.spacing(np.max(np.abs(samples))))
    return np.asarray(upper * (1.0 + 1e-9) + slack >= top)


def _nearest(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None, only_max: bool
) -> FloatArray:
    """:func:`nearest_distances`; with ``only_max``, exact only where it can be the largest.

    With ``only_max`` an unsure sample that cannot reach the largest settled distance
    keeps its upper bound (:func:`_reaching`): the array's max and argmax are exact.
    """
    search = _box_search(samples, a, b, ends)
    if search is None:
        return _nearest_kd(samples, a, b, ends=ends, only_max=only_max)
    ends = ends or _LazyTree(search.points)
    d = np.empty(len(samples), dtype=np.float64)
    unsure = np.zeros(len(samples), dtype=bool)
    for i in range(0, len(samples), NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        near, rk, lower, ask = search.measure(part)
        if ask.any():  # ends tie at the k-th distance and the k-d tree's choice matters
            rows = np.flatnonzero(ask) + i
            near[rows - i] = search.chosen(ends, rows)
        d[part] = near
        unsure[part] = ~search.settled(near, rk, lower)
    return _settle_unsure(
        search.samples, d, unsure, search.a, search.b, search.nearby, only_max=only_max
    )


@dataclass(frozen=True, eq=False)
class _BoxSearch:
    """The compiled nearest search of some samples among segments ``a → b`` (:func:`_box_search`).

    Attributes:
        samples: ``(N, 2)`` the query points, C-contiguous float64, mm.
        a: ``(M, 2)`` segment starts, likewise.
        b: ``(M, 2)`` segment ends, likewise.
        half: half the longest segment, mm.
        points: ``concatenate([a, b])``, the ends (as the k-d tree of ties holds them).
        tree: their search tree (:func:`_ends_tree`).
        kernels: :mod:`camtool.accel.nearkernels`.
    """

    samples: FloatArray
    a: FloatArray
    b: FloatArray
    half: float
    points: FloatArray
    tree: tuple[Any, ...]
    kernels: ModuleType

    def measure(self, part: slice) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
        """``near``, ``rk``, ``lower`` and ``ask`` of the samples ``part``.

        :func:`camtool.accel.nearkernels.near_segments`' distance to the segments of the
        nearest ends (unset where ``ask``: the k-d tree's choice among tied ends matters),
        the k-th end's distance and the vertex bound ``sqrt(r0² − half²)``, with the
        square roots the k-d tree takes.
        """
        near, r0_2, rk_2, ask = self.kernels.near_segments(
            self.samples[part], *self.tree, self.a, self.b, NEAREST_ENDS
        )
        lower = np.sqrt(np.maximum(np.sqrt(r0_2) ** 2 - self.half * self.half, 0.0))
        return near, np.sqrt(rk_2), lower, ask

    def chosen(self, ends: _LazyTree, rows: IntArray) -> FloatArray:
        """The distance of samples ``rows`` to the segments of the ends the k-d tree keeps."""
        x = self.samples[rows]
        found = ends.tree.query(x, k=NEAREST_ENDS, workers=KD_WORKERS)[1]
        seg = np.asarray(found).reshape(-1, NEAREST_ENDS) % len(self.a)
        return _to_segments(x, self.a[seg], self.b[seg]).min(axis=1)

    def settled(self, near: FloatArray, rk: FloatArray, lower: FloatArray) -> Any:
        """Where ``near`` is the distance (:func:`nearest_distances`' two tests)."""
        return (near + self.half < rk) | (near - lower <= NEAREST_TOLERANCE_MM)

    def nearby(self, samples: FloatArray, upper: FloatArray, need: Any = None) -> FloatArray | None:
        """:func:`_nearby_boxes` among these segments."""
        return _nearby_boxes(
            samples, upper, self.a, self.b, self.tree, self.half, self.kernels, need
        )


def _box_search(
    samples: FloatArray, a: FloatArray, b: FloatArray, ends: _LazyTree | None = None
) -> _BoxSearch | None:
    """The compiled search of ``samples`` among ``a → b``, or ``None`` for the k-d tree path.

    ``None`` without the compiled search (:func:`near_kernels`: numba missing, or too few
    samples in this process so far), for fewer than :data:`NEAREST_ENDS` ends, and for
    many samples near the segments (:func:`_far`), which the k-d tree answers faster.
    Both paths give the same distances. ``ends``: the segments' ends
    (``concatenate([a, b])``, C-contiguous float64) with the search trees already built
    for other samples; built here otherwise.
    """
    kernels = near_kernels(len(samples))
    if kernels is None or len(a) == 0 or 2 * len(a) <= NEAREST_ENDS:
        return None
    samples = np.ascontiguousarray(samples, dtype=np.float64)
    if ends is None:
        a = np.ascontiguousarray(a, dtype=np.float64)
        b = np.ascontiguousarray(b, dtype=np.float64)
        ends = _LazyTree(_end_points(a, b))
    else:
        a, b = _halves(np.ascontiguousarray(ends.points, dtype=np.float64))
    half = ends.half()
    many = len(samples) > BOX_TREE_UP_TO
    if many and not _far(samples, ends.boxes(len(samples), kernels, any_built=True), half, kernels):
        return None
    tree = ends.boxes(len(samples), kernels)
    return _BoxSearch(samples, a, b, half, ends.points, tree, kernels)


def farthest_off(samples: FloatArray, a: FloatArray, b: FloatArray, offset: float) -> float:
    """``max(|nearest_distances(samples, a, b) - offset|)``: the same float.

    For a caller that needs only the largest offset distance (the error budget's
    distance to the drawing: ``offset`` is the tool radius). The compiled search of
    :func:`_nearest` settles most samples; the others are made exact as it makes them
    only where they can reach the largest value, given bounds on their distance: at
    most the segment distance found (a sample its tests leave unsure) or the k-th end's
    distance (a sample where the k-d tree's choice among tied ends matters: every
    segment it can keep has an end that near), at least ``sqrt(r0² − L²/4)`` (``r0``
    the nearest end, ``L`` the longest segment), each widened by a billionth, 1e-12 mm
    and 64 ulps of the largest coordinate for the rounding of two formulas. So the k-d
    tree of every end is built only when a tied sample can be the largest: on issue
    17's benchmark part none can, which spares a budget worker that tree (~0.3 s).

    The exact stage gets what :func:`_settle_unsure` gets in :func:`_nearest` (the same
    unsure samples, so the same choice between its two ways of measuring), so a tied
    sample is left out only when it is sure whatever the k-d tree keeps (its upper bound
    passes the vertex test); one that may end unsure is asked the k-d tree as
    :func:`_nearest` asks it. Where :func:`_nearest` takes the k-d tree path
    (:func:`_box_search` gives none), every distance is measured on it.

    Args:
        samples: ``(N, 2)`` query points, mm, ``N >= 1``.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        offset: subtracted from each distance, mm.
    """
    search = _box_search(samples, a, b)
    if search is None:
        return _largest_off(_nearest_kd(samples, a, b, ends=None, only_max=False), offset)
    n = len(samples)
    d, lower, kth = np.empty(n), np.empty(n), np.empty(n)
    ask = np.zeros(n, dtype=bool)
    for i in range(0, n, NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        d[part], kth[part], lower[part], ask[part] = search.measure(part)
    sure = ~ask & search.settled(d, kth, lower)
    best = _largest_off(d[sure], offset)
    slack = 1e-12 + 64.0 * float(np.spacing(np.max(np.abs(search.samples))))
    low = lower * (1.0 - 1e-9) - slack
    high = kth * (1.0 + 1e-9) + slack
    surely = high - lower <= NEAREST_TOLERANCE_MM  # sure whatever the k-d tree keeps
    asked = ask & (~surely | _can_reach(high, low, offset, best))
    if asked.any():  # the k-d tree's choice, as _nearest takes it
        rows = np.flatnonzero(asked)
        d[rows] = search.chosen(_LazyTree(search.points), rows)
        sure[rows] = search.settled(d[rows], kth[rows], lower[rows])
        best = max(best, _largest_off(d[rows[sure[rows]]], offset))
    unsure = ~sure & (asked | ~ask)
    if unsure.any():  # _settle_unsure's exact stage, only where a distance can be the largest
        need = _can_reach(d[unsure] * (1.0 + 1e-9) + slack, low[unsure], offset, best)
        x = search.samples[unsure]
        exact = search.nearby(x, d[unsure], need)
        if exact is None:
            exact = _all_exact_where(x, d[unsure], search.a, search.b, need)
        best = max(best, _largest_off(exact[need], offset))
    return best


def _can_reach(
    upper: FloatArray, lower: FloatArray, offset: float, best: float
) -> npt.NDArray[np.bool_]:
    """Where a distance within ``[lower, upper]`` may be ``offset`` ± at least ``best``."""
    return np.asarray((upper - offset >= best) | (offset - lower >= best))


def _largest_off(distances: FloatArray, offset: float) -> float:
    """``max(|distances - offset|)`` (``-inf`` for none)."""
    return float(np.max(np.abs(distances - offset))) if len(distances) else -math.inf


MERGE_ENDS_PER_SAMPLE = 16
"""Ends per sample up to which :func:`_ends_tree` merges the ends at one point into a place."""


def _ends_tree(points: FloatArray, samples: int, kernels: ModuleType) -> tuple[Any, ...]:
    """The search tree of the segment ends ``points`` (``concatenate([a, b])``) for ``samples``.

    :func:`camtool.accel.nearkernels.tree`, its places along the segments. The ends at
    one point are one place for at least one sample per :data:`MERGE_ENDS_PER_SAMPLE`
    ends: the 737 736 ends of the benchmark part are 115 838 places (two segments
    meet at each, and the part is cut in three passes), and the drawing's search takes
    about a fifth of the time; a few samples against a long trace (the shortfall's
    unsure ones) search every end instead of paying for the merge. The answers are the
    same.
    """
    merge = len(points) <= MERGE_ENDS_PER_SAMPLE * samples
    return tuple(kernels.tree(points, segments=True, merge=merge))


def _near_segments_numpy(
    chunk: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    kernels: ModuleType,
) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """:func:`camtool.accel.nearkernels.near_segments` with numpy's segment distances.

    The form it replaced (its :func:`_tied` and :func:`_to_segments` in numpy), kept
    as the tests' reference: the same ``near``, ``r0_2``, ``rk_2`` and ``ask``.
    """
    k = NEAREST_ENDS
    r0_2, rk_2, index, state = kernels.knn(chunk, *tree, k)
    seg = index % len(a)
    near = _to_segments(chunk, a[seg], b[seg]).min(axis=1)
    ask = np.zeros(len(chunk), dtype=bool)
    tied = state != 0
    if tied.any():
        near[tied], asks = _tied(chunk[tied], rk_2[tied], a, b, tree, kernels)
        ask[np.flatnonzero(tied)[asks]] = True
    return near, r0_2, rk_2, ask


def _tied(
    samples: FloatArray,
    kth2: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    kernels: ModuleType,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """The k-d tree's ``d`` where ends tie at the k-th distance, when its choice cannot matter.

    The k-d tree keeps every end nearer than the k-th distance (``S``) and some of those
    exactly at it (``T``); ``d`` is the least segment distance over what it keeps. With
    ``V`` the least over ``S`` and ``T``: when ``S`` reaches ``V``, or so many ends of
    ``T`` reach it that any choice keeps one, ``d`` is ``V`` whatever it chose.

    Returns:
        ``d`` ``(U,)`` and ``(U,)`` True where the choice matters (``d`` is then unset).
    """
    least = np.empty(len(samples), dtype=np.float64)
    settled = np.empty(len(samples), dtype=bool)
    for i in range(0, len(samples), TIED_CHUNK):  # ~1.5 kB per sample at once
        part = slice(i, i + TIED_CHUNK)
        found, d2, count = kernels.within(samples[part], *tree, kth2[part])
        cap = found.shape[1]
        width = max(1, min(cap, int(count.max())))  # the columns any sample fills
        found, d2 = found[:, :width], d2[:, :width]
        valid = np.arange(width)[None, :] < count[:, None]
        seg = found % len(a)
        values = _to_segments(samples[part], a[seg], b[seg])
        values[~valid] = np.inf
        nearer = valid & (d2 < kth2[part, None])
        at = valid & (d2 == kth2[part, None])
        low = values.min(axis=1)
        low_nearer = np.where(nearer, values, np.inf).min(axis=1)
        pick = NEAREST_ENDS - nearer.sum(axis=1)
        reaching = (at & (values == low[:, None])).sum(axis=1)
        least[part] = low
        settled[part] = (count <= cap) & ((low_nearer == low) | (at.sum(axis=1) - reaching < pick))
    return least, ~settled


TIED_CHUNK = 2_000
"""Samples :func:`_tied` measures at once."""


class _LazyTree:
    """The search structures of some points, each built when first asked for.

    scipy's k-d tree (:attr:`tree`) and, for segment ends ``concatenate([a, b])``
    (:func:`_end_points`), the compiled search's trees (:meth:`boxes`) and half the
    longest segment (:meth:`half`): the batches of samples measured against one trace
    share them instead of building them once a batch.
    """

    def __init__(self, points: FloatArray) -> None:
        self.points = points
        self._tree: Any = None
        self._boxes: dict[bool, tuple[Any, ...]] = {}
        self._half: float | None = None

    @property
    def tree(self) -> Any:
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(self.points)
        return self._tree

    def half(self) -> float:
        """Half the longest of the segments ``a[i] → b[i]`` whose ends these points are, mm."""
        if self._half is None:
            a, b = _halves(self.points)
            self._half = float(np.max(np.hypot(*(b - a).T))) / 2.0
        return self._half

    def boxes(
        self, samples: int, kernels: ModuleType, *, any_built: bool = False
    ) -> tuple[Any, ...]:
        """:func:`_ends_tree` of these segment ends for ``samples`` samples.

        ``any_built``: a tree built already for another number of samples will do (the
        same answers, :func:`_ends_tree`).
        """
        merge = len(self.points) <= MERGE_ENDS_PER_SAMPLE * samples
        if any_built and self._boxes:
            return next(iter(self._boxes.values()))
        if merge not in self._boxes:
            self._boxes[merge] = _ends_tree(self.points, samples, kernels)
        return self._boxes[merge]


def _halves(points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(a, b)`` of segment ends ``concatenate([a, b])`` (views)."""
    n = len(points) // 2
    return points[:n], points[n:]


NEAR_KERNELS_FROM = 500_000
"""Samples :func:`nearest_distances` has measured in this process (this call's included)
from which it loads the numba search: loading numba and its cache costs about 0.5 s and
100 MB once, the search saves about 1–3 µs a sample (most far from the trace, a drawing
point against the tool-centre path), so a small part (the logo) keeps the k-d tree."""
_NEAR_KERNELS: dict[str, ModuleType | None] = {}
_NEAR_WORK = [0]


def near_kernels(work: int = NEAR_KERNELS_FROM) -> ModuleType | None:
    """:mod:`camtool.accel.nearkernels` once the samples asked for reach the threshold.

    ``work``: the samples the caller is about to measure, added to those before
    (:data:`NEAR_KERNELS_FROM`; the default loads at once). ``None`` before that, with
    ``CAMTOOL_ACCEL=0`` and without numba; :func:`nearest_distances_kd` then answers, the same.
    """
    if not accel.enabled():
        return None
    if "kernels" in _NEAR_KERNELS:
        return _NEAR_KERNELS["kernels"]
    _NEAR_WORK[0] += work
    if _NEAR_WORK[0] < NEAR_KERNELS_FROM:
        return None
    kernels: ModuleType | None
    try:
        from camtool.accel import nearkernels as kernels
    except ImportError:
        kernels = None
    _NEAR_KERNELS["kernels"] = kernels
    return kernels


def nearest_distances_kd(samples: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """:func:`nearest_distances` with the nearest ends from scipy's k-d tree (the plain form)."""
    return _nearest_kd(samples, a, b, ends=None, only_max=False)


def _nearest_kd(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None, only_max: bool
) -> FloatArray:
    """:func:`nearest_distances_kd` (``ends``, ``only_max``: as for :func:`_nearest`)."""
    if len(a) == 0:
        return np.full(len(samples), np.inf)
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0 if ends is None else ends.half()
    tree = (ends or _LazyTree(_end_points(a, b))).tree
    d = np.empty(len(samples), dtype=np.float64)
    unsure = np.empty(len(samples), dtype=bool)
    for i in range(0, len(samples), NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        d[part], unsure[part] = _nearest_chunk(samples[part], a, b, tree, half)
    nearby = partial(_nearby_exact, a=a, b=b, ends=tree, half=half)
    return _settle_unsure(samples, d, unsure, a, b, nearby, only_max=only_max)


BOX_TREE_UP_TO = 20_000
"""Samples up to which :func:`_nearest` asks the box tree it has built whether or not they
lie far from the segments (:func:`_far`): the shortfall's few unsure samples
(:class:`_Bounded`) search it in milliseconds, where a k-d tree would be built for them
(and scipy loaded, ~0.3 s). Both give the same distances; only the time depends on it."""
FAR_PROBE = 1000
"""Samples :func:`_far` looks at (evenly spread)."""
FAR_RATIO = 8.0
"""Median nearest-end distance, in half the longest segment, from which the box tree
searches (:func:`_far`)."""


def _far(samples: FloatArray, tree: tuple[Any, ...], half: float, kernels: ModuleType) -> bool:
    """Whether the samples lie far from the segments for their length: the box tree's case.

    The compiled box tree answers a sample a tool radius from a dense trace (a drawing
    point against the tool-centre path) 2–3× faster than scipy's k-d tree, but one near
    the trace (a path sample, a drawing cut on its line) several times slower: a LibreCAD
    hatch cut on the line took 13.6 s in the box tree and 2.0 s in the k-d tree. The
    median distance of :data:`FAR_PROBE` samples to their nearest end, against half the
    longest segment (:data:`FAR_RATIO`), decides. Both give the same distances; only the
    time depends on it.
    """
    probe = np.ascontiguousarray(samples[:: max(1, len(samples) // FAR_PROBE)])
    r0_2 = kernels.knn(probe, *tree, 1)[0]
    return bool(np.median(r0_2) > (FAR_RATIO * half) ** 2)


def _settle_unsure(
    samples: FloatArray,
    d: FloatArray,
    unsure: npt.NDArray[np.bool_],
    a: FloatArray,
    b: FloatArray,
    nearby: Callable[..., FloatArray | None],
    *,
    only_max: bool,
) -> FloatArray:
    """The exact stage of both searches: GEOS's distance where the cheap tests were unsure.

    ``nearby(samples, upper, need=...)`` measures the segments near each unsure sample
    (:func:`_nearby_boxes` or :func:`_nearby_exact`, ``None`` over the pair limit, then
    :func:`_all_exact_where`); with ``only_max`` only the samples that can be the largest
    (:func:`_reaching`). ``d`` is updated in place and returned.
    """
    if unsure.any():
        need = _reaching(d[unsure], d[~unsure], samples) if only_max else None
        exact = nearby(samples[unsure], d[unsure], need=need)
        if exact is None:
            exact = _all_exact_where(samples[unsure], d[unsure], a, b, need)
        d[unsure] = exact
    return d


def _all_exact_where(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    need: npt.NDArray[np.bool_] | None,
) -> FloatArray:
    """:func:`_all_exact` of the samples ``need`` names (all when ``None``); ``upper`` elsewhere."""
    if need is None:
        return _all_exact(samples, a, b)
    out = upper.copy()
    if need.any():
        out[need] = _all_exact(samples[need], a, b)  # GEOS answers each sample alone
    return out


def _all_exact(samples: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """The GEOS distance (shapely) from each sample to the nearest of all segments, mm.

    What :func:`nearest_distances` gave before :func:`_nearby_exact` (its fallback, and
    the reference the tests compare it with, bit for bit).

    The samples are asked :data:`ALL_EXACT_CHUNK` at a time against one tree, a chunk
    per core at once (shapely releases the GIL while GEOS works): GEOS answers each
    point alone, so the distances are those of one query of them all, while only a few
    chunks' point geometries (~100 bytes each) exist at once (5.9 M unsure samples of a
    213-icon drawing took 1.3 GB in one query).
    """
    import shapely

    tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
    out = np.empty(len(samples), dtype=np.float64)

    def nearest(lo: int) -> None:
        points = shapely.points(samples[lo : lo + ALL_EXACT_CHUNK])
        _, exact = tree.query_nearest(points, return_distance=True, all_matches=False)
        out[lo : lo + len(points)] = exact

    each_threaded(nearest, range(0, len(samples), ALL_EXACT_CHUNK))  # each fills its rows
    return out


ALL_EXACT_CHUNK = 1 << 16
"""Samples :func:`_all_exact` asks GEOS's nearest query at once (memory, not the answer)."""


NEARBY_MAX_PAIRS = 4_000_000
"""Most (sample, segment) pairs :func:`_nearby_exact` measures; beyond it :func:`_all_exact`."""


def _nearby_exact(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    ends: Any,
    half: float,
    need: npt.NDArray[np.bool_] | None = None,
) -> FloatArray | None:
    """:func:`_all_exact` over only the segments that can be the nearest, or ``None``.

    A segment lies within ``L/2 <= half`` of one of its ends, so one whose ends are both
    farther than ``upper + half`` from a sample lies farther than ``upper``, the distance
    to a segment already found: it cannot be the nearest. The same GEOS distance is
    taken over the rest, so the minimum is the one :func:`_all_exact` finds, without
    building a tree of every segment for a few samples. ``None`` when the segments near
    the samples are too many (over :data:`NEARBY_MAX_PAIRS` pairs).

    Args:
        samples: ``(U, 2)`` query points, mm.
        upper: ``(U,)`` distance of each to some segment ``a → b``, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        ends: the k-d tree of ``concatenate([a, b])``.
        half: half the longest segment, mm.
        need: ``(U,)`` the samples to measure (``None``: all); the others keep ``upper``.
            The limit counts the pairs of all samples, so which of the two ways gives a
            sample's distance does not depend on ``need``.
    """
    reach = (upper + half) * (1.0 + 1e-9) + 1e-12  # a float margin: never leaves one out
    counts = _counts_within(ends, samples, reach)
    if counts is None:
        return None
    if counts.min() == 0:
        return None  # cannot happen (the segment of ``upper`` is within reach): be safe
    if need is not None:
        out = upper.copy()
        if need.any():
            out[need] = _nearby_pairs(samples[need], reach[need], counts[need], a, b, ends)
        return out
    return _nearby_pairs(samples, reach, counts, a, b, ends)


def _counts_within(ends: Any, samples: FloatArray, reach: FloatArray) -> IntArray | None:
    """How many ends lie within ``reach`` of each sample, or ``None`` over the pair limit.

    Counted :data:`NEARBY_COUNT_CHUNK` samples at a time (scipy's count holds a list per
    sample while it runs: ~400 MB for 5.9 M samples in one call), stopping as soon as the
    running total passes :data:`NEARBY_MAX_PAIRS`: the answer of one count of them all.
    """
    parts: list[IntArray] = []
    total = 0
    for lo in range(0, len(samples), NEARBY_COUNT_CHUNK):
        part = slice(lo, lo + NEARBY_COUNT_CHUNK)
        near = ends.query_ball_point(
            samples[part], reach[part], return_length=True, workers=KD_WORKERS
        )
        total += int(np.sum(near))
        if total > NEARBY_MAX_PAIRS:
            return None
        parts.append(np.asarray(near, dtype=np.int64))
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


NEARBY_COUNT_CHUNK = 1 << 16
"""Samples :func:`_counts_within` counts at once (memory, and an early end over the limit)."""


def _nearby_pairs(
    samples: FloatArray,
    reach: FloatArray,
    counts: IntArray,
    a: FloatArray,
    b: FloatArray,
    ends: Any,
) -> FloatArray:
    """:func:`_nearby_exact`'s GEOS minimum over the ends within ``reach`` (``counts`` of them)."""
    out = np.empty(len(samples), dtype=np.float64)
    ends_before = np.concatenate([[0], np.cumsum(counts)])
    lo = 0
    while lo < len(samples):  # a few samples at a time: their lists of ends are Python ints
        hi = int(np.searchsorted(ends_before, ends_before[lo] + NEARBY_CHUNK_PAIRS, "right")) - 1
        hi = min(max(hi, lo + 1), len(samples))
        found = ends.query_ball_point(samples[lo:hi], reach[lo:hi], workers=KD_WORKERS)
        owner = np.repeat(np.arange(hi - lo), counts[lo:hi])
        seg = np.fromiter(itertools.chain.from_iterable(found), dtype=np.int64, count=len(owner))
        out[lo:hi] = _nearby_min(samples[lo:hi], owner, seg, a, b)
        lo = hi
    return out


def _nearby_boxes(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    half: float,
    kernels: ModuleType,
    need: npt.NDArray[np.bool_] | None = None,
) -> FloatArray | None:
    """:func:`_nearby_exact` with the ends within reach from the box tree (numba).

    The same GEOS distances over the segments with an end within reach (a margin wider:
    any set holding those gives the same minimum), so the same answer.

    Args:
        samples: ``(U, 2)`` query points, mm.
        upper: ``(U,)`` distance of each to some segment ``a → b``, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        tree: the ends' search tree (:func:`camtool.accel.nearkernels.tree`).
        half: half the longest segment, mm.
        kernels: :mod:`camtool.accel.nearkernels`.
        need: as for :func:`_nearby_exact` (the limit counts every sample's pairs).
    """
    reach = ((upper + half) * (1.0 + 1e-9) + 1e-12) * (1.0 + 1e-12)
    owner, seg = kernels.pairs_within(np.ascontiguousarray(samples), *tree, reach, NEARBY_MAX_PAIRS)
    if len(owner) == 0 or len(np.unique(owner)) < len(samples):
        return None  # over the limit (or, which cannot happen, a sample without one)
    if need is None:
        return _nearby_min(samples, owner, seg, a, b)
    out = upper.copy()
    if need.any():
        keep = need[owner]
        renumber = np.cumsum(need) - 1  # a needed sample's place among the needed
        out[need] = _nearby_min(samples[need], renumber[owner[keep]], seg[keep], a, b)
    return out


NEARBY_CHUNK_PAIRS = 50_000
"""Most ``(sample, segment)`` pairs :func:`_nearby_min` hands GEOS at once (memory)."""


def _nearby_min(
    samples: FloatArray,
    owner: IntArray,
    seg: IntArray,
    a: FloatArray,
    b: FloatArray,
    chunk: int = NEARBY_CHUNK_PAIRS,
) -> FloatArray:
    """The least GEOS distance of each sample over its ``(owner, end)`` pairs (sample-major).

    ``owner`` is ascending and names every sample at least once. The pairs are measured
    a few samples at a time (about ``chunk`` pairs, a sample's pairs never split), which
    bounds the memory GEOS's points and lines take; each pair's distance and each
    sample's minimum are the same whatever the grouping. With numba
    (:func:`_pair_kernels`) the same GEOS distances are taken compiled, in one pass
    (:func:`camtool.accel.nearkernels.least_of_pairs`).
    """
    kernels = _pair_kernels(len(owner))
    if kernels is not None:  # the same GEOS floats, compiled: no line objects
        return np.asarray(
            kernels.least_of_pairs(
                np.ascontiguousarray(samples, dtype=np.float64),
                np.ascontiguousarray(owner, dtype=np.int64),
                np.ascontiguousarray(seg % len(a), dtype=np.int64),
                np.ascontiguousarray(a, dtype=np.float64),
                np.ascontiguousarray(b, dtype=np.float64),
            ),
            dtype=np.float64,
        )
    out = np.empty(len(samples), dtype=np.float64)
    pos, count = 0, len(owner)
    while pos < count:
        end = min(pos + max(1, chunk), count)
        if end < count:  # back to the first pair of the sample ``end`` falls in
            end = int(np.searchsorted(owner, owner[end], side="left"))
            if end <= pos:  # one sample has more pairs than ``chunk``: take them all
                end = int(np.searchsorted(owner, owner[pos], side="right"))
        first, last = int(owner[pos]), int(owner[end - 1])
        out[first : last + 1] = _nearby_group(samples, owner[pos:end], seg[pos:end], a, b)
        pos = end
    return out


PAIR_KERNELS_FROM = 200_000
"""Pairs from which :func:`_nearby_min` loads the compiled GEOS distance when numba is not
loaded yet (loading it costs about 0.5 s once; GEOS through shapely ~1 µs a pair)."""


def _pair_kernels(pairs: int) -> ModuleType | None:
    """:mod:`camtool.accel.nearkernels` for :func:`_nearby_min`, or ``None`` (GEOS).

    Loaded when numba already is (its cached kernel loads in milliseconds) or for at
    least :data:`PAIR_KERNELS_FROM` pairs; ``None`` without numba.
    """
    if not accel.enabled() or ("numba" not in sys.modules and pairs < PAIR_KERNELS_FROM):
        return None
    try:
        from camtool.accel import nearkernels
    except ImportError:
        return None
    return nearkernels


def _nearby_group(
    samples: FloatArray, owner: IntArray, seg: IntArray, a: FloatArray, b: FloatArray
) -> FloatArray:
    """:func:`_nearby_min` of consecutive samples ``owner[0]..owner[-1]`` (each with a pair)."""
    import shapely

    seg = seg % len(a)
    pair = np.unique(owner * len(a) + seg)  # each (sample, segment) once, sample-major
    owner, seg = pair // len(a), pair % len(a)
    used, local = np.unique(seg, return_inverse=True)
    lines = shapely.linestrings(np.stack([a[used], b[used]], axis=1))
    first_sample = int(owner[0])
    points = shapely.points(samples[first_sample : int(owner[-1]) + 1])
    dist = shapely.distance(points[owner - first_sample], lines[local])
    first = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    return np.asarray(np.minimum.reduceat(dist, first), dtype=np.float64)


def _nearest_chunk(
    samples: FloatArray, a: FloatArray, b: FloatArray, ends: Any, half: float
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """:func:`nearest_distances` of a few samples from the k-d tree of segment ``ends``.

    Returns:
        The distances and which of them the tests could not settle.
    """
    k = min(NEAREST_ENDS, 2 * len(a))
    r, index = ends.query(samples, k=k, workers=KD_WORKERS)
    r = np.asarray(r, dtype=np.float64).reshape(len(samples), k)
    seg = np.asarray(index).reshape(len(samples), k) % len(a)
    d = _to_segments(samples, a[seg], b[seg]).min(axis=1)
    lower = np.sqrt(np.maximum(r[:, 0] ** 2 - half * half, 0.0))
    # exact where every segment that could be nearer had an end among the k found
    # (its nearer end lies within d + L/2), or where the vertex bound is tight enough
    sure = (d + half < r[:, -1]) | (k == 2 * len(a)) | (d - lower <= NEAREST_TOLERANCE_MM)
    return d, ~sure


ALONG_SPACING_MM = 0.001
"""Largest spacing of the programmed path's samples for :func:`along_path`, mm."""
ALONG_MAX_SAMPLES = 400_000
"""Most path samples :func:`along_path` measures (the spacing grows beyond it)."""
ALONG_MAX_TRACE = 400_000
"""Most trace points per contour :func:`along_path` keeps (every k-th beyond it)."""
ALONG_RESOLUTION_MM = 0.0005
"""Spacing the trace is thinned to for :func:`along_path`, mm: a thinned-out point lies
within about this of the polyline kept, so it bounds the error of the shortfall."""


def along_path(
    points: FloatArray, block_start: IntArray, start_mm: Point, program: Program
) -> AlongPath:
    """The path-to-trace measures of a trace (see :class:`AlongPath`).

    Args:
        points: ``(N, 2)`` float64 trace, mm.
        block_start: ``(B + 1,)`` offsets of each move's points in ``points``.
        start_mm: the carriage position before the first point.
        program: the program the trace executed.

    The path is sampled at most :data:`ALONG_SPACING_MM` apart (wider when it
    would take more than :data:`ALONG_MAX_SAMPLES`), every move's ends
    included; each contour's trace is a polyline through its points (the point
    before the contour included), thinned to points about
    :data:`ALONG_RESOLUTION_MM` apart (never more than :data:`ALONG_MAX_TRACE`).

    Only the samples that can hold the largest shortfall are measured exactly
    (:class:`_Bounded`): every sample's distance is first bounded by the trace
    segments at its place, and the contours are measured from the likeliest, each
    one's samples only where their bound reaches the largest found so far. The
    figures are those of measuring every sample, contours in order (the first of
    equal ones named), bit for bit; a part's 400 000 samples took 0.85 s that way and
    take about 0.15 s.
    """
    starts = move_starts(program)
    runs = contour_runs(program)
    total = sum(
        segment_of(starts[i], program.moves[i]).length for a, b in runs for i in range(a, b + 1)
    )
    spacing = max(ALONG_SPACING_MM, total / ALONG_MAX_SAMPLES)
    start = np.asarray(start_mm, dtype=np.float64).reshape(1, 2)
    ends: list[float] = []
    end_worst = (0.0, (0.0, 0.0), -1)
    count = 0
    reach: list[tuple[float, int]] = []  # (-largest bound, contour) of contours with samples
    nominal = nominal_arrays(program)
    floor = 0.0  # the largest shortfall measured so far, mm
    found: list[tuple[int, float, Point, int]] = []  # (contour, shortfall, at, move)
    bounds: dict[int, FloatArray] = {}

    def measured(c: int, far: float, k: int, samples: FloatArray, owner: IntArray) -> None:
        nonlocal floor
        floor = max(floor, far)
        found.append((c, far, (float(samples[k, 0]), float(samples[k, 1])), int(owner[k])))

    def contour(c: int) -> tuple[FloatArray, IntArray, FloatArray, FloatArray, IntArray]:
        first, last = runs[c]
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        before = points[lo - 1 : lo] if lo > 0 else start
        run = np.vstack([before, points[lo:hi]])
        samples, owner, t = _sample_moves(program, starts, first, last, spacing)
        return samples, owner, t, run, block_start[first + 1 : last + 2] - lo

    def bounded(
        c: int, samples: FloatArray, owner: IntArray, t: FloatArray, run: FloatArray, keep: IntArray
    ) -> _Bounded:
        first, last = runs[c]
        part = {k: v[first : last + 1] for k, v in nominal.items()}
        made = _Bounded.of_run(samples, owner - first, t, run, keep, part, bounds.get(c))
        bounds[c] = made.reach
        return made

    for c, (first, last) in enumerate(runs):
        for b in range(first, last + 1):
            here = _carriage_after(points, block_start, start, b)
            gap = math.dist(here, starts[b + 1]) * 1000.0
            if gap > end_worst[0]:
                end_worst = (gap, starts[b + 1], b)
        ends.append(math.dist(_carriage_after(points, block_start, start, last), starts[last + 1]))
        samples, owner, t, run, keep = contour(c)
        count += len(samples)
        if len(samples) == 0:
            continue
        if len(samples) < SHORTFALL_BOUND_FROM:  # a small contour: measured at once
            measured(c, *_farthest_from_trace(samples, _thinned(run, keep)), samples, owner)
        else:
            reach.append((-bounded(c, samples, owner, t, run, keep).reach_max, c))
    # the long contours that can hold the largest shortfall, the likeliest first: the
    # others are left out once one measured is larger than every bound of theirs
    for _, c in sorted(reach):
        samples, owner, t, run, keep = contour(c)
        got = bounded(c, samples, owner, t, run, keep).farthest(floor)
        if got is not None:
            measured(c, *got, samples, owner)
    worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
    for _, far, at, block in sorted(found):  # in contour order, as one pass over them
        if far * 1000.0 > worst[0]:
            worst = (far * 1000.0, at, block)
    return AlongPath(
        shortfall_um=worst[0],
        shortfall_at_mm=worst[1],
        shortfall_block=int(worst[2]),
        block_end_um=end_worst[0],
        block_end_at_mm=(float(end_worst[1][0]), float(end_worst[1][1])),
        block_end_block=int(end_worst[2]),
        contour_end_um=tuple(e * 1000.0 for e in ends),
        samples=count,
    )


def _farthest_from_trace(
    samples: FloatArray, trace: FloatArray, ends: _LazyTree | None = None
) -> tuple[float, int]:
    """Largest distance of a path sample to the polyline ``trace`` and the first sample at it.

    Distances in mm, to the one point when ``trace`` has one (:func:`farthest_nearest`);
    ``ends``: the k-d tree of the segment ends, shared by the batches of one trace.
    """
    return farthest_nearest(samples, *_segments(trace), ends=ends)


def _segments(trace: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The segments ``a → b`` of the polyline ``trace`` (views): one of no length for one point."""
    if len(trace) == 1:
        return trace, trace
    return trace[:-1], trace[1:]


SHORTFALL_BOUND_FROM = 2048
"""Path samples from which a contour's shortfall is bounded before it is measured
(:class:`_Bounded`); a smaller contour is measured at once, all its samples. The bounds
cost about 1 ms a contour whatever its size, and save nothing where every contour's
shortfall ties (identical pockets): 1 000 such squares of 400 samples took 1.36 s bounded
against 0.41 s measured, 200 of 2 000 samples 0.62 s against 0.31 s; the benchmark part
(36 contours, ~11 000 samples each) 0.25 s bounded against 0.74 s. Only the time depends
on it."""
SHORTFALL_WINDOW = 4
"""Trace segments on each side of a path sample's place along the trace that
:class:`_Bounded` measures it against (its bound; only the time depends on it)."""
SHORTFALL_ROUND = 1024
"""Samples of largest bound :meth:`_Bounded.farthest` measures first (only the time
depends on it: the likeliest samples measured first leave most others out)."""
SHORTFALL_CHUNK = 1 << 15
"""Path samples or trace points :class:`_Bounded` works on at once (memory)."""


class _Places:
    """A contour's thinned trace, each point with its place along the contour's moves.

    The place of a trace point of move ``j`` is ``j + f``, ``f`` the fraction of the
    move's nominal segment at the foot of the point (lines: its projection; arcs: its
    angle; 0 to 1), made non-decreasing along the trace; a path sample's is ``j + t``
    (:func:`_fractions`). Where the backlash holds the carriage at a move's start, or
    the rows crowd, the place still finds the rows beside a sample.

    The trace is given as its segments ``a[i] → b[i]`` (``b[i] == a[i + 1]``; one
    segment of no length for a trace of one point): the streamed verify holds them as
    views of the k-d tree's array of segment ends, not the trace beside it (6 MB).

    Args:
        a: ``(S, 2)`` segment starts, mm (the trace less its last point).
        b: ``(S, 2)`` segment ends, mm (the trace less its first point).
        spans: ``(J,)`` each move's first and ``(J,)`` last index in the trace
            (:func:`_move_spans`).
        nominal: the contour's moves' nominal geometry (:func:`nominal_arrays` of the
            program, rows ``first..last``).

    Attributes:
        a, b: the segments.
        index: ``(K,)`` the trace points that moved (each unlike the one before; int32
            below 2**31 points): the same polyline without its segments of no length.
        keys: ``(K,)`` their places, non-decreasing.
    """

    def __init__(
        self,
        a: FloatArray,
        b: FloatArray,
        spans: tuple[IntArray, IntArray],
        nominal: dict[str, FloatArray],
    ) -> None:
        self.a, self.b = a, b
        first, last = spans
        # a row that did not move the carriage adds a segment of no length: the points
        # that moved make the same polyline, and the window then spans real segments
        points = len(a) + 1 if len(a) > 1 or np.any(a != b) else 1
        moved = np.ones(points, dtype=bool)
        for lo in range(0, points - 1, SHORTFALL_CHUNK):
            part = slice(lo, lo + SHORTFALL_CHUNK)
            sa, sb = a[part], b[part]
            moved[lo + 1 : lo + 1 + len(sa)] = (sa[:, 0] != sb[:, 0]) | (sa[:, 1] != sb[:, 1])
        self.index = np.flatnonzero(moved).astype(np.int32 if points < 2**31 else np.int64)
        del moved
        keys = np.empty(len(self.index), dtype=np.float64)
        for lo in range(0, len(keys), SHORTFALL_CHUNK):
            index = self.index[lo : lo + SHORTFALL_CHUNK].astype(np.int64)
            move = np.minimum(np.searchsorted(last, index), len(last) - 1)
            rows = np.maximum(last[move] - first[move], 1)
            by_row = (index - first[move]) / rows
            keys[lo : lo + len(index)] = move + _foot_fraction(
                self.point(index), move, nominal, by_row
            )
        self.keys = np.maximum.accumulate(keys, out=keys) if len(keys) else keys

    @cached_property
    def magnitude(self) -> float:
        """The largest coordinate magnitude of the segments (of every batch's samples' bound)."""
        return max(_largest_magnitude(self.a), _largest_magnitude(self.b))

    def point(self, index: IntArray) -> FloatArray:
        """The trace points ``index`` ``(N, 2)``: ``a[i]``, or ``b[i - 1]`` for the last."""
        out = self.b[np.maximum(index - 1, 0)]
        out[index == 0] = self.a[0]
        return out


def _foot_fraction(
    points: FloatArray, move: IntArray, nominal: dict[str, FloatArray], by_row: FloatArray
) -> FloatArray:
    """``(N,)`` where along its move's nominal segment each point's foot lies, 0 to 1.

    ``by_row``: each point's place among its move's rows, 0 to 1. An arc's angle turns
    over at its start: a point of a full circle just before its start (or just past its
    end) is taken at the end the rows put it at, not a turn away.
    """
    x0, y0 = nominal["x0"][move], nominal["y0"][move]
    dx, dy = nominal["x1"][move] - x0, nominal["y1"][move] - y0
    length2 = dx * dx + dy * dy
    dot = (points[:, 0] - x0) * dx + (points[:, 1] - y0) * dy
    out = np.divide(dot, length2, out=np.zeros_like(length2), where=length2 > 0)
    arc = nominal["kind"][move] == 1
    if arc.any():
        m = move[arc]
        sweep = nominal["sweep"][m]
        turn = np.arctan2(points[arc, 1] - nominal["cy"][m], points[arc, 0] - nominal["cx"][m])
        turn = np.mod(np.where(sweep < 0, -1.0, 1.0) * (turn - nominal["a0"][m]), 2 * math.pi)
        size = np.abs(sweep)
        past = turn > size  # beyond the arc: at the nearer of its ends
        turn = np.where(past & (turn > (size + 2 * math.pi) / 2), 0.0, turn)
        f = np.clip(np.divide(turn, size, out=np.zeros_like(size), where=size > 0), 0.0, 1.0)
        rows = by_row[arc]
        out[arc] = np.where(f - rows > 0.5, 0.0, np.where(rows - f > 0.5, 1.0, f))
    return np.clip(out, 0.0, 1.0)


class _Bounded:
    """Path samples of one contour, each with a cheap upper bound of its shortfall.

    The shortfall of a sample is its distance to the nearest segment of the contour's
    thinned trace (:func:`_farthest_from_trace`). The trace follows the path, so the
    trace segments at the sample's place (:class:`_Places`) are near it: the least
    distance to the :data:`SHORTFALL_WINDOW` segments on each side bounds its
    shortfall from above, in a few vector operations. :meth:`farthest` then measures,
    as :func:`_farthest_from_trace` measures them all, only the samples whose bound can
    reach the largest shortfall, and gives the same two numbers.

    A sample left out has a bound ``u`` with
    ``(u + NEAREST_TOLERANCE_MM)(1 + 1e-9) + slack`` below a shortfall known to be
    reached (a sample's own, or ``floor``). That is strictly below what
    :func:`nearest_distances` can give it: it gives the true distance ``d <= u``, or,
    settled by the vertex bound, at most :data:`NEAREST_TOLERANCE_MM` more; the
    ``slack`` (1e-12 mm and 64 ulps of the largest coordinate, as :func:`_reaching`)
    covers two formulas' rounding of one distance. So it can be neither the largest nor
    tie with it, and the first largest of the rest is the first largest of all.

    Args:
        samples: ``(N, 2)`` path samples, mm (:func:`_sample_moves`).
        move: ``(N,)`` each one's move, counted from the contour's first (0).
        t: ``(N,)`` how far along its move each lies, 0 to 1 (:func:`_fractions`).
        places: the contour's thinned trace (its segments) and its places.
        ends: the k-d tree of the trace's segment ends (:meth:`_Contour.ends`), shared
            by the batches of one trace; built when needed otherwise.
        reach: the bounds an earlier one of the same samples and trace made
            (:attr:`reach`), instead of making them again.
    """

    def __init__(
        self,
        samples: FloatArray,
        move: IntArray,
        t: FloatArray,
        places: _Places,
        ends: _LazyTree | None = None,
        reach: FloatArray | None = None,
    ) -> None:
        self.samples, self.places, self.ends = samples, places, ends
        self.slack = 0.0
        if len(samples) == 0:
            self.reach = np.zeros(0)
        else:
            scale = max(_largest_magnitude(samples), places.magnitude)
            self.slack = 1e-12 + 64.0 * float(np.spacing(scale))
            if reach is None:
                upper = _window_bounds(samples, move + t, places)
                reach = (upper + NEAREST_TOLERANCE_MM) * (1.0 + 1e-9) + self.slack
            self.reach = reach
        self.reach_max = float(np.max(self.reach)) if len(samples) else -math.inf

    @classmethod
    def of_run(
        cls,
        samples: FloatArray,
        move: IntArray,
        t: FloatArray,
        run: FloatArray,
        keep: IntArray,
        nominal: dict[str, FloatArray],
        reach: FloatArray | None = None,
    ) -> _Bounded:
        """The samples against a contour's whole run (thinned here, :func:`_thinned`).

        ``run``: the point before the contour, then its rows; ``keep``: each move's last
        row in ``run``; ``nominal``: the contour's moves' (:class:`_Places`); ``reach``:
        as for the class.
        """
        spans = _move_spans(len(run), _run_every(run), keep)
        a, b = _segments(_thinned(run, keep))
        return cls(samples, move, t, _Places(a, b, spans, nominal), reach=reach)

    def farthest(self, floor: float = 0.0) -> tuple[float, int] | None:
        """:func:`_farthest_from_trace` of the samples, or ``None`` when none can reach ``floor``.

        ``floor``: a shortfall already found, mm. A sample whose shortfall cannot reach
        it is not measured; ``None`` says that none can (their largest is below it).
        The answer may still be below ``floor`` (then the largest of those that may not).

        The samples are measured in two rounds: the :data:`SHORTFALL_ROUND` of largest
        bound, then the others whose bound reaches the largest shortfall of the first.
        Each sample's distance is its own (:func:`nearest_distances`) and each round
        gives its largest and the first sample at it, so the larger of the two and the
        first sample at it are those of measuring them all at once.
        """
        if len(self.samples) == 0:
            return None
        order = np.argsort(-self.reach, kind="stable")  # the likeliest first
        reach = self.reach[order]
        if reach[0] < floor:
            return None
        a, b = self.places.a, self.places.b
        ends = self.ends if self.ends is not None else _LazyTree(_end_points(a, b))
        best: tuple[float, int] | None = None
        known, at, size = floor, 0, SHORTFALL_ROUND
        while at < len(order):
            stop = min(len(order), at + size)  # of those whose bound reaches the largest known
            stop = min(stop, at + int(np.searchsorted(-reach[at:stop], -known, "right")))
            if stop <= at:
                break
            index = np.sort(order[at:stop])  # in sample order: the first of equal ones
            far, k = farthest_nearest(self.samples[index], a, b, ends=ends)
            if best is None or far > best[0] or (far == best[0] and index[k] < best[1]):
                best = (far, int(index[k]))
            known = max(known, far)
            at, size = stop, len(order)
        return best


def _largest_magnitude(values: FloatArray) -> float:
    """``max(|values|)`` without an array of the magnitudes (a trace's would be ~6 MB)."""
    return max(abs(float(np.max(values))), abs(float(np.min(values))))


def _segment_formula(
    apx: FloatArray, apy: FloatArray, abx: FloatArray, aby: FloatArray
) -> FloatArray:
    """Distance of ``p`` to the segment ``a → b`` from the columns of ``p - a`` and ``b - a``."""
    length2 = abx * abx + aby * aby
    dot = apx * abx + apy * aby
    t = np.divide(dot, length2, out=np.zeros_like(length2), where=length2 > 0)
    np.clip(t, 0.0, 1.0, out=t)
    ox, oy = apx - t * abx, apy - t * aby
    return np.sqrt(ox * ox + oy * oy)


def _window_bounds(samples: FloatArray, place: FloatArray, places: _Places) -> FloatArray:
    """``(N,)`` each sample's least distance to the trace segments around its ``place``.

    The segments up to :data:`SHORTFALL_WINDOW` on each side of the trace points
    whose places (:class:`_Places`) enclose the sample's. Each is a distance to one
    segment of the trace, so no less than the distance to them all.
    """
    a, b, moved = places.a, places.b, places.index
    m = len(moved) - 1
    if m == 0:  # the carriage never moved: the one point
        return np.hypot(samples[:, 0] - a[0, 0], samples[:, 1] - a[0, 1])
    out = np.empty(len(samples), dtype=np.float64)
    for lo in range(0, len(samples), SHORTFALL_CHUNK):
        part = slice(lo, lo + SHORTFALL_CHUNK)
        centre = np.searchsorted(places.keys, place[part]) - 1
        px, py = samples[part, 0], samples[part, 1]
        best = np.full(len(px), np.inf)
        for off in range(-SHORTFALL_WINDOW, SHORTFALL_WINDOW + 1):
            k = np.clip(centre + off, 0, m - 1)
            i, j = moved[k], moved[k + 1] - 1  # from point i (a[i]) to point j + 1 (b[j])
            ax, ay = a[i, 0], a[i, 1]
            d = _segment_formula(px - ax, py - ay, b[j, 0] - ax, b[j, 1] - ay)
            np.minimum(best, d, out=best)
        out[part] = best
    return out


def _move_spans(n: int, every: int, keep: IntArray) -> tuple[IntArray, IntArray]:
    """The first and last index of each move in a contour's thinned trace (:func:`_thinned`).

    Args:
        n: points of the run (the point before the contour, then its rows).
        every: the run's thinning step (:func:`_run_every`; 1: nothing left out).
        keep: ``(J,)`` each move's last row in the run, which :func:`_thinned` keeps.

    Returns:
        ``(J,)`` first and ``(J,)`` last indices: move ``j`` runs from the last row of
        move ``j - 1`` (the point before, 0, for the first) to its own. A kept row's
        index counts the kept rows before it: the multiples of ``every`` and the other
        kept rows (``keep`` and the run's last).
    """
    rows = np.clip(np.asarray(keep, dtype=np.int64), 0, max(n - 1, 0))
    if every == 1:
        at = rows
    else:
        inside = np.asarray(keep, dtype=np.int64)
        kept = np.unique(np.append(inside[(inside >= 0) & (inside < n)], n - 1))
        others = kept[kept % every != 0]
        at = -(-rows // every) + np.searchsorted(others, rows)
    return np.concatenate(([0], at[:-1])).astype(np.int64), at.astype(np.int64)


def _thinned(run: FloatArray, keep: IntArray) -> FloatArray:
    """``run``'s every k-th point, its last and the rows ``keep``, about 0.5 µm apart.

    The spacing is :data:`ALONG_RESOLUTION_MM`, never more than :data:`ALONG_MAX_TRACE`
    points (plus ``keep``). Keeping every move's last row keeps the corners, which a
    thinned polyline would cut.
    """
    every = _run_every(run)
    if every == 1:
        return run
    mask = np.zeros(len(run), dtype=bool)
    mask[::every] = True
    mask[-1] = True
    mask[keep[(keep >= 0) & (keep < len(run))]] = True
    return run[mask]


THIN_HEAD = 2000
"""Points at the start of a contour's trace whose median spacing :func:`_thinned` reads."""


def _run_every(run: FloatArray) -> int:
    """Every how many points :func:`_thinned` keeps of ``run`` (1: all of them)."""
    if len(run) < 3:
        return 1
    return _thin_every(run[: min(len(run), THIN_HEAD)], len(run))


def _thin_every(head: FloatArray, n: int) -> int:
    """Every how many points :func:`_thinned` keeps of a trace of ``n`` (>= 3) points.

    ``head`` is the trace's first ``min(n, THIN_HEAD)`` points: their median spacing
    against :data:`ALONG_RESOLUTION_MM`, and at most :data:`ALONG_MAX_TRACE` points.
    """
    step = _median_step(head)
    every = max(1, int(ALONG_RESOLUTION_MM / step) if step > 0 else 1)
    return max(every, -(-n // ALONG_MAX_TRACE))


def _median_step(head: FloatArray) -> float:
    """The median distance between consecutive points of ``head`` ``(n, 2)``, mm (0 if n < 2)."""
    steps = np.diff(head, axis=0)
    return float(np.median(np.hypot(steps[:, 0], steps[:, 1]))) if len(steps) else 0.0


def _carriage_after(
    points: FloatArray, block_start: IntArray, start: FloatArray, block: int
) -> FloatArray:
    """Carriage position after move ``block``'s last row (or before it, when it has none)."""
    row = int(block_start[block + 1]) - 1
    return points[row] if row >= 0 else start[0]


def _sample_moves(
    program: Program, starts: Sequence[Point], first: int, last: int, spacing: float
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Points along moves ``first..last`` at most ``spacing`` apart, ends included.

    Returns:
        ``(N, 2)`` points, mm; ``(N,)`` the move of each; ``(N,)`` how far along its
        move each lies (0 at its start, 1 at its end: :func:`_fractions`).
    """
    chunks = [_sample_move(program, starts, b, spacing) for b in range(first, last + 1)]
    if not chunks:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0)
    owners = [np.full(len(pts), b, dtype=np.int64) for b, pts in enumerate(chunks, first)]
    fractions = [_fractions(len(pts)) for pts in chunks]
    return np.vstack(chunks), np.concatenate(owners), np.concatenate(fractions)


def _fractions(count: int) -> FloatArray:
    """``(count,)``: how far along its move each of :func:`_sample_move`'s points lies, 0 to 1."""
    return np.arange(count, dtype=np.float64) / max(1, count - 1)


def _sample_move(program: Program, starts: Sequence[Point], b: int, spacing: float) -> FloatArray:
    """``(n + 1, 2)`` points along move ``b`` at most ``spacing`` apart, its ends included."""
    seg = segment_of(starts[b], program.moves[b])
    n = max(1, math.ceil(seg.length / spacing))
    t = np.arange(n + 1, dtype=np.float64) / n
    if isinstance(seg, Arc):
        r, c = seg.radius, seg.centre
        angle = math.atan2(seg.start[1] - c[1], seg.start[0] - c[0]) + seg.sweep * t
        pts = np.column_stack((c[0] + r * np.cos(angle), c[1] + r * np.sin(angle)))
        pts[-1] = seg.end
        return pts
    (x0, y0), (x1, y1) = seg.start, seg.end
    return np.column_stack((x0 + (x1 - x0) * t, y0 + (y1 - y0) * t))


def _sample_batches(
    program: Program, starts: Sequence[Point], first: int, last: int, spacing: float, size: int
) -> Iterator[tuple[FloatArray, IntArray, FloatArray]]:
    """:func:`_sample_moves` in consecutive pieces of ``size`` points (the last shorter).

    The pieces are exactly ``samples[i : i + size]`` (and owners and fractions) of the
    whole arrays, built move by move: never more than a piece and one move's points are
    held.
    """
    held: list[FloatArray] = []
    owners: list[IntArray] = []
    along: list[FloatArray] = []
    count = 0
    for b in range(first, last + 1):
        pts = _sample_move(program, starts, b, spacing)
        held.append(pts)
        owners.append(np.full(len(pts), b, dtype=np.int64))
        along.append(_fractions(len(pts)))
        count += len(pts)
        while count >= size:
            samples, owner, t = np.vstack(held), np.concatenate(owners), np.concatenate(along)
            yield samples[:size], owner[:size], t[:size]
            held, owners, along = [samples[size:]], [owner[size:]], [t[size:]]
            count -= size
    if count:
        yield np.vstack(held), np.concatenate(owners), np.concatenate(along)


STREAM_SAMPLES = 100_000
"""Path samples :class:`TraceStream` measures against a contour's trace at once: the
distance of each is found alone (:func:`nearest_distances`), so the pieces give the same
distances as one call, with about 30 MB less held on the bench program."""
ZOOM_ROWS = 256
"""Rows on each side of the worst deviation a streamed trace keeps for the picture's zoom
(within the worst point's chunk): every k-th row alone leaves the zoom on it empty."""
PICTURE_ROWS = 100_000
"""About how many rows of a streamed trace :class:`TraceStream` keeps for the picture
(on the 10 mm wide 13 M-row benchmark program, a kept row about every 20 µm of path,
a few pixels of a preview; the worst point is always kept)."""


@dataclass(frozen=True, eq=False)
class StreamedMeasures:
    """What :class:`TraceStream` measured on a trace seen chunk by chunk.

    Attributes:
        deviation: as :func:`deviation` of the whole trace; ``rms_um`` is the square
            root of the exact (correctly rounded) mean of the squares (see
            :class:`TraceStream`), which may differ in the last bits from numpy's
            pairwise mean of the whole array.
        along: as :func:`along_path` of the whole trace (the same figures).
        contours: as :func:`measure_contours` of the whole trace (the same figures).
        picture_rows: ``(K,) int64`` rows kept for the picture (every k-th row of the
            trace, k = ceil(rows / :data:`PICTURE_ROWS`), and the worst deviation's).
        picture_mm: ``(K, 2) float64`` the carriage at those rows, mm.
        picture_blocks: ``(K,) int64`` their move indices.
        picture_steps: ``(K, 2) int8`` their motor steps.
        picture_compensation: ``(K,) bool`` whether each is a compensation row.
        compensation_steps: compensation steps ``(x, y)`` of the whole trace.
    """

    deviation: Deviation
    along: AlongPath
    contours: tuple[ContourMeasure, ...]
    picture_rows: IntArray
    picture_mm: FloatArray
    picture_blocks: IntArray
    picture_steps: npt.NDArray[np.int8]
    picture_compensation: npt.NDArray[np.bool_]
    compensation_steps: tuple[int, int]


class _Contour:
    """One contour's state while :class:`TraceStream` reads its rows."""

    def __init__(self, number: int, first: int, last: int, block_start: IntArray) -> None:
        self.number, self.first, self.last = number, first, last
        self.lo, self.hi = int(block_start[first]), int(block_start[last + 1])
        self.n = self.hi - self.lo + 1  # the run: the point before, then the rows
        self.keep = block_start[first + 1 : last + 2] - self.lo  # each move's last row
        self.top = [-math.inf, -math.inf]
        self.low = [math.inf, math.inf]
        self.before: FloatArray = np.zeros(2)
        self.last_point: FloatArray = np.zeros(2)
        self.every = 1 if self.n < 3 else 0  # 0: not known before the head is read
        self.pending: list[tuple[int, FloatArray]] = []
        self.pending_count = 0
        self.kept: list[FloatArray] = []
        self.circle: CircleFit | None = None  # a circle's fit, fed its run as it comes

    def add(self, j0: int, points: FloatArray) -> None:
        """The run's points ``j0, j0 + 1, ...`` (run index 0 is the point before), in order."""
        if self.circle is not None:
            self.circle.add(points)
        if self.every == 0:
            self.pending.append((j0, points))
            self.pending_count += len(points)
            if self.pending_count >= min(self.n, THIN_HEAD):
                self._head_read()
            return
        self._select(j0, points)

    def _head_read(self) -> None:
        head = np.vstack([p for _, p in self.pending])[: min(self.n, THIN_HEAD)]
        self.every = _thin_every(head, self.n)
        for j0, points in self.pending:
            self._select(j0, points)
        self.pending = []

    def _select(self, j0: int, points: FloatArray) -> None:
        """Keep what :func:`_thinned` keeps of the run's points ``j0 ...``."""
        if self.every == 1:
            self.kept.append(points.copy())
            return
        j1 = j0 + len(points)
        every = self.every
        first = -(-j0 // every) * every
        wanted = np.arange(first, j1, every, dtype=np.int64)
        a, b = np.searchsorted(self.keep, [j0, j1])
        extra = self.keep[a:b]
        if j0 <= self.n - 1 < j1:
            extra = np.append(extra, self.n - 1)
        if len(extra):  # np.union1d's sorted distinct values, without its hash table
            merged = np.concatenate([wanted, extra])
            merged.sort()
            wanted = merged[np.concatenate(([True], merged[1:] != merged[:-1]))]
        self.kept.append(points[wanted - j0])

    def trace(self) -> FloatArray:
        """The thinned trace (what :func:`_thinned` gives of the whole run)."""
        if self.every == 0:
            self._head_read()
        return np.vstack(self.kept) if self.kept else np.zeros((0, 2))

    def ends(self) -> FloatArray:
        """The segment ends of :meth:`trace`, ``concatenate(_segments(trace))``, from the pieces.

        The starts ``a``, then the ends ``b`` (:func:`_segments`), made from the kept
        pieces without the joined trace beside them (6 MB of a 400 000-point contour).
        """
        if self.every == 0:
            self._head_read()
        n = sum(len(p) for p in self.kept)
        if n <= 1:
            return np.concatenate(_segments(self.trace()))
        out = np.empty((2 * (n - 1), 2), dtype=np.float64)
        at = n - 2  # the trace from n - 2: its points 1.. are the segment ends b
        for piece in self.kept:
            out[at : at + len(piece)] = piece
            at += len(piece)
        at = 0  # then its points ..n - 2 are the starts a (the one at n - 2 set again)
        for piece in self.kept:
            take = min(len(piece), n - 1 - at)
            out[at : at + take] = piece[:take]
            at += take
        return out

    def extent(self) -> tuple[float, float]:
        """:func:`_extent` of the run."""
        if self.hi <= self.lo:
            return (0.0, 0.0)
        return (self.top[0] - self.low[0], self.top[1] - self.low[1])


class TraceStream:
    """The measures of a trace read chunk by chunk (no array of the whole trace).

    Every measure of :func:`deviation`, :func:`measure_contours` and :func:`along_path`,
    from chunks of whole moves.

    Feed the chunks in order with :meth:`add` (``first`` move, global row offsets, the
    carriage and steps of their rows), then :meth:`finish`. The figures are those of
    the whole-trace functions, bit for bit: each point's distance is computed by the
    same float operations, maxima and their positions compared in trace order (the
    first of equal maxima wins), extents by ``max``/``min`` (exact), each contour's
    trace thinned to the points :func:`_thinned` keeps of the whole contour (its
    every-k-th, read from the contour's first :data:`THIN_HEAD` points and its known
    length, the moves' last rows and its last point) and measured as
    :func:`along_path` measures it (:class:`_Bounded`, the samples that cannot pass the
    largest shortfall so far left out). A contour that is a circle feeds its rows to its
    fit as they come (:class:`~camtool.verify.circlefit.CircleFit`). The one exception
    is the deviation's rms: numpy's pairwise mean of the
    whole array cannot be reproduced chunk by chunk, so it is the square root of the
    exact sum of the squares (an integer sum of their mantissas by exponent,
    :func:`camtool.accel.kernels.exact_sum_squares`; the squares are numpy's ``d * d``),
    correctly rounded, divided by the count: at least as accurate, and it may differ
    from the whole-array figure in the last bits.

    Args:
        program: the program the trace executed.
        block_start: ``(B + 1,) int64`` row offsets of every move in the whole trace.
        start_mm: the carriage before the first row.
        kernels: the compiled kernels (:mod:`camtool.accel.kernels`).
        rms: measure the deviation's rms; ``False`` (the error budget, whose figures do
            not include it): ``deviation.rms_um`` is NaN.
    """

    def __init__(
        self,
        program: Program,
        block_start: IntArray,
        start_mm: Point,
        kernels: Any,
        *,
        rms: bool = True,
    ):
        self.rms = rms
        near_kernels()  # numba is loaded already: the compiled nearest search costs its cache
        self.program = program
        self.block_start = block_start
        self.kernels = kernels
        self.nominal = nominal_arrays(program)
        self.start = np.asarray(start_mm, dtype=np.float64).reshape(1, 2)
        self.prev: FloatArray = self.start[0]
        self.starts = move_starts(program)
        self.runs = contour_runs(program)
        self.next_run = 0
        self.open: _Contour | None = None
        self.contours: list[ContourMeasure] = []
        self.rows = int(block_start[-1])
        self.every_picture = max(1, -(-self.rows // PICTURE_ROWS))
        self.picture: list[tuple[IntArray, FloatArray, IntArray, Any, Any]] = [
            (
                np.zeros(0, np.int64),
                np.zeros((0, 2)),
                np.zeros(0, np.int64),
                np.zeros((0, 2), np.int8),
                np.zeros(0, np.bool_),
            )
        ]
        self.comp_steps = [0, 0]
        # deviation
        self.dev_max = -1.0
        self.dev_where: tuple[Point, int, int] = ((0.0, 0.0), -1, -1)  # at, block, row
        self.dev_rows: tuple[IntArray, FloatArray, IntArray, Any, Any] | None = None  # near it
        self.dev_count = 0
        self.bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
        # along the path
        total = sum(
            segment_of(self.starts[i], program.moves[i]).length
            for a, b in self.runs
            for i in range(a, b + 1)
        )
        self.spacing = max(ALONG_SPACING_MM, total / ALONG_MAX_SAMPLES)
        self.worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
        self.end_worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
        self.ends: list[float] = []
        self.samples = 0

    def add(
        self,
        first: int,
        block_start: IntArray,
        points: FloatArray,
        steps: npt.NDArray[np.int8],
        compensation: npt.NDArray[np.bool_],
        measured: tuple[IntArray, FloatArray, list[tuple[int, int]]] | None = None,
    ) -> None:
        """Measure one chunk: moves ``first ..`` with global row offsets ``block_start``.

        ``measured``: :meth:`distances` of this chunk, when another thread took them.
        """
        r0 = int(block_start[0])
        blocks, dist, pieces = measured or self.distances(first, block_start, points)
        self._deviation(r0, points, blocks, steps, compensation, dist, pieces)
        self._picture(r0, points, blocks, steps, compensation)
        comp = steps[np.flatnonzero(compensation)]  # a few rows: 5 µs, where the mask took 76
        for axis in (0, 1):
            self.comp_steps[axis] += int(np.abs(comp[:, axis]).sum())
        self._contours(first, first + len(block_start) - 1, r0, points)
        if len(points):
            self.prev = points[-1].copy()

    def distances(
        self, first: int, block_start: IntArray, points: FloatArray
    ) -> tuple[IntArray, FloatArray, list[tuple[int, int]]]:
        """A chunk's move of each row and its rows' distances to their moves (:func:`_distances`).

        It reads only the chunk and the program's nominal moves, so another thread may
        take it while this one measures the chunk before (:func:`_stream`'s producer).
        """
        r0 = int(block_start[0])
        count = len(block_start) - 1
        blocks = np.repeat(np.arange(first, first + count, dtype=np.int64), np.diff(block_start))
        bounds = block_start - r0
        return blocks, *_distances(points, blocks, self.nominal, bounds, first, self.kernels)

    def _deviation(
        self,
        r0: int,
        points: FloatArray,
        blocks: IntArray,
        steps: Any,
        compensation: Any,
        dist: FloatArray,
        pieces: list[tuple[int, int]],
    ) -> None:
        if not len(dist):
            return
        worst = int(np.argmax(dist))
        if float(dist[worst]) > self.dev_max:
            row = _row_of(pieces, worst)
            self.dev_max = float(dist[worst])
            at = (float(points[row, 0]), float(points[row, 1]))
            self.dev_where = (at, int(blocks[row]), r0 + row)
            near = slice(max(0, row - ZOOM_ROWS), row + ZOOM_ROWS + 1)
            self.dev_rows = (
                np.arange(r0 + near.start, r0 + near.start + len(points[near]), dtype=np.int64),
                points[near].copy(),
                blocks[near].copy(),
                steps[near].copy(),
                compensation[near].copy(),
            )
        self.dev_count += len(dist)
        if self.rms:
            self.kernels.exact_sum_squares(dist, self.bins)

    def _picture(
        self, r0: int, points: FloatArray, blocks: IntArray, steps: Any, compensation: Any
    ) -> None:
        every = self.every_picture
        local = np.arange(-(-r0 // every) * every - r0, len(points), every, dtype=np.int64)
        self.picture.append(
            (local + r0, points[local], blocks[local], steps[local], compensation[local])
        )

    def _point(self, row: int, r0: int, points: FloatArray) -> FloatArray:
        """The carriage after global ``row`` (in this chunk or the row before it)."""
        return points[row - r0] if row >= r0 else self.prev

    def _contours(self, first: int, stop: int, r0: int, points: FloatArray) -> None:
        bs = self.block_start
        while True:
            c = self.open
            if c is None:
                if self.next_run >= len(self.runs) or self.runs[self.next_run][0] >= stop:
                    return
                a, b = self.runs[self.next_run]
                self.next_run += 1
                c = _Contour(self.next_run, a, b, bs)
                c.before = self._point(c.lo - 1, r0, points).copy()
                candidate = _circle_candidate(
                    [segment_of(self.starts[i], self.program.moves[i]) for i in range(a, b + 1)]
                )
                if candidate is not None and math.dist(self.starts[a], self.starts[b + 1]) <= 1e-6:
                    c.circle = CircleFit(candidate[1])  # fed as the rows come
                for axis in (0, 1):
                    c.top[axis] = c.low[axis] = float(c.before[axis])
                c.add(0, c.before.reshape(1, 2))
                self.open = c
            g0, g1 = max(c.lo, r0), min(c.hi, r0 + len(points))
            if g1 > g0:
                part = points[g0 - r0 : g1 - r0]
                x_top, x_low, y_top, y_low = self.kernels.extent(part)  # one pass
                c.top[0], c.low[0] = max(x_top, c.top[0]), min(x_low, c.low[0])
                c.top[1], c.low[1] = max(y_top, c.top[1]), min(y_low, c.low[1])
                c.add(g0 - c.lo + 1, part)
            for b in range(max(c.first, first), min(c.last, stop - 1) + 1):
                here = self._point(int(bs[b + 1]) - 1, r0, points)
                gap = math.dist(here, self.starts[b + 1]) * 1000.0
                if gap > self.end_worst[0]:
                    self.end_worst = (gap, self.starts[b + 1], b)
            if c.last >= stop:
                return
            c.last_point = self._point(c.hi - 1, r0, points).copy() if c.hi > c.lo else c.before
            self._close(c)
            self.open = None

    def _close(self, c: _Contour) -> None:
        program, starts = self.program, self.starts
        self.ends.append(math.dist(c.last_point, starts[c.last + 1]))
        fitted = None if c.circle is None else c.circle.result()
        self.contours.append(
            _contour_measure(
                program,
                starts,
                c.number,
                (c.first, c.last),
                c.before,
                c.last_point,
                c.extent(),
                lambda centre: None if fitted is None else fitted[2],
            )
        )
        ends = _LazyTree(c.ends())  # one k-d tree for every batch (when one is used)
        segments = len(ends.points) // 2  # a and b: views of the tree's ends, not the trace
        a, b = ends.points[:segments], ends.points[segments:]
        c.kept = []  # the trace is let go: ~6 MB of a 400 000-point contour
        self._shortfall(c, ends, a, b)

    def _shortfall(self, c: _Contour, ends: _LazyTree, a: FloatArray, b: FloatArray) -> None:
        """The largest shortfall of contour ``c`` from its thinned trace ``a → b`` (``ends``)."""
        program, starts = self.program, self.starts
        places: _Places | None = None  # made for the first batch that is bounded
        batches = _sample_batches(program, starts, c.first, c.last, self.spacing, STREAM_SAMPLES)
        for samples, owner, t in batches:  # each sample's distance is its own
            self.samples += len(samples)
            if len(samples) < SHORTFALL_BOUND_FROM:  # few: measured at once
                got: tuple[float, int] | None = farthest_nearest(samples, a, b, ends=ends)
            else:
                if places is None:
                    nominal = {k: v[c.first : c.last + 1] for k, v in self.nominal.items()}
                    places = _Places(a, b, _move_spans(c.n, c.every, c.keep), nominal)
                bounded = _Bounded(samples, owner - c.first, t, places, ends)
                got = bounded.farthest(self.worst[0] / 1000.0)  # none can pass the worst
            if got is None:
                continue
            far, k = got
            if far * 1000.0 > self.worst[0]:
                at = (float(samples[k, 0]), float(samples[k, 1]))
                self.worst = (far * 1000.0, at, int(owner[k]))

    def finish(self) -> StreamedMeasures:
        """The measures of the whole trace (after its last chunk)."""
        if self.dev_count == 0:
            dev = Deviation(0.0, 0.0, (0.0, 0.0), -1, 0)
        else:
            mean = self.kernels.exact_sum(self.bins) / self.dev_count if self.rms else math.nan
            at, block, _ = self.dev_where
            dev = Deviation(
                self.dev_max * 1000.0, math.sqrt(mean) * 1000.0, at, block, self.dev_count
            )
        along = AlongPath(
            shortfall_um=self.worst[0],
            shortfall_at_mm=self.worst[1],
            shortfall_block=int(self.worst[2]),
            block_end_um=self.end_worst[0],
            block_end_at_mm=(float(self.end_worst[1][0]), float(self.end_worst[1][1])),
            block_end_block=int(self.end_worst[2]),
            contour_end_um=tuple(e * 1000.0 for e in self.ends),
            samples=self.samples,
        )
        if self.dev_rows is not None:  # the worst point and the rows around it, unless kept
            rows, *columns = self.dev_rows
            new = rows % self.every_picture != 0
            points, blocks, steps, comp = columns
            self.picture.append((rows[new], points[new], blocks[new], steps[new], comp[new]))
        order = np.argsort(np.concatenate([p[0] for p in self.picture]), kind="stable")

        def joined(k: int) -> Any:
            return np.concatenate([p[k] for p in self.picture])[order]

        return StreamedMeasures(
            deviation=dev,
            along=along,
            contours=tuple(self.contours),
            picture_rows=joined(0),
            picture_mm=joined(1).reshape(-1, 2),
            picture_blocks=joined(2),
            picture_steps=joined(3).reshape(-1, 2),
            picture_compensation=joined(4),
            compensation_steps=(self.comp_steps[0], self.comp_steps[1]),
        )


NOT_CUT_KINDS = ("tight-corner", "offset-vanished", "uncut")
"""Plan finding kinds that say a feature cannot be cut as drawn with this tool."""


@dataclass(frozen=True)
class NotCut:
    """A feature of the drawing the planner reported it cannot cut as drawn.

    Attributes:
        kind: the plan finding's kind (one of :data:`NOT_CUT_KINDS`).
        at: where the feature is, mm: the drawing point farthest from the
            programmed path (a tight corner's vertex) or the finding's location.
        error_um: largest |d(q, trace) − r| over the drawing points of the feature, µm.
        samples: drawing points counted in this feature (left out of the main figure).
        value: the finding's size (a region's width mm, an area mm², ...), or ``None``.
    """

    kind: str
    at: Point
    error_um: float
    samples: int
    value: float | None = None

    @property
    def label(self) -> str:
        """A short name: ``"tight corner"``, ``"2 mm wide region"``, ``"uncut region"``."""
        if self.kind == "tight-corner":
            return "tight corner"
        if self.kind == "offset-vanished" and self.value is not None:
            return f"{fmt_num(self.value, 3).rstrip('0').rstrip('.')} mm wide region"
        return "uncut region" if self.kind == "uncut" else "region narrower than the tool"


class FindingLike(Protocol):
    """What :func:`against_drawing` reads of a plan finding.

    :class:`camtool.toolpath.cuts.Finding` is one.
    """

    @property
    def kind(self) -> str: ...  # noqa: D102
    @property
    def at(self) -> Point | None: ...  # noqa: D102
    @property
    def value(self) -> float | None: ...  # noqa: D102


@dataclass(frozen=True)
class Against:
    """The machined edge compared with the drawing.

    The machined edge is the trace swept by the tool radius r: a drawing point q
    is off by ``d(q, trace) − r`` (> 0: material left, < 0: cut too deep), and a
    trace point p gouges the drawing by ``r − d(p, drawing)`` where that is > 0.
    Drawing points of features the planner reported as impossible with this
    tool (:data:`NOT_CUT_KINDS`) are measured apart, in ``not_cut``.

    Attributes:
        max_um: largest |d(q, trace) − r| over the sampled drawing that was cut
            as drawn (``not_cut`` features left out), µm.
        rms_um: RMS of the same, µm.
        at_mm: drawing point where the max occurs.
        overcut_um: largest gouge of the drawing, µm (0 when none).
        samples: drawing points measured (all, features included).
        not_cut: the features not cut as drawn, each with its own error.
    """

    max_um: float
    rms_um: float
    at_mm: Point
    overcut_um: float
    samples: int
    not_cut: tuple[NotCut, ...] = ()

    @property
    def strict_max_um(self) -> float:
        """The largest error over the whole drawing, features not cut as drawn included, µm."""
        return max([self.max_um, *(f.error_um for f in self.not_cut)])


AGAINST_RESOLUTION_MM = 0.0005
"""Spacing :func:`against_drawing` thins the cutting trace to by default, mm."""


AGAINST_SPACING_MM = 0.005
"""Spacing of the drawing's points :func:`against_drawing` measures by default, mm."""
PREPARE_KERNELS_FROM = 20_000
"""Drawing points (100 mm of edge at :data:`AGAINST_SPACING_MM`) from which
:func:`prepare_comparison` loads the compiled nearest search: the comparisons of such a
drawing (and the shortfall of its toolpath) measure more than :data:`NEAR_KERNELS_FROM`
samples; the preview benchmark's part has 112 688, ``make demo``'s plate 48 577, its logo
6 911 (which keeps the k-d tree)."""


def prepare_comparison(drawing: Drawing) -> None:
    """Ahead of comparing traces with ``drawing`` here and in forked workers: make them once.

    The drawing's points are sampled now (and kept, as every comparison keeps its last
    drawing's) and, for a drawing of at least :data:`PREPARE_KERNELS_FROM` points, the
    compiled nearest search is loaded (:func:`near_kernels`) with the machine code of the
    kernels a comparison calls (:func:`_load_kernels`), so that workers forked next
    inherit both instead of each making them again (its loading alone is ~0.5 s). Only the
    time depends on it: the figures are the same.
    """
    samples, _ = _sample_drawing(drawing, AGAINST_SPACING_MM)
    if len(samples) >= PREPARE_KERNELS_FROM:
        _load_kernels()


def prepare_stream() -> None:
    """Ahead of streaming a trace here and in a forked helper: load what both call once.

    numba's compiler registries (its first call, ~0.2 s), the kernels the measures of
    every chunk call on its read-only carriage (``to_line``, ``extent``) and the
    compiled nearest search of the shortfall (:func:`near_kernels`, ``load_cached``),
    so that a helper forked next inherits them instead of loading them again, while this
    process would load them at its first chunk anyway. Only the time depends on it.
    """
    from camtool.verify.interpolators import compiled

    kernels = compiled()
    near = near_kernels()
    if kernels is None or near is None:
        return
    near.load_cached()
    points = np.zeros((2, 2))
    points.flags.writeable = False  # as a chunk's carriage comes
    kernels.to_line(points, 0.0, 0.0, 1.0, 0.0, np.zeros(2))
    kernels.extent(points)


def comparison_preloads(drawing: Drawing) -> list[Callable[[], object]]:
    """What :func:`prepare_comparison` will load for ``drawing``, as tasks for a wait.

    For a job that will compare a trace with ``drawing`` but first waits for another
    process (:func:`camtool.accel.cores.meanwhile`: ``post --preview`` waits ~0.4 s for
    the offsets' child to load OpenCASCADE): the compiled nearest search
    (:func:`near_kernels`, numba's import ~0.15 s), then numba's first call, which loads
    its compiler's registries (~0.2 s), then the machine code of the kernels a comparison
    calls (:func:`_load_kernels`, ~0.08 s), three tasks so that a short wait ends sooner;
    only when ``drawing`` has at least :data:`PREPARE_KERNELS_FROM` points at
    :data:`AGAINST_SPACING_MM` (counted, not sampled). Only the time depends on it. The
    drawing compared may be scaled from this one (``--fit``), so the count is an
    estimate; a wrong one costs time and memory, not figures.
    """
    count = sum(_contour_samples(c.segments, AGAINST_SPACING_MM) for c in drawing.contours)
    return [near_kernels, _first_call, _load_kernels] if count >= PREPARE_KERNELS_FROM else []


def _first_call() -> None:
    """Make :func:`near_kernels`' first call, on one point: numba loads its registries then."""
    kernels = near_kernels()
    if kernels is not None:
        kernels.build(np.zeros((1, 2)))


def _load_kernels() -> None:
    """:func:`near_kernels` with the kernels a comparison calls loaded (``load_cached``)."""
    kernels = near_kernels()
    if kernels is not None:
        kernels.load_cached()


def against_drawing(
    points: FloatArray,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    resolution_mm: float = AGAINST_RESOLUTION_MM,
    runs: IntArray | None = None,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
    overcut: bool = True,
) -> Against:
    """Compare a cutting trace with the drawing it was made from (shapely nearest queries).

    The trace is a polyline through its points, thinned to points about
    ``resolution_mm`` apart (never more than 400 000): a thinned-out point lies
    within about that distance of the polyline, so it bounds the error of this
    measure (the step-level deviation from the path is :func:`deviation`).

    With ``findings`` and the ``nominal`` path, the drawing points the planner
    could not cut as drawn (:func:`not_cut_groups`) are measured apart.

    Args:
        points: ``(N, 2)`` float64 cutting trace (rapids left out), mm, in the
            drawing's coordinates.
        drawing: the drawing.
        tool_radius_mm: tool radius; 0 for a scribing point or an engraving on the line.
        spacing_mm: largest distance between sampled drawing points, mm.
        resolution_mm: spacing of the thinned trace, mm.
        runs: ``(N,)`` id of the continuous cut each point belongs to (the rows
            between two rapids); the trace is not joined across two runs, so a
            rapid never counts as cutting. ``None``: one run.
        nominal: the programmed cutting path, one ``(M, 2)`` polyline (mm) per
            run of cutting moves.
        findings: the plan's findings; those of :data:`NOT_CUT_KINDS` with a
            location name the features measured apart.
        overcut: measure the overcut (``False``: ``overcut_um`` is 0, for a caller that
            reads only the other figures, as the error budget does).
    """
    return against_thinned(
        thin_cutting(points, runs, resolution_mm),
        drawing,
        tool_radius_mm,
        spacing_mm=spacing_mm,
        nominal=nominal,
        findings=findings,
        overcut=overcut,
    )


def thin_cutting(
    points: FloatArray, runs: IntArray | None, resolution_mm: float = AGAINST_RESOLUTION_MM
) -> ThinTrace:
    """The cutting trace thinned as :func:`against_drawing` compares it with the drawing.

    Every k-th row (about ``resolution_mm`` apart, read from the first
    :data:`CUT_HEAD_ROWS` rows; at most :data:`CUT_MAX_ROWS` of them), each run's first
    and last row and the last row (:func:`_thin_index`). :class:`CuttingStream` gives
    the same from a trace read chunk by chunk.

    Args:
        points: ``(N, 2)`` cutting rows, mm.
        runs: ``(N,)`` the run (cut between rapids) of each row, or ``None`` (one run).
        resolution_mm: the spacing aimed at, mm.
    """
    n = len(points)
    if n < 2:
        return ThinTrace(points, runs, n)
    every = _cut_every(points[: min(n, CUT_HEAD_ROWS)], resolution_mm)
    keep = _thin_index(n, _cut_limit(n, every), runs)
    return ThinTrace(points[keep], None if runs is None else runs[keep], n)


CUT_HEAD_ROWS = 2000
"""Cutting rows whose median step sets the thinning of :func:`against_drawing`."""
CUT_MAX_ROWS = 400_000
"""Most every-k-th rows :func:`against_drawing` keeps of the cutting trace."""


def _cut_every(head: FloatArray, resolution_mm: float) -> int:
    """Every how many rows the trace is about ``resolution_mm`` long (``head``: its first rows)."""
    step = _median_step(head)
    return max(1, int(resolution_mm / step)) if step > 0 else 1


def _cut_limit(n: int, every: int) -> int:
    """The ``limit`` of :func:`_thin_index` for ``n`` cutting rows thinned ``every`` rows."""
    return min(CUT_MAX_ROWS, math.ceil(n / every))


@dataclass(frozen=True, eq=False)
class ThinTrace:
    """A cutting trace thinned as :func:`against_drawing` thins it.

    Attributes:
        points: ``(K, 2)`` the rows kept (every k-th, each run's first and last, the
            last), mm, in trace order.
        runs: ``(K,)`` the run (continuous cut between rapids) of each, or ``None``
            (one run).
        rows: the cutting rows of the whole trace (``N``; ``K <= N``).
    """

    points: FloatArray
    runs: IntArray | None
    rows: int


class CutDigest:
    """A digest of a trace's cutting rows and their run ids, fed chunk by chunk.

    Two traces whose cutting rows (mm, as float64 bytes) and runs between rapids are the
    same have the same :meth:`digest` however they were cut into chunks, so the drawing
    comparison of one (it reads nothing else of the trace) is the other's: the error
    budget tells so without holding either trace whole. A different digest says only
    that they may differ (a ``-0.0`` is not a ``0.0`` here).

    Args:
        rapid: ``(B,)`` bool, which moves are rapids (their rows do not cut).
    """

    def __init__(self, rapid: npt.NDArray[np.bool_]) -> None:
        self.rapid = rapid
        self.gaps = 0  # rows that do not cut, so far (the run id is their count)
        self._rows = hashlib.sha256()
        self._runs = hashlib.sha256()

    def add(self, points: FloatArray, blocks: IntArray) -> tuple[FloatArray, IntArray]:
        """One chunk: its rows ``(R, 2)`` mm and the move of each; returns its cutting rows.

        The cutting rows ``(C, 2)`` and their run ids ``(C,) int64`` (the count of rows
        that do not cut before each, from the first chunk on).
        """
        cutting = ~self.rapid[blocks] if len(blocks) else np.zeros(0, dtype=bool)
        runs = (self.gaps + np.cumsum(~cutting, dtype=np.int64))[cutting]
        self.gaps += int(len(cutting) - np.count_nonzero(cutting))
        cut = points[cutting]
        self._rows.update(np.ascontiguousarray(cut, dtype="<f8").tobytes())
        self._runs.update(np.ascontiguousarray(runs, dtype="<i8").tobytes())
        return cut, runs

    def digest(self) -> bytes:
        """The digest of every chunk added so far."""
        return self._rows.digest() + self._runs.digest()


class CuttingStream:
    """The thinned cutting trace of :func:`against_drawing`, from a trace read chunk by chunk.

    Feed every chunk of the whole trace in order with :meth:`add` (the chunk's rows, mm,
    and the move of each row), then :meth:`finish`: the rows and run ids are those
    :func:`against_drawing` keeps of the whole trace's cutting rows (what
    :func:`camtool.verify.verifier._cutting_rows` gives), bit for bit, while no more
    than a chunk and :data:`CUT_HEAD_ROWS` rows are held besides the kept ones. The
    cutting rows are known in advance (``rows``: from the moves' row counts), so the
    every-k-th is known as soon as the first :data:`CUT_HEAD_ROWS` of them are read;
    the last row of each chunk waits for the next chunk to say whether a run ends there.

    Args:
        rapid: ``(B,)`` bool, which moves are rapids (their rows do not cut).
        rows: the cutting rows of the whole trace.
        resolution_mm: as for :func:`against_drawing`.
    """

    def __init__(self, rapid: npt.NDArray[np.bool_], rows: int, resolution_mm: float) -> None:
        self.rapid = rapid
        self.n = rows
        self.resolution_mm = resolution_mm
        self.k = 0  # the every-k-th, once the head is read
        self.seen = 0  # cutting rows given to _take (the carried one included)
        self.head: list[tuple[FloatArray, IntArray]] = []
        self.head_rows = 0
        self.carry: tuple[FloatArray, IntArray, bool] | None = None
        self.kept: list[tuple[FloatArray, IntArray]] = []
        self.digest = CutDigest(rapid)
        """The digest of the cutting rows seen (:class:`CutDigest`)."""

    def add(self, points: FloatArray, blocks: IntArray) -> None:
        """One chunk: its rows ``(R, 2)`` mm and the move of each row ``(R,)``."""
        cut, runs = self.digest.add(points, blocks)
        if not len(cut):
            return
        if self.k:
            self._take(cut, runs)
            return
        self.head.append((cut, runs))
        self.head_rows += len(cut)
        if self.head_rows >= min(self.n, CUT_HEAD_ROWS):
            self._start()

    def _start(self) -> None:
        """The every-k-th from the head, then the head's rows taken."""
        cut = np.concatenate([c for c, _ in self.head]) if self.head else np.zeros((0, 2))
        runs = np.concatenate([r for _, r in self.head]) if self.head else np.zeros(0, np.int64)
        self.head = []
        every = _cut_every(cut[:CUT_HEAD_ROWS], self.resolution_mm)
        self.k = _thin_step(self.n, _cut_limit(self.n, every)) if self.n else 1
        if len(cut):
            self._take(cut, runs)

    def _take(self, cut: FloatArray, runs: IntArray) -> None:
        """Keep what :func:`_thin_index` keeps of these consecutive cutting rows.

        Each row is kept when its index is a multiple of k, is the last, or starts or
        ends a run (:func:`_picked`); the last row given waits (``carry``) for the row
        after it, which says whether a run ends there.
        """
        first = self.seen
        if self.carry is not None:
            point, run, picked_before = self.carry
            cut = np.concatenate([point, cut])
            runs = np.concatenate([run, runs])
            first -= 1
        picked = _picked(first, len(cut), self.k, self.n, runs)
        if self.carry is not None:
            picked[0] |= picked_before
        self.kept.append((cut[:-1][picked[:-1]], runs[:-1][picked[:-1]]))
        self.carry = (cut[-1:], runs[-1:], bool(picked[-1]))
        self.seen = first + len(cut)

    def finish(self) -> ThinTrace:
        """The thinned cutting trace (after the last chunk).

        Raises:
            RuntimeError: the chunks did not hold the ``rows`` cutting rows announced.
        """
        if not self.k:
            self._start()
        if self.carry is not None:  # the last cutting row (n − 1): always kept
            point, run, _ = self.carry
            self.carry = None
            self.kept.append((point, run))
        if self.seen != self.n:
            raise RuntimeError(f"{self.seen} cutting rows streamed, {self.n} announced")
        points = np.concatenate([p for p, _ in self.kept]) if self.kept else np.zeros((0, 2))
        runs = np.concatenate([r for _, r in self.kept]) if self.kept else np.zeros(0, np.int64)
        return ThinTrace(points, runs, self.n)


def against_thinned(
    thin: ThinTrace,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
    overcut: bool = True,
) -> Against:
    """:func:`against_drawing` of a trace already thinned (:class:`ThinTrace`).

    The arguments are :func:`against_drawing`'s; ``thin`` is its thinned cutting trace
    (of a whole trace, or of one streamed by :class:`CuttingStream`).
    """
    samples, sizes = _sample_drawing(drawing, spacing_mm)
    if thin.rows < 2 or len(samples) == 0:
        return Against(0.0, 0.0, (0.0, 0.0), 0.0, 0)
    trace = thin.points
    off = nearest_distances(samples, *_chords(thin)) - tool_radius_mm
    apart = _not_cut(samples, sizes, tool_radius_mm, nominal, findings)
    main = _cut_as_drawn(len(samples), apart)
    features = [
        NotCut(
            kind=finding.kind,
            at=at,
            error_um=float(np.max(np.abs(off[index]))) * 1000.0,
            samples=len(index),
            value=finding.value,
        )
        for finding, index, at in apart
    ]
    if main.all():  # no feature apart: the arrays themselves, not copies
        kept, kept_at = off, samples
    elif main.any():
        kept, kept_at = off[main], samples[main]
    else:
        kept, kept_at = np.zeros(1), np.zeros((1, 2))
    worst = int(np.argmax(np.abs(kept)))
    overcut_um = 0.0
    if overcut and tool_radius_mm > 0:
        least = _least_nearest(trace, samples, sizes)
        overcut_um = max(0.0, float(tool_radius_mm - least)) * 1000.0
    return Against(
        max_um=float(abs(kept[worst])) * 1000.0,
        rms_um=float(np.sqrt(np.mean(kept * kept))) * 1000.0,
        at_mm=(float(kept_at[worst, 0]), float(kept_at[worst, 1])),
        overcut_um=overcut_um,
        samples=len(samples),
        not_cut=tuple(features),
    )


def against_worst(
    thin: ThinTrace,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
) -> float:
    """``against_thinned(...).max_um`` alone, the same float, for the error budget.

    The distance to the drawing of the samples cut as drawn is measured exactly only
    where it can be the largest (:func:`farthest_off`); the arguments are
    :func:`against_thinned`'s.
    """
    samples, sizes = _sample_drawing(drawing, spacing_mm)
    if thin.rows < 2 or len(samples) == 0:
        return 0.0
    main = _cut_as_drawn(len(samples), _not_cut(samples, sizes, tool_radius_mm, nominal, findings))
    if not main.any():
        return 0.0
    kept = samples if main.all() else samples[main]
    return farthest_off(kept, *_chords(thin), tool_radius_mm) * 1000.0


def _chords(thin: ThinTrace) -> tuple[FloatArray, FloatArray]:
    """The machined edge's segments: ``(a, b)`` joining consecutive rows of a run of ``thin``.

    A trace of single points (no two rows in one run) gives each point as a segment
    from the point to the next, so that their nearest distances still count.
    """
    trace, runs = thin.points, thin.runs
    joined = np.ones(len(trace) - 1, dtype=bool) if runs is None else runs[1:] == runs[:-1]
    if not joined.any():
        joined[:] = True
    count = int(np.count_nonzero(joined))
    ends = np.empty((2 * count, 2), dtype=np.float64)  # a then b: the search's ends, no copy
    np.compress(joined, trace[:-1], axis=0, out=ends[:count])
    np.compress(joined, trace[1:], axis=0, out=ends[count:])
    return ends[:count], ends[count:]


def _end_points(a: FloatArray, b: FloatArray) -> FloatArray:
    """``concatenate([a, b])``: the segments' ends, as the searches' trees hold them.

    Where ``a`` and ``b`` are already the two halves of one array of float64 (as
    :func:`_chords` makes them), that array itself: the same values, without a second copy
    of every end at the comparison's peak of memory (~11 MiB on the benchmark part).
    """
    base = a.base
    if (
        isinstance(base, np.ndarray)
        and base is b.base
        and base.dtype == np.float64
        and base.flags.c_contiguous
        and base.shape == (len(a) + len(b), 2)
        and a.flags.c_contiguous
        and b.flags.c_contiguous
        and a.ctypes.data == base.ctypes.data
        and b.ctypes.data == base.ctypes.data + a.nbytes
    ):
        return base
    return np.concatenate([a, b])


def _not_cut(
    samples: FloatArray,
    sizes: list[int],
    tool_radius_mm: float,
    nominal: Sequence[FloatArray],
    findings: Sequence[FindingLike],
) -> list[tuple[FindingLike, IntArray, Point]]:
    """:func:`not_cut_groups` of the drawing's ``samples`` when there is anything to group."""
    if not nominal or not any(f.kind in NOT_CUT_KINDS and f.at is not None for f in findings):
        return []
    nominal_off = _distance_to(samples, nominal) - tool_radius_mm
    return not_cut_groups(samples, _contour_ids(sizes), nominal_off, findings, tool_radius_mm)


def _cut_as_drawn(
    count: int, apart: list[tuple[FindingLike, IntArray, Point]]
) -> npt.NDArray[np.bool_]:
    """Which of ``count`` drawing samples are cut as drawn: in none of ``apart``'s groups.

    ``apart`` is :func:`_not_cut`'s: the samples a finding (an uncut feature) accounts for,
    which the comparison reports apart instead of in its largest distance and rms.
    """
    main = np.ones(count, dtype=bool)
    for _, index, _ in apart:
        main[index] = False
    return main


OVERCUT_PRUNE_FROM = 20_000
"""Trace points from which :func:`_least_nearest` measures only those that can be nearest."""
OVERCUT_ANCHOR = 4
"""Every how many trace points :func:`_least_nearest` measures first, to bound the others:
on the benchmark part (369 000 thinned trace points 1.5 mm from 112 000 drawing
chords) 92 000 anchors and 105 000 points left took 0.30 s where all took 0.55 s (every
8th: 0.41 s). Only the time depends on it."""


def _least_nearest(points: FloatArray, samples: FloatArray, sizes: list[int]) -> float:
    """``min(nearest_distances(points, chords))`` of the drawing's chords: the same float.

    The chords join consecutive ``samples`` of a contour (``sizes`` points each, as
    :func:`_sample_drawing` gives them). Only the least distance is wanted (the overcut).
    For many points, every :data:`OVERCUT_ANCHOR`-th (and the last) is measured first;
    a point's distance to the drawing is at least an anchor's less the distance between
    the two (the triangle inequality), and an anchor's exact distance is at least what
    :func:`nearest_distances` gives less :data:`NEAREST_TOLERANCE_MM`. Only the points
    whose bound from the anchors on either side, less a rounding margin, reaches the
    least anchor's distance are measured; each point's distance is its own, so the
    least of them is the least of all, bit for bit. ``inf`` without chords.
    """
    same = _same_contour(sizes)
    a, b = samples[:-1][same], samples[1:][same]
    n = len(points)
    if n == 0 or len(a) == 0:
        return math.inf
    if n < OVERCUT_PRUNE_FROM:
        return float(np.min(nearest_distances(points, a, b)))
    every = OVERCUT_ANCHOR
    anchors = np.append(np.arange(0, n - 1, every), n - 1)
    got = nearest_distances(points[anchors], a, b)
    upper = float(np.min(got))
    scale = max(_largest_magnitude(points), _largest_magnitude(samples))
    slack = NEAREST_TOLERANCE_MM + 1e-12 + 128.0 * float(np.spacing(scale))
    left = np.minimum(np.arange(n) // every, len(anchors) - 1)
    right = np.minimum(left + 1, len(anchors) - 1)
    lower = np.full(n, -math.inf)
    for side in (left, right):
        gap = np.hypot(*(points - points[anchors[side]]).T) * (1.0 + 1e-9)
        np.maximum(lower, got[side] * (1.0 - 1e-9) - gap - slack, out=lower)
    maybe = lower <= upper
    maybe[anchors] = False  # measured
    if not maybe.any():
        return upper
    return min(upper, float(np.min(nearest_distances(points[maybe], a, b))))


PLAN_TOLERANCE_MM = 0.002
"""Least distance of the programmed edge from the drawing that counts as "not as drawn", mm."""


def not_cut_groups(
    samples: FloatArray,
    contour_of: IntArray,
    nominal_off: FloatArray,
    findings: Sequence[FindingLike],
    tool_radius_mm: float,
) -> list[tuple[FindingLike, IntArray, Point]]:
    """The drawing points of each feature the plan reported as not cut as drawn.

    A feature is a stretch of one drawing contour where even the *programmed*
    edge (the nominal path swept by the tool) lies off the drawing by more than
    a threshold: ``max(PLAN_TOLERANCE_MM, 3 × the median such distance)`` (the
    median absorbs the dialect's rounding). A stretch belongs to a finding that
    names its contour: a ``tight-corner`` finding every stretch of the contour
    through its corner whose peak exceeds ``max(2 × threshold, r / 100)`` (the
    finding locates only the first of its corners), an ``offset-vanished`` one
    the stretches of the smallest contour around its location, an ``uncut`` one
    those within ``max(2r, 2√area)`` of its location on the nearest contour.
    Stretches no finding names stay in the main figure: the planner did not
    say why they are off.

    Args:
        samples: ``(S, 2)`` drawing points, mm, contour after contour.
        contour_of: ``(S,)`` index of the contour of each sample.
        nominal_off: ``(S,)`` distance of each sample from the programmed path
            minus the tool radius, mm.
        findings: plan findings; only :data:`NOT_CUT_KINDS` with a location count.
        tool_radius_mm: tool radius, mm.

    Returns:
        ``(finding, sample indices, location mm)`` per feature, in finding order.
    """
    size = np.abs(nominal_off)
    threshold = max(PLAN_TOLERANCE_MM, 3.0 * float(np.median(size)))
    stretches = _stretches(samples, contour_of, size > threshold)
    taken = [False] * len(stretches)
    out: list[tuple[FindingLike, IntArray, Point]] = []
    for finding in findings:
        if finding.kind not in NOT_CUT_KINDS or finding.at is None:
            continue
        at = np.asarray(finding.at, dtype=np.float64)
        contour = _named_contour(samples, contour_of, at, inside=finding.kind == "offset-vanished")
        for k, index in enumerate(stretches):
            if taken[k] or contour_of[index[0]] != contour:
                continue
            peak = int(index[np.argmax(size[index])])
            if finding.kind == "tight-corner":
                if size[peak] <= max(2.0 * threshold, tool_radius_mm / 100.0):
                    continue
                where = (float(samples[peak, 0]), float(samples[peak, 1]))
            else:
                if finding.kind == "uncut":
                    reach = max(2.0 * tool_radius_mm, 2.0 * math.sqrt(max(finding.value or 0, 0)))
                    if np.min(np.hypot(*(samples[index] - at).T)) > reach:
                        continue
                where = (float(at[0]), float(at[1]))
            taken[k] = True
            out.append((finding, index, where))
    return out


def _stretches(
    samples: FloatArray, contour_of: IntArray, flagged: npt.NDArray[np.bool_]
) -> list[IntArray]:
    """Runs of consecutive flagged samples of one contour (joined across a closed one's seam)."""
    out: list[IntArray] = []
    cuts = np.flatnonzero(np.diff(contour_of)) + 1  # samples come contour after contour
    for lo, hi in zip([0, *cuts.tolist()], [*cuts.tolist(), len(contour_of)], strict=True):
        idx = np.arange(lo, hi)
        f = flagged[idx]
        if not f.any():
            continue
        if f.all():
            out.append(idx)
            continue
        edges = np.flatnonzero(np.diff(f.astype(np.int8)))
        starts = [0, *(edges + 1).tolist()]
        pieces = [idx[a:b] for a, b in zip(starts, [*starts[1:], len(idx)], strict=True)]
        pieces = [p for p in pieces if flagged[p[0]]]
        closed = math.dist(samples[idx[0]], samples[idx[-1]]) <= 1e-9
        if (
            closed and f[0] and f[-1] and len(pieces) > 1
        ):  # the seam of a closed contour splits one run
            pieces = [np.concatenate([pieces[-1], pieces[0]]), *pieces[1:-1]]
        out.extend(pieces)
    return out


def _named_contour(
    samples: FloatArray, contour_of: IntArray, at: FloatArray, *, inside: bool
) -> int:
    """The contour a finding at ``at`` names: the smallest closed one around it, or the nearest."""
    if inside:
        import shapely

        best, best_area = -1, math.inf
        point = shapely.Point(at)
        for c in np.unique(contour_of):
            ring = samples[contour_of == c]
            if len(ring) < 4 or math.dist(ring[0], ring[-1]) > 1e-9:
                continue
            polygon = shapely.Polygon(ring)
            if polygon.is_valid and polygon.area < best_area and polygon.contains(point):
                best, best_area = int(c), polygon.area
        if best >= 0:
            return best
    return int(contour_of[np.argmin(np.hypot(*(samples - at).T))])


_DISTANCE_TO: list[tuple[FloatArray, Sequence[FloatArray], FloatArray]] = []
"""The last :func:`_distance_to` answer, with the very arrays it was for (kept, so their
``id`` is not reused): the error budget asks it again for the same samples and path."""


def _distance_to(samples: FloatArray, lines: Sequence[FloatArray]) -> FloatArray:
    """Distance of each sample to the nearest of ``lines`` (polylines ``(M, 2)``), mm.

    The same ``samples`` and ``lines`` objects as the last call, when they cannot change
    (read-only arrays, ``lines`` a tuple: see :func:`_sample_drawing` and
    :func:`camtool.verify.verifier._nominal_lines`), give the last answer again.
    """
    frozen = (
        not samples.flags.writeable
        and isinstance(lines, tuple)
        and not any(line.flags.writeable for line in lines)
    )
    if not frozen:
        return _distance_to_now(samples, lines)
    for seen_samples, seen_lines, answer in _DISTANCE_TO:
        if seen_samples is samples and seen_lines is lines:
            return answer
    answer = _distance_to_now(samples, lines)
    answer.flags.writeable = False
    _DISTANCE_TO[:] = [(samples, lines, answer)]
    return answer


def _distance_to_now(samples: FloatArray, lines: Sequence[FloatArray]) -> FloatArray:
    """:func:`_distance_to` without the kept answer."""
    import shapely

    chords = [np.stack([p[:-1], p[1:]], axis=1) for p in lines if len(p) > 1]
    singles = [p for p in lines if len(p) == 1]
    parts = []
    if chords:
        parts.append(shapely.linestrings(np.concatenate(chords)))
    if singles:
        parts.append(shapely.points(np.concatenate(singles)))
    if not parts:
        return np.full(len(samples), np.inf)
    tree = shapely.STRtree(np.concatenate(parts))
    _, d = tree.query_nearest(shapely.points(samples), return_distance=True, all_matches=False)
    return np.asarray(d, dtype=np.float64)


def _contour_ids(sizes: list[int]) -> IntArray:
    """``(S,)`` index of the contour of each point of :func:`_sample_drawing`."""
    return np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)


_SAMPLED: list[tuple[Drawing, float, FloatArray, list[int]]] = []
"""The last drawing :func:`_sample_drawing` sampled (the error budget compares the same
drawing once per source): the drawing itself is kept, so its ``id`` is not reused."""


def _sample_drawing(drawing: Drawing, spacing_mm: float) -> tuple[FloatArray, list[int]]:
    """Points along every contour, at most ``spacing_mm`` apart, and the count per contour.

    Contour after contour; the counts feed :func:`_contour_ids` and :func:`_same_contour`.
    The last drawing's points are kept (read-only) and given again for the same drawing.
    """
    for seen, spacing, samples, sizes in _SAMPLED:
        if seen is drawing and spacing == spacing_mm:
            return samples, list(sizes)
    samples, sizes = _sample_drawing_now(drawing, spacing_mm)
    samples.flags.writeable = False
    _SAMPLED[:] = [(drawing, spacing_mm, samples, list(sizes))]
    return samples, sizes


def _sample_drawing_now(drawing: Drawing, spacing_mm: float) -> tuple[FloatArray, list[int]]:
    """:func:`_sample_drawing` without the kept copy.

    The points are written into one array sized in advance (what stacking the
    contours' arrays gives, without holding them all twice: 9.6 M points of a
    213-icon drawing are 154 MB).
    """
    sizes = [_contour_samples(c.segments, spacing_mm) for c in drawing.contours]
    out = np.empty((sum(sizes), 2), dtype=np.float64)
    at = 0
    for contour, size in zip(drawing.contours, sizes, strict=True):
        out[at : at + size] = _sample_contour(contour.segments, spacing_mm)
        at += size
    return out, sizes


def _contour_samples(segments: tuple[Segment, ...], spacing_mm: float) -> int:
    """How many points :func:`_sample_contour` gives for ``segments``."""
    return sum(_segment_samples(seg, spacing_mm) for seg in segments) + 1


def _segment_samples(seg: Segment, spacing_mm: float) -> int:
    """Points :func:`_sample_contour` takes along ``seg`` (its end is the next one's start)."""
    return max(1, math.ceil(seg.length / spacing_mm))


def _sample_contour(segments: tuple[Segment, ...], spacing_mm: float) -> FloatArray:
    pts: list[Point] = []
    for seg in segments:
        n = _segment_samples(seg, spacing_mm)
        if isinstance(seg, Line):
            (x0, y0), (x1, y1) = seg.start, seg.end
            pts.extend((x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n))
        else:
            pts.extend(seg.point_at(k / n) for k in range(n))
    pts.append(segments[-1].end)
    return np.asarray(pts, dtype=np.float64)


def _same_contour(sizes: list[int]) -> npt.NDArray[np.bool_]:
    """Mask of the sample chords that join two points of the same contour.

    ``sizes``: points per contour, as :func:`_sample_drawing` gives them.
    """
    mask = np.ones(sum(sizes) - 1, dtype=bool)
    edge = 0
    for size in sizes[:-1]:
        edge += size
        mask[edge - 1] = False
    return mask


def _thin_index(n: int, limit: int, runs: IntArray | None) -> IntArray:
    """Indices of every k-th of ``n`` points, the last, and each run's first and last.

    Sorted, each once (a mask: what ``np.unique`` of the picks gives, without sorting).
    """
    return np.flatnonzero(_picked(0, n, _thin_step(n, limit), n, runs)).astype(np.int64)


def _thin_step(n: int, limit: int) -> int:
    """The k of :func:`_thin_index`: every k-th of ``n`` rows keeps at most ``limit``."""
    return max(1, math.ceil(n / limit))


def _picked(first: int, count: int, k: int, n: int, runs: IntArray | None) -> npt.NDArray[np.bool_]:
    """Which of the rows ``first .. first + count − 1`` (of ``n``) :func:`_thin_index` keeps.

    Every k-th row, the last one, and where ``runs`` (the run of each of these rows,
    ``None``: one run) changes the rows on both sides. A caller that gives a part of the
    rows (:class:`CuttingStream`) decides its last row with the part after it.
    """
    picked = np.zeros(count, dtype=bool)
    picked[(-first) % k :: k] = True
    if 0 <= n - 1 - first < count:
        picked[n - 1 - first] = True
    if runs is not None and count > 1:
        change = runs[1:] != runs[:-1]
        picked[1:] |= change
        picked[:-1] |= change
    return picked
