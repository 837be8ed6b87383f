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
from collections.abc import Sequence

from camtool.model.shapes import Arc, Contour, Point, Segment
from camtool.toolpath.cuts import Finding

SAME_MM = 0.001
"""How far two ends or centres may differ for two contours to be one path, mm: 1 µm, below
the step of every machine camtool writes for, so the two would be one cut. Not
``--tolerance``: at 0.5 mm two circles 0.3 mm apart (a thin ring) would be one."""


def drop_copies(
    contours: Sequence[Contour],
    tolerance: float = SAME_MM,
    *,
    cut_before: Sequence[tuple[str, Sequence[Contour]]] = (),
) -> tuple[list[Contour], list[Finding]]:
    """``contours`` with each path once, and a ``copy`` finding per copy left out.

    A copy is open or closed as an earlier contour is and has as many segments, of the same
    kinds, with every end and arc centre within ``tolerance`` mm of the earlier one's, run
    either way and, when closed, from any of its vertices. Lines and arcs only: a copy
    split differently (an arc where the other has chords) is not found and is cut twice,
    as drawn.

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
        The contours kept, in their order, and a finding per copy naming the contour it
        repeats (the warnings name the first few and count the rest,
        :func:`~camtool.toolpath.cuts.finding_warnings`).
    """
    from camtool.model.units import fmt_point

    quantum = 4.0 * tolerance
    seen: dict[tuple[object, ...], list[tuple[Contour, str]]] = {}
    for who, earlier in cut_before:
        for contour in earlier:
            seen.setdefault(_key(contour, quantum), []).append((contour, who))
    kept: list[Contour] = []
    findings: list[Finding] = []
    for contour in contours:
        bucket = seen.setdefault(_key(contour, quantum), [])
        first = next(((c, w) for c, w in bucket if _same(c, contour, tolerance)), None)
        if first is None:
            bucket.append((contour, ""))
            kept.append(contour)
            continue
        other, who = first
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
    return kept, findings


def one_way(
    contours: Sequence[Contour], tolerance: float = SAME_MM
) -> tuple[list[Contour], list[Finding]]:
    """``contours``, each that comes back on its own path cut one way, with a finding each.

    Two stacked copies of a line (or of a run of lines and arcs) chain end to end into a
    contour that goes out and back on one path, closed when it ends where it began: the
    tool would cut the line twice and, closed, find no area in it. Each such contour
    becomes its way out, an open contour (within ``tolerance`` mm, as :func:`drop_copies`).

    Returns:
        The contours, in their order (the others the same objects), and a ``copy``
        finding per contour cut one way.
    """
    from camtool.model.units import fmt_point

    out: list[Contour] = []
    findings: list[Finding] = []
    for contour in contours:
        way = _one_way(contour, tolerance)
        out.append(way)
        if way is not contour:
            findings.append(
                Finding(
                    "copy",
                    f"contour {contour.source} at {fmt_point(contour.start)} mm runs back on "
                    "its own path (a line drawn twice, end to end): cut one way",
                    contour.start,
                )
            )
    return out, findings


def _one_way(contour: Contour, tolerance: float) -> Contour:
    """``contour``, or its way out when it comes back on the same path (an open contour).

    Two stacked copies of a line (or of a run of lines and arcs) chain end to end into a
    contour that goes out and back, closed when it ends where it began.
    """
    segments = contour.segments
    n = len(segments)
    if n % 2:
        return contour
    k = n // 2
    for shift in range(n if contour.closed else 1):
        turn = segments[(shift + k - 1) % n]
        if not _same_segment(turn.reversed(), segments[(shift + k) % n], tolerance):
            continue
        way = [segments[(shift + i) % n] for i in range(n)]
        if all(_same_segment(way[k - 1 - i].reversed(), way[k + i], tolerance) for i in range(k)):
            return dataclasses.replace(contour, segments=tuple(way[:k]), closed=False)
    return contour


def _key(contour: Contour, quantum: float) -> tuple[object, ...]:
    """What two copies share for sure: closedness, segment count, the box on a coarse grid."""
    x0, y0, x1, y1 = contour.bbox()
    box = tuple(round(v / quantum) for v in (x0, y0, x1, y1))
    return (contour.closed, len(contour.segments), box)


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
