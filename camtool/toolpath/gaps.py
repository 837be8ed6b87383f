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

import numpy as np

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
    lengths = np.full(len(contours), np.nan)  # of the contours a gap was judged against
    kept, largest, offset = 0, 0.0, 0
    for lo in range(0, len(points), _QUERY_CHUNK):
        # the pairs of a run of ends at a time: all of them at once are ~100 bytes a pair,
        # and a dense drawing has tens of near ends per end
        a, b = tree.query(points[lo : lo + _QUERY_CHUNK], predicate="dwithin", distance=near)
        a = a + lo
        a, b = a[a < b], b[a < b]  # each pair once, in the order the tree gives them
        exact = _Exact(xy, a, b)
        keep = exact.above(np.arange(len(a)), joint)
        own = np.flatnonzero(keep & (owner[a] == owner[b]))  # a contour's own two ends
        share = GAP_SHARE * _lengths(contours, lengths, owner[a[own]])
        keep[own] = ~exact.above(own, share, inclusive=True)  # a "C": drawn open on
        # purpose (close_gaps leaves it too)
        two = np.flatnonzero(keep & exact.above(np.arange(len(a)), FREE_JOINT_MM))
        two = two[owner[a[two]] != owner[b[two]]]
        # two contours: ends further apart than half the shorter one are drawn apart, and
        # no --chain-tolerance joins them (geometry.chain.JOINT_SHARE)
        shorter = np.minimum(
            _lengths(contours, lengths, owner[a[two]]), _lengths(contours, lengths, owner[b[two]])
        )
        keep[two] = ~exact.above(two, JOINT_SHARE * shorter)
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


def _lengths(contours: Sequence[Contour], known: Any, indices: Any) -> Any:
    """The lengths (mm) of contours ``indices`` (an int array).

    Each is measured once into ``known`` (one per contour, NaN until measured), not kept on
    the contours.
    """
    need = np.unique(indices[np.isnan(known[indices])])
    known[need] = [contours[int(i)].length_unkept() for i in need]
    return known[indices]


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
        self.xy, self.a, self.b = xy, a, b
        d = xy[b] - xy[a]
        self.rough = np.hypot(d[:, 0], d[:, 1])

    def gap(self, k: int) -> float:
        return math.dist(self.xy[self.a[k]], self.xy[self.b[k]])

    def above(self, ks: Any, limit: Any, *, inclusive: bool = False) -> Any:
        """``(len(ks),) bool``: gap ``> limit`` (``>=`` with ``inclusive``) for pairs ``ks``.

        ``limit`` is one limit (mm) or one per pair (``(len(ks),)``).
        """
        rough = self.rough[ks]
        limit = np.broadcast_to(np.asarray(limit, dtype=np.float64), rough.shape)
        out = rough > limit
        near = np.flatnonzero(np.abs(rough - limit) <= _MARGIN * np.maximum(limit, 1e-300))
        for i in near:
            gap = self.gap(int(ks[i]))
            out[i] = gap >= limit[i] if inclusive else gap > limit[i]
        return out

    def smallest(self, ks: Any, count: int) -> list[int]:
        """The ``count`` pairs of ``ks`` with the least gaps, least first, ties in ``ks`` order."""
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
