"""Chaining: segments and contours whose ends meet within a tolerance, joined exactly.

Design notes: docs/internals.md, ``camtool/geometry/chain.py``.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence

from camtool.model.errors import GeometryError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment, distance
from camtool.model.units import fmt_point

_MAX_CELLS = 2.0**40
"""Largest cell number of the end hash (keeps cell numbers small ints on huge drawings)."""

MIN_JOINT_MM = 1e-9
"""Joint distance used for ``--chain-tolerance 0`` (only coincident ends meet)."""


def joint_distance(chain_tolerance: float) -> float:
    """The distance, mm, within which ends are joined for a ``--chain-tolerance`` in mm.

    ``max(chain_tolerance, MIN_JOINT_MM)``: 0 joins only ends that coincide to
    :data:`MIN_JOINT_MM`. The planner (:func:`camtool.toolpath.plan.plan_drawing`) and
    ``camtool inspect`` (:func:`camtool.importers.lint.inspect_drawing`) both chain at
    this distance, so what one calls closed the other does too.
    """
    return max(chain_tolerance, MIN_JOINT_MM)


def chain(contours: Sequence[Contour], tolerance: float) -> list[Contour]:
    """Join open contours end to end where their ends meet within ``tolerance`` mm.

    :func:`chain_members` without the members.
    """
    return chain_members(contours, tolerance)[0]


def chain_members(
    contours: Sequence[Contour], tolerance: float
) -> tuple[list[Contour], list[tuple[int, ...]]]:
    """Join open contours end to end where their ends meet within ``tolerance`` mm.

    Closed contours pass through unchanged. Open contours are extended forwards
    then backwards, reversing a neighbour where its far end is the one that
    meets; the first contour of a chain keeps its drawn direction. A gap wider than
    :data:`FREE_JOINT_MM` joins a piece (or closes a chain) only if it is at most
    :data:`JOINT_SHARE` of that piece's (chain's) length. Where more than
    two ends meet (a T, two rectangles drawn with a side in common), an open chain that
    comes back to a point it passed (within :data:`LOOP_JOINT_MM`) is split there: the loop
    between is a closed contour of its own (:func:`_loops`), not buried in an open chain a
    side offset leaves out. A
    chain that closes stays one contour (two triangles tip to tip, one figure of eight).
    Layer, source, colour and linetype of a chain are its first piece's (its lowest
    index); an open contour that joins nothing is returned as it was (the same object).

    Args:
        contours: contours as read, mm.
        tolerance: largest gap, mm, that still counts as a joint (≥ 0; 0: ends
            must coincide).

    Returns:
        The chained contours, in the order their first pieces were given, and for each
        the indices in ``contours`` of its pieces (in their order along it).

    Raises:
        GeometryError: an open contour's end is not finite (importers refuse
            those; huge finite coordinates are fine).
    """
    if not tolerance >= 0:
        raise ValueError(f"chaining tolerance must be ≥ 0 mm, got {tolerance!r}")
    result: list[Contour] = []
    members: list[tuple[int, ...]] = []
    pieces = list(contours)
    grid = _EndGrid(tolerance, [c for c in pieces if not c.closed])
    for index, contour in enumerate(pieces):
        if not contour.closed:
            grid.add(index, contour)
    used: set[int] = set()
    for index, contour in enumerate(pieces):
        if contour.closed:
            result.append(contour)
            members.append((index,))
            continue
        if index in used:
            continue
        used.add(index)
        parts: list[tuple[int, list[Segment]]] = [(index, list(contour.segments))]
        _extend(parts, pieces, grid, used, tolerance, forward=True)
        _extend(parts, pieces, grid, used, tolerance, forward=False)
        segs = [seg for _, piece in parts for seg in piece]
        # One line cannot close on itself (zero-length lines are dropped on import);
        # one arc can: a full circle drawn as an ARC from 0° to 360°, not a speck.
        if _closes(segs, tolerance):
            segs[-1] = with_end(segs[-1], segs[0].start)
            result.append(_joined(segs, True, contour))
            members.append(tuple(i for i, _ in parts))
            continue
        if len(parts) == 1:
            result.append(contour)  # nothing joined: the contour as it was
            members.append((index,))
            continue
        meet = min(tolerance, LOOP_JOINT_MM)
        if not _may_loop(parts, meet):
            result.append(_joined(segs, False, contour))
            members.append(tuple(i for i, _ in parts))
            continue
        for closed, run in sorted(_loops(parts, meet), key=lambda cr: min(i for i, _ in cr[1])):
            segs = [seg for _, piece in run for seg in piece]
            if closed:
                segs[-1] = with_end(segs[-1], segs[0].start)
            first = pieces[min(i for i, _ in run)]  # its first drawn piece: the seed, if there
            result.append(_joined(segs, closed, first))
            members.append(tuple(i for i, _ in run))
    return result, members


def _closes(segs: Sequence[Segment], tolerance: float) -> bool:
    """Whether a run of segments ending within ``tolerance`` of its start is closed.

    A gap wider than :data:`FREE_JOINT_MM` closes it only if it is short beside the
    run (:func:`_bridges`).
    """
    gap = distance(segs[-1].end, segs[0].start)
    if gap > tolerance or not (len(segs) > 1 or closes_alone(segs[0])):
        return False
    return _bridges(gap, Contour(tuple(segs), False))


FREE_JOINT_MM = 0.01
"""Gaps up to this (mm; the default ``--chain-tolerance``) join whatever the pieces' lengths."""

