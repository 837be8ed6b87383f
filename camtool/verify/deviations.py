"""Deviation of a simulated trace from the nominal toolpath: each point to its own block's segment.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.model.program import ArcMove, Program, Rapid, segment_of
from camtool.model.shapes import Arc, Point

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


def move_starts(program: Program) -> _Starts:
    """The start of each move of ``program`` and the last one's end (see :class:`_Starts`)."""
    moves = program.moves
    xy = np.empty((len(moves) + 1, 2), dtype=np.float64)
    xy[0] = program.origin
    xy[1:, 0] = np.fromiter((m.x for m in moves), dtype=np.float64, count=len(moves))
    xy[1:, 1] = np.fromiter((m.y for m in moves), dtype=np.float64, count=len(moves))
    return _Starts(xy)


def nominal_arrays(
    program: Program, starts: Sequence[Point] | None = None
) -> dict[str, FloatArray]:
    """Per-move nominal geometry as arrays of shape ``(B,)`` (mm; ``kind`` 0 line, 1 arc, 2 rapid).

    Keys: ``kind, x0, y0, x1, y1, cx, cy, r, a0, sweep``; ``a0`` is the start
    angle and ``sweep`` the signed sweep of arcs (radians, CCW positive). The ends are
    views of one ``(B + 1, 2)`` array of the moves' starts (:func:`move_starts`); the
    rest six floats a move, built without a row object a move. ``starts``: the program's
    :func:`move_starts`, when the caller has them already.
    """
    if not isinstance(starts, _Starts):
        starts = move_starts(program)
    xy = starts.xy
    flat = array("d")
    start = program.origin
    for move in program.moves:
        if isinstance(move, ArcMove):
            arc = segment_of(start, move)
            assert isinstance(arc, Arc)
            a0 = math.atan2(start[1] - move.cy, start[0] - move.cx)
            flat.extend((1, move.cx, move.cy, arc.radius, a0, arc.sweep))
        else:
            flat.extend((2 if isinstance(move, Rapid) else 0, 0.0, 0.0, 0.0, 0.0, 0.0))
        start = (move.x, move.y)
    table = np.frombuffer(flat, dtype=np.float64).reshape(-1, 6)
    out = {name: table[:, i] for i, name in enumerate(("kind", "cx", "cy", "r", "a0", "sweep"))}
    out |= {"x0": xy[:-1, 0], "y0": xy[:-1, 1], "x1": xy[1:, 0], "y1": xy[1:, 1]}
    return out


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
