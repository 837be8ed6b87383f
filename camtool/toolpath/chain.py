"""Closing gaps: contours whose own ends nearly meet, closed with a reported line.

Chaining (contours whose ends meet within the tolerance, joined exactly) is the shared
:func:`camtool.geometry.chain.chain`; :func:`close_gaps` then closes contours whose ends
nearly meet (a larger gap, reported), and :func:`as_cut` takes chains the way the planner
cuts them (gaps closed, paths drawn out and back taken one way).
"""

from __future__ import annotations

from collections.abc import Sequence

from camtool.model.shapes import Contour, Line, distance
from camtool.model.units import fmt_point
from camtool.toolpath.copies import one_way
from camtool.toolpath.cuts import Finding, where

GAP_SHARE = 0.1
"""A gap :func:`close_gaps` closes is shorter than this share of its contour's length;
a longer one is a deliberate "C" (:func:`camtool.toolpath.gaps.open_gaps` skips it too)."""


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
        contours: chained contours, mm (see :func:`camtool.geometry.chain.chain`).
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
            or gap >= GAP_SHARE * contour.length
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


def as_cut(
    joined: Sequence[Contour], close_gap: float, joint_mm: float, *, open_too: bool = True
) -> tuple[list[Contour], list[Finding]]:
    """Chained contours as the planner cuts them, one per chain, in order.

    Gaps up to ``close_gap`` mm closed (:func:`close_gaps`), then each contour that comes
    back on its own path taken one way (:func:`~camtool.toolpath.copies.one_way`): in that
    order, which every judge of what is cut shares (the planner, a job's selection and its
    not-cut note, ``job init``).

    Args:
        joined: contours chained ``joint_mm`` apart at most
            (:func:`~camtool.geometry.chain.chain_members`), mm.
        close_gap: largest gap closed, mm (≥ 0).
        joint_mm: the chaining distance, mm.
        open_too: an open contour drawn out and back is taken one way too (as
            :func:`~camtool.toolpath.copies.one_way`'s); the planner under a side keeps it.

    Returns:
        The contours, and the ``closed-gap`` and ``copy`` findings.
    """
    closed, found = close_gaps(joined, close_gap, joint_mm)
    out, back = one_way(closed, joint_mm, open_too=open_too)
    return out, found + back