JOINT_SHARE = 0.5
"""A wider gap joins only a piece (or closes a chain) at least ``1 / JOINT_SHARE`` times as
long as the gap: a wide ``--chain-tolerance`` bridges gaps between pieces drawn to meet,
and must not snap one short line onto another a few of its lengths away (two 10 mm lines
50 mm apart at ``--chain-tolerance 100`` would make a line there and back, one never cut)."""


def _bridges(gap: float, piece: Contour) -> bool:
    """Whether a joint across ``gap`` mm may join (or close) ``piece``.

    Its length is measured only for a gap wider than :data:`FREE_JOINT_MM`, and not kept
    (:meth:`~camtool.model.shapes.Contour.length_unkept`).
    """
    return gap <= FREE_JOINT_MM or gap <= JOINT_SHARE * piece.length_unkept()


LOOP_JOINT_MM = 0.001
"""Farthest apart (mm) two joints of an open chain are for it to close a loop there
(:func:`_loops`), whatever the chaining tolerance: where pieces meet at a T or an X in a
drawing their ends coincide, while a larger ``--chain-tolerance`` (to bridge gaps) would
otherwise close a loop over every detail smaller than it (an arc of 0.2 mm LINEs at 0.5 mm
would be cut as 30 triangles)."""


def _cell_size(distance_mm: float, reach: float) -> float:
    """Width of a square cell to bin points ``distance_mm`` apart in, mm.

    ``distance_mm``, or wider on a drawing so large (``reach``, the largest coordinate)
    that cell numbers would pass :data:`_MAX_CELLS`; 1.0 when both are 0.
    """
    return max(distance_mm, reach / _MAX_CELLS) or 1.0


_FEW_JOINTS = 12
"""Most joints :func:`_may_loop` compares pair by pair; more are binned in arrays."""


def _may_loop(parts: list[tuple[int, list[Segment]]], tolerance: float) -> bool:
    """Whether two joints of an open chain may be within ``tolerance`` of each other.

    The joints are its ends and the points its pieces meet; a loop in it needs two of
    them to meet (:func:`_loops`). Exact for a few joints; for more, two points within
    ``tolerance`` share a cell of one of four grids of cells ``4 × tolerance`` wide (or
    wider on a huge drawing), shifted by half a cell along X, Y or both, so a ``False``
    is sure and a ``True`` only a maybe.
    """
    points = [parts[0][1][0].start, *(piece[-1].end for _, piece in parts)]
    if len(points) <= _FEW_JOINTS:
        return any(
            distance(p, q) <= tolerance for i, p in enumerate(points) for q in points[i + 1 :]
        )
    import numpy as np  # here: a re-post of lines chains nothing this long, and loads none

    xy = np.array(points, dtype=float)
    size = _cell_size(4.0 * tolerance, float(np.abs(xy).max()))
    for shift in ((0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)):
        cells = np.floor(xy / size + shift)  # whole numbers within ±2⁴⁰: exact
        keys = cells[:, 0] + 1j * cells[:, 1]
        if len(np.unique(keys)) < len(keys):
            return True
    return False


