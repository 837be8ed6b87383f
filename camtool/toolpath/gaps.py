"""Open contours that nearly meet: say how far apart their ends are and what would join them.

Real CAD files leave gaps between entities that should meet. :func:`~camtool.geometry.chain.chain`
joins ends within ``--chain-tolerance`` and :func:`~camtool.toolpath.chain.close_gaps` closes a
contour whose own ends are within ``--close-gap``; what stays open is reported here, with the
value of the option that would join it, so that the user can decide (a deliberate open path
stays open).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from camtool.geometry.chain import joint_distance
from camtool.model.shapes import Contour, Point
from camtool.model.units import fmt_num, fmt_point
from camtool.toolpath.chain import GAP_SHARE
from camtool.toolpath.cuts import Finding, where
from camtool.toolpath.options import PlanOptions

NEAR_GAP_FACTOR = 100.0
"""Ends further apart than this many chaining tolerances (and than 0.1 mm) are not reported:
they are meant to be apart."""

MAX_REPORTED = 10
"""At most this many near gaps are reported one by one; the rest are counted."""


def open_gaps(contours: Sequence[Contour], options: PlanOptions) -> list[Finding]:
    """One ``open-gap`` finding per open contour end that lies near another open end.

    An end is *near* when the nearest other open end (of another contour, or the
    contour's own other end) is further than the chaining tolerance but within
    ``max(0.1 mm, NEAR_GAP_FACTOR × tolerance)``. The message names the contour, the gap
    and the ``--chain-tolerance`` (another contour) or ``--close-gap`` (its own
    ends) that would join it.

    Args:
        contours: chained and closed-where-possible contours, mm.
        options: ``chain_tolerance`` and ``close_gap``.

    Returns:
        The findings (``at`` the gap's midpoint, ``value`` the gap, mm), nearest first,
        at most :data:`MAX_REPORTED` plus one summary.
    """
    import numpy as np
    import shapely

    ends: list[tuple[int, Point]] = []
    for index, contour in enumerate(contours):
        if not contour.closed:
            ends += [(index, contour.start), (index, contour.end)]
    if len(ends) < 2:
        return []
    joint = joint_distance(options.chain_tolerance)
    near = max(0.1, NEAR_GAP_FACTOR * joint)
    xy = np.array([p for _, p in ends], dtype=np.float64)
    points = shapely.points(xy)
    tree = shapely.STRtree(points)
    pairs = tree.query(points, predicate="dwithin", distance=near)
    best: dict[tuple[int, int], float] = {}
    for a, b in zip(*pairs, strict=True):
        if a >= b:
            continue
        gap = math.dist(xy[a], xy[b])
        if gap > joint:
            best[(int(a), int(b))] = gap
    found: list[tuple[float, int, int]] = []
    for (a, b), gap in sorted(best.items(), key=lambda item: item[1]):
        if ends[a][0] == ends[b][0] and gap >= GAP_SHARE * contours[ends[a][0]].length:
            continue  # a "C": drawn open on purpose (close_gaps leaves it too)
        found.append((gap, a, b))
    # only the reported ones are written out (100 000 loose lines: 240 000 near pairs)
    out = [_finding(contours, ends[a], ends[b], gap, options) for gap, a, b in found[:MAX_REPORTED]]
    if len(found) > MAX_REPORTED:
        largest = max(g for g, _, _ in found)
        out.append(
            Finding(
                "open-gap",
                f"{len(found) - MAX_REPORTED} more open end(s) lie near another (gaps up to "
                f"{fmt_num(largest, 4)} mm); --chain-tolerance {_option_value(largest)} joins "
                "them all",
                value=largest,
            )
        )
    return out


def _finding(
    contours: Sequence[Contour],
    a: tuple[int, Point],
    b: tuple[int, Point],
    gap: float,
    options: PlanOptions,
) -> Finding:
    (ia, pa), (ib, pb) = a, b
    mid = ((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2)
    if ia == ib:
        fix = f"--close-gap {_option_value(gap)} closes it"
        what = f"{where(contours[ia])} stays open: its ends are {fmt_num(gap, 4)} mm apart"
    else:
        fix = f"--chain-tolerance {_option_value(gap)} joins them"
        what = (
            f"{where(contours[ia])} ends {fmt_num(gap, 4)} mm from {where(contours[ib])}, "
            "so both stay open"
        )
    return Finding("open-gap", f"{what} at {fmt_point(mid)} mm; {fix}", mid, gap)


def _option_value(gap: float) -> str:
    """A round option value just above ``gap`` mm (two significant digits, rounded up)."""
    digits = 1 - math.floor(math.log10(gap))
    step = 10.0**-digits
    return f"{math.ceil(gap / step * (1 + 1e-9)) * step:.{max(digits, 0)}f}"
