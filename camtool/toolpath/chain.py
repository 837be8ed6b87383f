"""Chaining: join contours whose ends meet within a tolerance into longer contours.

The importers give one contour per entity; a drawing made of separate LINE and
ARC entities becomes closed contours here. A joint within ``tolerance`` is
snapped: the later segment starts exactly where the earlier one ends, so the
emitted code has no gaps. A contour whose ends meet within ``tolerance`` is
closed. :func:`close_gaps` then closes contours whose ends nearly meet (a larger
gap, reported).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment, distance
from camtool.model.units import fmt_point
from camtool.toolpath.cuts import Finding, where

_GAP_SHARE = 0.1  # a gap closed by close_gaps is shorter than this share of the contour
_MAX_CELLS = 2.0**40
"""Largest cell number of the end hash (keeps cell numbers small ints on huge drawings)."""


def chain(contours: Sequence[Contour], tolerance: float) -> list[Contour]:
    """Join open contours end to end where their ends meet within ``tolerance`` mm.

    Closed contours pass through unchanged. Open contours are extended forwards
    then backwards, reversing a neighbour where its far end is the one that
    meets; the first contour of a chain keeps its drawn direction. Layers and
    sources of the joined pieces are kept from the first piece.

    Args:
        contours: contours as read, mm.
        tolerance: largest gap, mm, that still counts as a joint (≥ 0; 0: ends
            must coincide).

    Returns:
        The chained contours, in the order their first pieces were given.

    Raises:
        ToolpathError: an open contour's end is not finite (importers refuse
            those; huge finite coordinates are fine).
    """
    if not tolerance >= 0:
        raise ValueError(f"chaining tolerance must be ≥ 0 mm, got {tolerance!r}")
    result: list[Contour] = []
    pieces = list(contours)
    grid = _EndGrid(tolerance, [c for c in pieces if not c.closed])
    for index, contour in enumerate(pieces):
        if not contour.closed:
            grid.add(index, contour)
    used: set[int] = set()
    for index, contour in enumerate(pieces):
        if contour.closed:
            result.append(contour)
            continue
        if index in used:
            continue
        used.add(index)
        segs = list(contour.segments)
        _extend(segs, pieces, grid, used, tolerance, forward=True)
        _extend(segs, pieces, grid, used, tolerance, forward=False)
        # One line cannot close on itself (zero-length lines are dropped on import);
        # one arc can: a full circle drawn as an ARC from 0° to 360°.
        meets = distance(segs[-1].end, segs[0].start) <= tolerance
        closed = meets and (len(segs) > 1 or isinstance(segs[0], Arc))
        if closed:
            segs[-1] = _with_end(segs[-1], segs[0].start)
        result.append(Contour(tuple(segs), closed, contour.layer, contour.source))
    return result


def _extend(
    segs: list[Segment],
    pieces: Sequence[Contour],
    grid: _EndGrid,
    used: set[int],
    tolerance: float,
    *,
    forward: bool,
) -> None:
    while True:
        here = segs[-1].end if forward else segs[0].start
        if not forward and distance(here, segs[-1].end) <= tolerance and len(segs) > 1:
            return  # already closed
        found = grid.nearest(here, used)
        if found is None:
            return
        index, at_start = found
        used.add(index)
        piece = pieces[index]
        if forward:
            nxt = piece if at_start else piece.reversed()
            new = list(nxt.segments)
            new[0] = _with_start(new[0], here)
            segs.extend(new)
        else:
            prv = piece.reversed() if at_start else piece
            new = list(prv.segments)
            new[-1] = _with_end(new[-1], here)
            segs[:0] = new


def _with_start(seg: Segment, p: Point) -> Segment:
    if isinstance(seg, Line):
        return Line(p, seg.end)
    return Arc(p, seg.end, seg.centre, seg.clockwise)


def _with_end(seg: Segment, p: Point) -> Segment:
    if isinstance(seg, Line):
        return Line(seg.start, p)
    return Arc(seg.start, p, seg.centre, seg.clockwise)


class _EndGrid:
    """Spatial hash of open-contour ends in square cells of at least ``tolerance``.

    Ends within ``tolerance`` of a point lie in its cell or the 8 around it. The
    cell is ``tolerance`` wide unless the drawing is so large that cell numbers
    would pass :data:`_MAX_CELLS` (then wider: any width ≥ ``tolerance`` works).

    Raises:
        ToolpathError: an end is not a finite point (the importers refuse those).
    """

    def __init__(self, tolerance: float, pieces: Sequence[Contour]) -> None:
        reach = max((max(abs(v) for v in (*c.start, *c.end)) for c in pieces), default=0.0)
        if not math.isfinite(reach):
            bad = next(c for c in pieces if not all(map(math.isfinite, (*c.start, *c.end))))
            raise ToolpathError(f"{where(bad)}: an end point is not finite; check the drawing")
        self.size = max(tolerance, reach / _MAX_CELLS) or 1.0  # 1.0: every end at (0, 0)
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


def close_gaps(
    contours: Sequence[Contour], max_gap: float, tolerance: float
) -> tuple[list[Contour], list[Finding]]:
    """Close open contours whose ends nearly meet, with a straight line across the gap.

    An open contour is closed when its ends are more than ``tolerance`` but at
    most ``max_gap`` apart and the gap is under a tenth of the contour's length
    (a deliberate "C" stays open). The drawn segments are kept exactly; one
    :class:`~camtool.model.shapes.Line` from the end back to the start is appended.
    Every closure is reported: the drawing is probably wrong there.

    Args:
        contours: chained contours, mm (see :func:`chain`).
        max_gap: largest gap closed, mm (≥ 0); 0 closes nothing.
        tolerance: the chaining tolerance, mm: gaps up to it were closed by
            :func:`chain` already.

    Returns:
        The contours in the same order (unchanged objects where nothing was
        closed) and one ``closed-gap`` :class:`~camtool.toolpath.cuts.Finding` per
        closure (``at`` the gap's midpoint, ``value`` the gap in mm).
    """
    out: list[Contour] = []
    findings: list[Finding] = []
    for contour in contours:
        gap = distance(contour.end, contour.start)
        if (
            contour.closed
            or max_gap <= 0
            or not tolerance < gap <= max_gap
            or gap >= _GAP_SHARE * contour.length
        ):
            out.append(contour)
            continue
        bridge = Line(contour.end, contour.start)
        out.append(Contour((*contour.segments, bridge), True, contour.layer, contour.source))
        mid = ((contour.start[0] + contour.end[0]) / 2, (contour.start[1] + contour.end[1]) / 2)
        findings.append(
            Finding(
                "closed-gap",
                f"{where(contour)}: closed a {gap:.4g} mm gap between its ends at "
                f"{fmt_point(mid)} mm with a straight line; check the drawing "
                "(--close-gap 0 keeps it open)",
                mid,
                gap,
            )
        )
    return out, findings