def _joined(segs: list[Segment], closed: bool, first: Contour) -> Contour:
    """A chain of ``segs`` named and styled as its piece ``first``."""
    return Contour(tuple(segs), closed, first.layer, first.source, first.colour, first.linetype)


def _loops(
    parts: list[tuple[int, list[Segment]]], tolerance: float
) -> list[tuple[bool, list[tuple[int, list[Segment]]]]]:
    """An open chain's pieces as closed loops and what is left of the chain.

    Where several pieces' ends meet at one point (a drawing's T or X, two rectangles
    sharing a side), the chain follows one of them and may come back to a point it has
    passed: the pieces between are a closed loop in the chain. Each such loop is taken
    out as a closed contour (the latest point met again first, so the smallest loops),
    and the pieces left join where it was (the next one moved by at most ``tolerance``
    onto the end before it). Only the points where pieces meet count, not the vertices
    inside a piece (a polyline drawn crossing itself stays one contour).

    Args:
        parts: the chain's pieces in order, each (index, its segments, oriented and
            snapped end to start); the chain does not close.
        tolerance: how far apart two joints may be to be one, mm
            (:data:`LOOP_JOINT_MM` at most).

    Returns:
        ``(closed, pieces)`` per contour: the loops taken out (closed), then the rest of
        the chain (open), if any is left.
    """
    reach = max(max(abs(v) for v in (*piece[0].start, *piece[-1].end)) for _, piece in parts)
    size = _cell_size(tolerance, reach)
    out: list[tuple[bool, list[tuple[int, list[Segment]]]]] = []
    stack: list[tuple[int, list[Segment]]] = []
    starts: dict[tuple[int, int], list[int]] = defaultdict(list)  # cell → stack positions

    def cell(p: Point) -> tuple[int, int]:
        return (math.floor(p[0] / size), math.floor(p[1] / size))

    def met(p: Point) -> int | None:
        """The latest stack position whose start meets ``p`` and closes a loop there."""
        cx, cy = cell(p)
        best = None
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for k in starts.get((cx + dx, cy + dy), ()):
                    if (best is None or k > best) and distance(
                        stack[k][1][0].start, p
                    ) <= tolerance:
                        last = stack[k][1]  # a loop of one piece: as a chain of one closes
                        if k < len(stack) - 1 or len(last) > 1 or closes_alone(last[0]):
                            best = k
        return best

    for index, segs in parts:
        if stack and segs[0].start != stack[-1][1][-1].end:
            segs = [with_start(segs[0], stack[-1][1][-1].end), *segs[1:]]
        starts[cell(segs[0].start)].append(len(stack))
        stack.append((index, segs))
        k = met(segs[-1].end)
        if k is not None:
            out.append((True, stack[k:]))
            for gone in range(k, len(stack)):
                starts[cell(stack[gone][1][0].start)].remove(gone)
            del stack[k:]
    if stack:  # starts where the chain does and ends where it ends: open, as it is
        out.append((False, stack))
    return out


def _extend(
    parts: list[tuple[int, list[Segment]]],
    pieces: Sequence[Contour],
    grid: _EndGrid,
    used: set[int],
    tolerance: float,
    *,
    forward: bool,
) -> None:
    while True:
        here = parts[-1][1][-1].end if forward else parts[0][1][0].start
        several = len(parts) > 1 or len(parts[0][1]) > 1
        if not forward and several and distance(here, parts[-1][1][-1].end) <= tolerance:
            return  # already closed
        found = grid.nearest(here, used)
        if found is None:
            return
        index, at_start = found
        piece = pieces[index]
        end = piece.segments[0].start if at_start else piece.segments[-1].end
        if not _bridges(distance(here, end), piece):
            return  # a gap as long as the piece is no joint: the piece is another line
        used.add(index)
        if forward:
            nxt = piece if at_start else piece.reversed()
            new = list(nxt.segments)
            new[0] = with_start(new[0], here)
            parts.append((index, new))
        else:
            prv = piece.reversed() if at_start else piece
            new = list(prv.segments)
            new[-1] = with_end(new[-1], here)
            parts.insert(0, (index, new))


