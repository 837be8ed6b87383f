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
from typing import Any

from camtool.geometry.chain import FREE_JOINT_MM, JOINT_SHARE, joint_distance
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
    ``max(0.1 mm, NEAR_GAP_FACTOR × tolerance)``, and the gap is one chaining would
    bridge: under a tenth of the contour's length for its own ends (a "C" is drawn open),
    and for two contours within :data:`~camtool.geometry.chain.FREE_JOINT_MM` or under
    :data:`~camtool.geometry.chain.JOINT_SHARE` of the shorter one's length. The message
    names the contour, the gap and the ``--chain-tolerance`` (another contour) or
    ``--close-gap`` (its own ends) that would join it.

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
    near = near_reach(joint)
    xy = np.array([p for _, p in ends], dtype=np.float64)
    owner = np.array([index for index, _ in ends])
    points = shapely.points(xy)
    tree = shapely.STRtree(points)
    least: list[tuple[float, int, int, int]] = []  # (gap, pair number, a, b)
    lengths: dict[int, float] = {}  # of the contours a wide gap was judged against
    kept, largest, offset = 0, 0.0, 0
    for lo in range(0, len(points), _QUERY_CHUNK):
        # the pairs of a run of ends at a time: all of them at once are ~100 bytes a pair,
        # and a dense drawing has tens of near ends per end
        a, b = tree.query(points[lo : lo + _QUERY_CHUNK], predicate="dwithin", distance=near)
        a = a + lo
        a, b = a[a < b], b[a < b]  # each pair once, in the order the tree gives them
        exact = _Exact(xy, a, b)
        keep = exact.above(np.arange(len(a)), joint)
        for k in np.flatnonzero(keep & (owner[a] == owner[b])):  # a contour's own two ends
            share = GAP_SHARE * contours[owner[a[k]]].length_unkept()
            keep[k] = not exact.above(np.array([k]), share, inclusive=True)[0]  # a "C": drawn
            # open on purpose (close_gaps leaves it too)
        wide = exact.above(np.arange(len(a)), FREE_JOINT_MM)
        for k in np.flatnonzero(keep & wide & (owner[a] != owner[b])):
            # two contours: ends further apart than half the shorter one are drawn
            # apart, and no --chain-tolerance joins them (geometry.chain.JOINT_SHARE)
            shorter = min(
                _length(contours, lengths, owner[a[k]]), _length(contours, lengths, owner[b[k]])
            )
            keep[k] = not exact.above(np.array([k]), JOINT_SHARE * shorter)[0]
        near_gaps = np.flatnonzero(keep)  # the near gaps, in the order the tree gives them
        if len(near_gaps):
            kept += len(near_gaps)
            largest = max(largest, exact.largest(near_gaps))
            least += [
                (exact.gap(k), offset + k, int(a[k]), int(b[k]))
                for k in exact.smallest(near_gaps, MAX_REPORTED)
            ]
            least = sorted(least)[:MAX_REPORTED]
        offset += len(a)
    out = [_finding(contours, ends[ia], ends[ib], gap, options) for gap, _, ia, ib in least]
    if kept > MAX_REPORTED:
        out.append(
            Finding(
                "open-gap",
                f"{kept - MAX_REPORTED} more open end(s) lie near another (gaps up to "
                f"{fmt_num(largest, 4)} mm); --chain-tolerance {option_value(largest)} joins "
                "them all",
                value=largest,
            )
        )
    return out


def _length(contours: Sequence[Contour], known: dict[int, float], index: Any) -> float:
    """Contour ``index``'s length, mm, measured once (``known``), not kept on the contour."""
    i = int(index)
    if i not in known:
        known[i] = contours[i].length_unkept()
    return known[i]


def near_reach(joint_mm: float) -> float:
    """How far apart (mm) open ends may lie and still be reported as a gap to join.

    ``max(0.1 mm, NEAR_GAP_FACTOR × joint_mm)`` for the chaining distance ``joint_mm``:
    further apart, they are meant to be apart.
    """
    return max(0.1, NEAR_GAP_FACTOR * joint_mm)


class _Exact:
    """The gaps of pairs of ends ``xy[a[k]]``, ``xy[b[k]]``: what ``math.dist`` gives, in bulk.

    numpy's ``hypot`` and ``math.dist`` may differ in the last bit, so numpy decides only
    what a relative margin of :data:`_MARGIN` (far above an ulp) leaves certain; every
    comparison within it, and every value written out or ordered, is ``math.dist``'s.
    """

    def __init__(self, xy: Any, a: Any, b: Any) -> None:
        import numpy as np

        self.xy, self.a, self.b = xy, a, b
        d = xy[b] - xy[a]
        self.rough = np.hypot(d[:, 0], d[:, 1])

    def gap(self, k: int) -> float:
        return math.dist(self.xy[self.a[k]], self.xy[self.b[k]])

    def above(self, ks: Any, limit: float, *, inclusive: bool = False) -> Any:
        """``(len(ks),) bool``: gap ``> limit`` (``>=`` with ``inclusive``) for pairs ``ks``."""
        import numpy as np

        rough = self.rough[ks]
        out = rough > limit
        near = np.flatnonzero(np.abs(rough - limit) <= _MARGIN * max(limit, 1e-300))
        for i in near:
            gap = self.gap(int(ks[i]))
            out[i] = gap >= limit if inclusive else gap > limit
        return out

    def smallest(self, ks: Any, count: int) -> list[int]:
        """The ``count`` pairs of ``ks`` with the least gaps, least first, ties in ``ks`` order."""
        import numpy as np

        if len(ks) == 0:
            return []
        rough = self.rough[ks]
        bound = np.partition(rough, min(count, len(ks)) - 1)[min(count, len(ks)) - 1]
        maybe = ks[rough <= bound * (1.0 + _MARGIN)]  # the exact least are among these
        return sorted((int(k) for k in maybe), key=lambda k: (self.gap(k), k))[:count]

    def largest(self, ks: Any) -> float:
        """The largest gap of the pairs ``ks`` (at least one)."""
        rough = self.rough[ks]
        maybe = ks[rough >= rough.max() * (1.0 - _MARGIN)]
        return max(self.gap(int(k)) for k in maybe)


_QUERY_CHUNK = 1024
"""Ends whose near pairs :func:`open_gaps` looks for at a time (bounds its arrays)."""
_MARGIN = 1e-9
"""Relative band around a limit within which the exact gap decides (an ulp is ~2e-16)."""


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
        fix = f"--close-gap {option_value(gap)} closes it"
        what = f"{where(contours[ia])} stays open: its ends are {fmt_num(gap, 4)} mm apart"
    else:
        fix = f"--chain-tolerance {option_value(gap)} joins them"
        what = (
            f"{where(contours[ia])} ends {fmt_num(gap, 4)} mm from {where(contours[ib])}, "
            "so both stay open"
        )
    return Finding("open-gap", f"{what} at {fmt_point(mid)} mm; {fix}", mid, gap)


def option_value(gap: float) -> str:
    """A round option value just above ``gap`` mm (two significant digits, rounded up).

    ``gap`` > 0; ``0.1414`` gives ``"0.15"``, ``0.04`` ``"0.041"``.
    """
    digits = 1 - math.floor(math.log10(gap))
    step = 10.0**-digits
    return f"{math.ceil(gap / step * (1 + 1e-9)) * step:.{max(digits, 0)}f}"
