"""Warnings about a job's operations taken together: what none selects, what two cut.

Each is a line for the user (stderr, the program's header); none changes the program.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import groupby
from typing import TYPE_CHECKING

from camtool.model.shapes import Contour, Drawing, Mark

if TYPE_CHECKING:
    from camtool.jobs.job import Job
    from camtool.jobs.run import OperationRun


def unselected(
    drawing: Drawing,
    selected: Sequence[Contour],
    construction: Sequence[Contour],
    joint_mm: float,
    cut: Sequence[Contour] = (),
    close_gap: float = 0.0,
) -> list[str]:
    """One line per layer of the contours no operation selects (construction said apart).

    ``selected``: the contours of ``drawing`` the operations select (the pieces, as drawn:
    an operation may cut the chains they make, :func:`~camtool.jobs.selection.as_chained`).
    They are counted as chained ``joint_mm`` apart at most, gaps up to ``close_gap`` closed
    (as the planner would cut them): four LINEs of an open outline are one open contour.
    A chain on the path of one of ``cut`` (the operations' contours as planned: a fill
    whose outline an operation cuts) is cut there and not counted. Open chains whose own
    ends nearly meet (:func:`_near_closed`) are counted with the ``close_gap`` that closes
    them: left out of a ``closed = true`` selection, they may be parts drawn for a laser.
    """
    from camtool.geometry.chain import chain_members
    from camtool.toolpath.chain import as_cut
    from camtool.toolpath.copies import drop_copies

    taken = {id(c) for c in selected}
    taken |= {id(c) for c in construction}
    left: dict[str, list[Contour]] = {}
    for contour in drawing.contours:
        if id(contour) not in taken:
            left.setdefault(contour.layer, []).append(contour)
    out = []
    for layer, pieces in sorted(left.items()):
        chains = as_cut(chain_members(pieces, joint_mm)[0], close_gap, joint_mm)[0]
        contours = drop_copies(chains, cut_before=[("", cut)])[0]
        if not contours:
            continue
        opened = sum(not c.closed for c in contours)
        first = contours[0]
        out.append(
            f"not cut: {len(contours)} contour(s) on layer {layer!r} ({opened} open; first "
            f"{first.source or 'contour'} at ({first.start[0]:.4f}, {first.start[1]:.4f}) mm): "
            "no operation selects them" + _near_closed(contours, joint_mm)
        )
    return out


def _near_closed(contours: Sequence[Contour], joint_mm: float) -> str:
    """What closes the open ``contours`` whose own ends lie near (as ``post`` reports them).

    Near: further apart than ``joint_mm``, within :func:`camtool.toolpath.gaps.near_reach`
    (as ``post`` reports gaps) and under ``GAP_SHARE`` of the contour's length (what
    ``close_gap`` closes). ``""`` when none is.
    """
    from camtool.model.shapes import distance
    from camtool.model.units import fmt_num
    from camtool.toolpath.chain import GAP_SHARE
    from camtool.toolpath.gaps import near_reach, option_value

    reach = near_reach(joint_mm)
    gaps = [
        gap
        for c in contours
        if not c.closed
        and joint_mm < (gap := distance(c.end, c.start)) <= reach
        and gap < GAP_SHARE * c.length
    ]
    if not gaps:
        return ""
    return (
        f"; {len(gaps)} of them end within {fmt_num(max(gaps), 4)} mm of their start: "
        f"close_gap = {option_value(max(gaps))} in [job] closes them"
    )


def undrilled(drawing: Drawing, drilled: set[int]) -> list[str]:
    """One line per layer of the drawing's points (DXF POINTs, SVG dots) no operation drills.

    ``drilled``: the ``id`` of each of ``drawing.marks`` an operation selected.
    """
    left: dict[str, list[Mark]] = {}
    for mark in drawing.marks:
        if id(mark) not in drilled:
            left.setdefault(mark.layer, []).append(mark)
    return [
        f"not drilled: {len(marks)} point(s) on layer {layer!r} (first "
        f"{marks[0].source or 'POINT'} at ({marks[0].at[0]:.4f}, {marks[0].at[1]:.4f}) mm): no "
        "operation selects them (a drill operation with points = true drills them)"
        for layer, marks in sorted(left.items())
    ]


OVERLAPS_LISTED = 3
"""Operations :func:`overlaps` names one by one; the rest share one warning."""


def overlaps(runs: Sequence[OperationRun], job: Job) -> list[str]:
    """A warning for two operations of one kind that cut the same contour.

    The first :data:`OVERLAPS_LISTED` such operations are named with their contour; the
    others share one warning that numbers them (a job of hundreds of operations with one
    selection would write hundreds of lines).
    """
    if job.shorthand:
        return []
    out: list[str] = []
    seen: dict[tuple[str, str], OperationRun] = {}
    more: list[int] = []
    for run in runs:
        for contour in run.placed.contours:
            key = (run.operation.kind, contour.source)
            other = seen.get(key)
            if other is not None and other.number != run.number and contour.source:
                if len(out) < OVERLAPS_LISTED:
                    out.append(
                        f"{run.label} cuts {contour.source} on layer {contour.layer!r} again, "
                        f"as {other.label} does: is one selection too wide?"
                    )
                else:
                    more.append(run.number)
                break
            seen[key] = run
    if more:
        them = "operation" if len(more) == 1 else "operations"
        out.append(
            f"{len(more)} more {them} ({_numbers(more)}) cut a contour again that an "
            "earlier operation of their kind cuts: is a selection too wide?"
        )
    return out


def _numbers(numbers: Sequence[int]) -> str:
    """``[1, 2, 5, 6, 7, 9]`` as ``"1, 2, 5-7, 9"``: runs of three or more as ranges."""
    parts: list[str] = []
    for _, pairs in groupby(enumerate(numbers), lambda pair: pair[1] - pair[0]):
        run = [n for _, n in pairs]  # consecutive numbers
        parts += [f"{run[0]}-{run[-1]}"] if len(run) > 2 else [str(n) for n in run]
    return ", ".join(parts)


def holes_cut_outside(
    runs: Sequence[OperationRun], job: Job, paths: Sequence[Sequence[Contour]]
) -> list[str]:
    """A warning for a contour cut on its outside that lies inside another operation's.

    Within one operation a hole is cut on its inside (its nesting says it is a hole); a
    hole selected alone by an ``outside`` profile is cut outside itself, into the part.
    ``paths``: each run's contours as its plan chained them (gaps closed:
    :attr:`camtool.toolpath.plan.Plan.paths`), in the order of ``runs``; a hole drawn open
    by a hair, which the planner closes and cuts, is judged closed.
    """
    if job.shorthand:
        return []
    from camtool.toolpath.order import nesting

    closed = [(r, c) for r, ps in zip(runs, paths, strict=True) for c in ps if c.closed]
    outside = any(r.operation.kind == "profile outside" for r, _ in closed)
    if not outside or len({id(r) for r, _ in closed}) < 2:
        return []  # no contour of an outside profile, or none of another operation
    nest = nesting([c for _, c in closed])
    out: list[str] = []
    for i, (run, contour) in enumerate(closed):
        if run.operation.kind != "profile outside":
            continue
        around = [closed[j] for j in nest.parents[i] if closed[j][0] is not run]
        if around and not any(closed[j][0] is run for j in nest.parents[i]):
            other, outer = around[0]
            out.append(
                f"{run.label} cuts {contour.source or 'a contour'} on layer "
                f"{contour.layer!r} on its outside, but it lies inside "
                f"{outer.source or 'a contour'} of {other.label}: a hole cut outside itself "
                'cuts into the part; give that operation side = "inside"'
            )
    return out