def with_start(seg: Segment, p: Point) -> Segment:
    """``seg`` moved to start exactly at ``p`` (an arc keeps its centre and direction).

    An arc shorter than the move may pass its other end: :func:`moved_arc` makes it a line.
    """
    if isinstance(seg, Line):
        return Line(p, seg.end)
    return moved_arc(seg, p, seg.end)


def with_end(seg: Segment, p: Point) -> Segment:
    """``seg`` moved to end exactly at ``p`` (an arc keeps its centre and direction).

    An arc shorter than the move may pass its other end: :func:`moved_arc` makes it a line.
    """
    if isinstance(seg, Line):
        return Line(seg.start, p)
    return moved_arc(seg, seg.start, p)


def moved_arc(arc: Arc, start: Point, end: Point) -> Segment:
    """``arc`` with its ends moved (by a joint's few µm) to ``start`` and ``end``, mm.

    The arc keeps its centre and direction, unless the move turned it inside out: an arc
    shorter than the move whose end was moved back past its start (or its start past its
    end) would run the other way round, nearly its whole circle (a 0.004 mm ARC of radius
    50 would be cut as a 100 mm circle). Such an arc is the line between the two points
    instead: it was within the move of both.
    """
    moved = Arc(start, end, arc.centre, arc.clockwise)
    if abs(moved.sweep) > abs(arc.sweep) + math.pi:
        return Line(start, end)
    return moved


def closes_alone(seg: Segment) -> bool:
    """Whether one segment whose ends meet is a closed contour: an arc round most of its circle.

    A line never is; an arc whose ends are a joint apart is either nearly a full circle
    (drawn as an ARC from 0° to 360°, or a path's circle whose end misses its start by
    a rounding) or a speck shorter than the joint, which stays the open speck it is.
    """
    return isinstance(seg, Arc) and abs(seg.sweep) > math.pi


class _EndGrid:
    """Spatial hash of open-contour ends in square cells of at least ``tolerance``.

    Ends within ``tolerance`` of a point lie in its cell or the 8 around it. The
    cell is ``tolerance`` wide unless the drawing is so large that cell numbers
    would pass :data:`_MAX_CELLS` (then wider: any width ≥ ``tolerance`` works).

    Raises:
        GeometryError: an end is not a finite point (the importers refuse those).
    """

    def __init__(self, tolerance: float, pieces: Sequence[Contour]) -> None:
        reach = max((max(abs(v) for v in (*c.start, *c.end)) for c in pieces), default=0.0)
        if not math.isfinite(reach):
            bad = next(c for c in pieces if not all(map(math.isfinite, (*c.start, *c.end))))
            src = f"{bad.source} " if bad.source else ""
            raise GeometryError(
                f"contour {src}at {fmt_point(bad.start)} mm: an end point is not finite; "
                "check the drawing"
            )
        self.size = _cell_size(tolerance, reach)
        self.tolerance = tolerance
        self.cells: dict[tuple[int, int], list[tuple[int, bool, Point]]] = defaultdict(list)

    def _cell(self, p: Point) -> tuple[int, int]:
        return (math.floor(p[0] / self.size), math.floor(p[1] / self.size))

    def add(self, index: int, contour: Contour) -> None:
        for at_start, p in ((True, contour.start), (False, contour.end)):
            self.cells[self._cell(p)].append((index, at_start, p))

    def nearest(self, p: Point, used: set[int]) -> tuple[int, bool] | None:
        cx, cy = self._cell(p)
        cells, tol = self.cells, self.tolerance
        px, py = p
        best: tuple[float, int, bool] | None = None
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for index, at_start, q in cells.get((cx + dx, cy + dy), ()):
                    if index in used:
                        continue
                    d = math.hypot(q[0] - px, q[1] - py)
                    if d > tol:
                        continue
                    if best is None or (d, index) < (best[0], best[1]):
                        best = (d, index, at_start)
        return None if best is None else (best[1], best[2])


def snap(segs: Sequence[Segment]) -> list[Segment]:
    """Make each segment start exactly where the one before ends (pieces meet to ~1e-15).

    Args:
        segs: at least one segment, each starting near the end of the one before, mm.

    Returns:
        The segments, every start but the first moved onto the end before it.
    """
    out = [segs[0]]
    for seg in segs[1:]:
        prev = out[-1].end
        if seg.start != prev:
            seg = with_start(seg, prev)
        out.append(seg)
    return out
