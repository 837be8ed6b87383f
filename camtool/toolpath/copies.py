"""Contours drawn twice: a fill and its outline, a copy stacked on the original.

Drawing programs write one shape twice more often than users know: LibreOffice Draw and
Impress export a filled and outlined shape as a fill path and a stroke path of the same
points, icon sets draw a highlight as an outline over its own fill, and CAD drawings stack
copies of an entity (``camtool inspect`` lists them as duplicate segments). Planned as
drawn, each copy is cut again on the same path: a second pass of a pen, a drag knife or a
laser, or a mill re-cutting its own groove. The planner cuts each path once and says so.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from camtool.geometry.chain import closes_alone, with_end
from camtool.model.shapes import Arc, Contour, Line, Point, Segment, distance
from camtool.toolpath.cuts import Finding

if TYPE_CHECKING:
    from camtool.toolpath.order import Nesting

SAME_MM = 0.001
"""How far two ends or centres may differ for two contours to be one path, mm: 1 µm, below
the step of every machine camtool writes for, so the two would be one cut. Not
``--tolerance``: at 0.5 mm two circles 0.3 mm apart (a thin ring) would be one."""


def drop_copies(
    contours: Sequence[Contour],
    tolerance: float = SAME_MM,
    *,
    cut_before: Sequence[tuple[str, Sequence[Contour]]] = (),
) -> tuple[list[Contour], list[Finding], list[int]]:
    """``contours`` with each path once, and a ``copy`` finding per copy left out.

    A copy is open or closed as an earlier contour is and runs on its path: once runs of
    collinear lines and of arcs on one circle are joined in each (:func:`_canonical`, for
    the comparison only: a square of four LINEs is the copy of a polyline square starting
    at another corner, an edge split in two included; a CIRCLE of two ARCs), the two have
    as many segments, of the same kinds, with every end and arc centre within
    ``tolerance`` mm of the other's, run either way and, when closed, from any vertex. A
    copy drawn with other kinds (chords where the other has an arc) is not found and is
    cut twice, as drawn.

    Args:
        contours: the contours of one operation as chained, mm. Copies are looked for
            after chaining: a LibreCAD diamond whose middle line is drawn twice chains
            into one closed outline only through both; two stacked LINEs alone chain into
            one there-and-back contour and stay so.
        tolerance: how far two ends may differ and still be one, mm (> 0).
        cut_before: ``(who, contours)`` of the earlier operations of a job that cut as
            this one does (same tool, type, side and options): a contour on one of their
            paths is their copy (``who`` names the operation in the finding).

    Returns:
        The contours kept, in their order; a finding per copy naming the contour it
        repeats (the warnings name the first few and count the rest,
        :func:`~camtool.toolpath.cuts.finding_warnings`); and the indices in ``contours``
        of the copies of ``cut_before``'s paths (cut by the earlier operations, not here).
    """
    from camtool.model.units import fmt_point

    quantum = 4.0 * tolerance
    seen: dict[tuple[object, ...], list[tuple[Contour, Contour, str]]] = {}
    for who, paths in cut_before:
        for contour in paths:
            path = _canonical(contour, tolerance)
            seen.setdefault(_key(path, quantum), []).append((path, contour, who))
    kept: list[Contour] = []
    findings: list[Finding] = []
    repeated: list[int] = []  # copies of ``cut_before``'s paths
    for index, contour in enumerate(contours):
        path = _canonical(contour, tolerance)
        bucket = seen.setdefault(_key(path, quantum), [])
        first = next(((c, w) for p, c, w in bucket if _same(p, path, tolerance)), None)
        if first is None:
            bucket.append((path, contour, ""))
            kept.append(contour)
            continue
        other, who = first
        if who:
            repeated.append(index)
        here = f"contour {contour.source} at {fmt_point(contour.start)} mm"
        if who and other.source == contour.source:  # selected again: the job says so
            message = f"{here}: {who} cuts it already: cut once"
        else:
            repeats = (
                f"contour {other.source}, which {who} cuts," if who else f"contour {other.source}"
            )
            message = (
                f"{here} repeats {repeats} on its path (a fill and its outline, or a copy on "
                "top of it): cut once"
            )
        findings.append(Finding("copy", message, contour.start))
    return kept, findings, repeated


def drop_near_copies(
    contours: Sequence[Contour], nest: Nesting
) -> tuple[list[Contour], list[Finding], Nesting]:
    """``contours`` without one of each pair of closed contours within 10 µm all along.

    An outline drawn twice a few µm off (a copy moved by a snap, an export of the same shape
    rounded two ways, a circle over its polygon) is not a :func:`drop_copies` copy, yet
    planned as drawn the two cross or nest, and everything inside lies two outlines deep:
    a hole taken for an island and cut on its outside. ``nest.near`` (the pairs
    :func:`~camtool.toolpath.order.nesting` found within
    :data:`~camtool.toolpath.order.NEAR_MM` all along) names them; of each pair the one of
    more segments (a circle's polygon), or the later of as many, is left out, said in a
    ``copy`` finding, and the nesting follows.

    Returns:
        The contours kept, in their order; a finding per one left out; their nesting.
    """
    from camtool.model.units import fmt_num, fmt_point

    dropped: dict[int, tuple[int, float]] = {}
    for i, j, gap in nest.near:
        if i not in dropped and j not in dropped:
            if len(contours[j].segments) < len(contours[i].segments):
                i, j = j, i
            dropped[j] = (i, gap)
    if not dropped:
        return list(contours), [], nest
    findings = []
    for j in sorted(dropped):
        i, gap = dropped[j]
        copy = contours[j]
        findings.append(
            Finding(
                "copy",
                f"contour {copy.source} at {fmt_point(copy.start)} mm runs within "
                f"{fmt_num(gap)} mm of contour {contours[i].source} all along (the outline "
                "drawn twice, a little off): cut once",
                copy.start,
            )
        )
    kept = [c for k, c in enumerate(contours) if k not in dropped]
    return kept, findings, nest.without(set(dropped))


def one_way(
    contours: Sequence[Contour],
    joint_mm: float,
    tolerance: float = SAME_MM,
    *,
    open_too: bool = True,
) -> tuple[list[Contour], list[Finding]]:
    """``contours``, each that comes back on its own path cut one way, with a finding each.

    Two stacked copies of a line (or of a run of lines and arcs) chain end to end into a
    contour that goes out and back on one path, closed when it ends where it began: the
    tool would cut the path twice and, closed, find no area in it. Each such contour
    (within ``tolerance`` mm, as :func:`drop_copies`) becomes its way out: open, unless its
    own ends are ``joint_mm`` apart at most, as chaining closes a contour (two copies of
    a circle drawn as an ARC a hair short of 360° are that circle, closed). With
    ``open_too`` false a contour whose way out is open is kept as drawn: cut with a side,
    a closed polyline drawn out and back (LibreCAD's terminals) is a region of no area,
    and the offset says so (``offset-vanished``).

    Returns:
        The contours, in their order (the others the same objects), and a ``copy``
        finding per contour cut one way.
    """
    from camtool.model.units import fmt_point

    out: list[Contour] = []
    findings: list[Finding] = []
    for contour in contours:
        way = _one_way(contour, tolerance, joint_mm)
        if not (open_too or way.closed):
            way = contour
        out.append(way)
        if way is not contour:
            findings.append(
                Finding(
                    "copy",
                    f"contour {contour.source} at {fmt_point(contour.start)} mm runs back on "
                    "its own path (drawn twice, end to end): cut one way",
                    contour.start,
                )
            )
    return out, findings


def _one_way(contour: Contour, tolerance: float, joint_mm: float) -> Contour:
    """``contour``, or its way out when it comes back on the same path.

    Two stacked copies of a line (or of a run of lines and arcs) chain end to end into a
    contour that goes out and back, closed when it ends where it began; chained, it starts
    at a copy's end, where it turns back (a closed contour that does not is left as it is).
    """
    segments = contour.segments
    n = len(segments)
    if n % 2:
        return contour
    k = n // 2
    turn, back = segments[k - 1], segments[k]
    if not (_near(turn.start, back.end, tolerance) and _near(turn.end, back.start, tolerance)):
        return contour  # no turn half way: most contours end here
    if contour.closed and not _near(segments[-1].start, segments[0].end, tolerance):
        return contour
    if not all(
        _same_segment(segments[k - 1 - i].reversed(), segments[k + i], tolerance) for i in range(k)
    ):
        return contour
    way = list(segments[:k])
    meets = distance(way[-1].end, way[0].start) <= joint_mm
    closed = meets and (k > 1 or closes_alone(way[0]))
    if closed:
        way[-1] = with_end(way[-1], way[0].start)
    return dataclasses.replace(contour, segments=tuple(way), closed=closed)


def _canonical(contour: Contour, tolerance: float) -> Contour:
    """``contour`` with each run of collinear lines, and of arcs on one circle, joined.

    For comparing paths only (what is cut stays as drawn): consecutive lines that go on
    in one direction, every vertex between them within ``tolerance`` mm of the line
    through the run's ends, become one line; consecutive arcs of one direction, with
    their centres and radii within ``tolerance`` of the first's and less than a turn
    together, one arc (:data:`_RUN_MAX` segments at most). A closed contour's last and
    first runs join too, so that it begins at a corner; one that is a whole circle then
    begins at its point of angle 0 (+X from the centre).
    """
    segments = contour.segments
    if len(segments) == 1:
        if contour.closed and isinstance(segments[0], Arc):
            return _from_zero(contour, segments[0])
        return contour
    pairs = itertools.pairwise((segments[-1], *segments) if contour.closed else segments)
    if not any(_may_go_on(a, b, tolerance) for a, b in pairs):  # the first after the last
        return contour  # most contours: a corner or a new centre at every vertex
    runs: list[list[Segment]] = []
    for seg in segments:
        if (
            runs
            and len(runs[-1]) < _RUN_MAX
            and _may_go_on(runs[-1][-1], seg, tolerance)
            and _goes_on(runs[-1], [seg], tolerance)
        ):
            runs[-1].append(seg)
        else:
            runs.append([seg])
    wrap = len(runs[-1]) + len(runs[0]) <= _RUN_MAX
    if (
        contour.closed
        and len(runs) > 1
        and wrap
        and _may_go_on(runs[-1][-1], runs[0][0], tolerance)
        and _goes_on(runs[-1], runs[0], tolerance)
    ):
        runs[0] = runs.pop() + runs[0]
    merged = [_joined(run) for run in runs]
    if contour.closed and len(merged) == 1 and isinstance(merged[0], Arc):
        return _from_zero(contour, merged[0])
    if len(merged) == len(segments):
        return contour
    return dataclasses.replace(contour, segments=tuple(merged))


def _from_zero(contour: Contour, arc: Arc) -> Contour:
    """``contour``, a whole circle ``arc``, as the one arc from its point of angle 0."""
    zero = (arc.centre[0] + arc.radius, arc.centre[1])
    return dataclasses.replace(contour, segments=(Arc(zero, zero, arc.centre, arc.clockwise),))


def _may_go_on(a: Segment, b: Segment, tolerance: float) -> bool:
    """A quick test: whether ``b`` may go on from ``a`` on its line or circle (:func:`_goes_on`).

    Two lines: ``a``'s end within ``tolerance`` of the line from ``a``'s start to ``b``'s
    end, going on one way; two arcs: one direction, centres within ``tolerance``.
    """
    if type(a) is not type(b):
        return False
    if type(a) is Arc:
        return (
            a.clockwise == b.clockwise  # type: ignore[union-attr]
            and abs(a.centre[0] - b.centre[0]) <= tolerance  # type: ignore[union-attr]
            and abs(a.centre[1] - b.centre[1]) <= tolerance  # type: ignore[union-attr]
        )
    (x0, y0), (x1, y1), (x2, y2) = a.start, a.end, b.end
    ax, ay, bx, by = x1 - x0, y1 - y0, x2 - x1, y2 - y1
    if ax * bx + ay * by <= 0.0:
        return False
    cross = ax * by - ay * bx  # twice the triangle's area: the joint's distance × the chord
    return cross * cross <= tolerance * tolerance * ((x2 - x0) ** 2 + (y2 - y0) ** 2)


_RUN_MAX = 64
"""Segments joined at most into one (each joining checks the run's every vertex again): a
copy drawn with more in a row is not found, and is cut twice as drawn."""

_TURN = 2.0 * math.pi + 1e-9
"""A whole turn, radians: arcs joined in :func:`_canonical` sweep no more."""


def _goes_on(run: Sequence[Segment], more: Sequence[Segment], tolerance: float) -> bool:
    """Whether the segments ``more`` continue ``run`` on one line or circle, one way."""
    if all(isinstance(s, Line) for s in (*run, *more)):
        start, end = run[0].start, more[-1].end
        dx, dy = end[0] - start[0], end[1] - start[1]
        length = math.hypot(dx, dy)
        if length <= tolerance:
            return False
        for seg in (*run, *more):
            along = (seg.end[0] - seg.start[0]) * dx + (seg.end[1] - seg.start[1]) * dy
            if along <= 0.0:  # turns back
                return False
        for seg in (*run[1:], *more):  # every vertex between the ends
            px, py = seg.start[0] - start[0], seg.start[1] - start[1]
            if abs(px * dy - py * dx) > tolerance * length:
                return False
        return True
    if all(isinstance(s, Arc) for s in (*run, *more)):
        first = run[0]
        assert isinstance(first, Arc)
        return (
            all(
                isinstance(s, Arc)
                and s.clockwise == first.clockwise
                and _near(s.centre, first.centre, tolerance)
                and abs(s.radius - first.radius) <= tolerance
                for s in more
            )
            and sum(abs(s.sweep) for s in (*run, *more) if isinstance(s, Arc)) <= _TURN
        )
    return False


def _joined(run: Sequence[Segment]) -> Segment:
    """A run :func:`_goes_on` accepted, as one segment."""
    first = run[0]
    if len(run) == 1:
        return first
    if isinstance(first, Arc):
        return Arc(first.start, run[-1].end, first.centre, first.clockwise)
    return Line(first.start, run[-1].end)


def _key(contour: Contour, quantum: float) -> tuple[object, ...]:
    """What two copies share for sure: closedness, segment count, lowest vertex x and y.

    The lowest x and y of the vertices, on a coarse grid, are the same from any start and
    either way round, and need no arc's bounds worked out.
    """
    segments = contour.segments
    low_x = min(s.start[0] for s in segments)
    low_y = min(s.start[1] for s in segments)
    if not contour.closed:
        low_x, low_y = min(low_x, contour.end[0]), min(low_y, contour.end[1])
    return (contour.closed, len(segments), round(low_x / quantum), round(low_y / quantum))


def _same(a: Contour, b: Contour, tolerance: float) -> bool:
    """Whether ``b`` runs on ``a``'s path (either way; from any vertex when closed)."""
    for other in (b, b.reversed()):
        if not a.closed:
            if _aligned(a.segments, other.segments, 0, tolerance):
                return True
            continue
        start = other.segments[0].start
        for shift, seg in enumerate(a.segments):
            if _near(seg.start, start, tolerance) and _aligned(
                a.segments, other.segments, shift, tolerance
            ):
                return True
    return False


def _aligned(a: Sequence[Segment], b: Sequence[Segment], shift: int, tolerance: float) -> bool:
    n = len(a)
    return all(_same_segment(a[(i + shift) % n], b[i], tolerance) for i in range(n))


def _same_segment(s: Segment, t: Segment, tolerance: float) -> bool:
    if type(s) is not type(t):
        return False
    if not (_near(s.start, t.start, tolerance) and _near(s.end, t.end, tolerance)):
        return False
    if isinstance(s, Arc):
        assert isinstance(t, Arc)
        return s.clockwise == t.clockwise and _near(s.centre, t.centre, tolerance)
    return True


def _near(p: Point, q: Point, tolerance: float) -> bool:
    return abs(p[0] - q[0]) <= tolerance and abs(p[1] - q[1]) <= tolerance
