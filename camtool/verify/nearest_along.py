"""GEOS's distance from points taken along a path to the nearest of many segments.

All inputs in mm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import itertools

import numpy as np
import numpy.typing as npt

from camtool.verify import nearest_exact

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


ALONG_BLOCK = 16
"""Consecutive samples :func:`along_distances` gives one search of the segments near them."""


ALONG_PART_BLOCKS = 1 << 16
"""Blocks whose spread :func:`along_distances` measures at a time (~1 M samples)."""


ALONG_MAX_CANDIDATES = 512
"""Segment ends near a block beyond which its samples get GEOS's nearest query instead."""


def along_distances(samples: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray | None:
    """GEOS's distance of each sample to the nearest segment ``a[i] → b[i]``, mm, or ``None``.

    For samples taken along a path (a drawing's points, contour after contour, a few µm
    apart): the distance to the segments is 1-Lipschitz, so a block of
    :data:`ALONG_BLOCK` consecutive samples within ``ρ`` of its middle one ``c`` lies at
    most ``r0 + ρ`` from its nearest segment (``r0``: ``c``'s nearest segment end). A
    segment that near a sample has an end within
    :func:`~camtool.verify.nearest_exact.within_reach` of it, so within that plus ``ρ`` of
    ``c``: one k-d tree query a block gives every segment that can be the nearest of its
    samples, and GEOS's distance to each of them (compiled:
    :func:`~camtool.verify.nearest_exact._nearby_min`) gives the least, the distance
    shapely's nearest query over all segments gives. Segments longer than
    :data:`LONG_FACTOR` × the median are searched apart, within the reach of their own
    longest (:func:`_by_length`). Blocks with more than
    :data:`ALONG_MAX_CANDIDATES` ends near them (samples far apart, or long segments)
    get that query itself.

    ``None`` without the compiled GEOS distance (numba, ``CAMTOOL_ACCEL``), where the
    pairs would cost more than the query: the caller asks shapely.

    Args:
        samples: ``(N, 2)`` query points, mm, in order along their path.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm (``a[i] == b[i]``: a point).

    Returns:
        ``(N,)`` float64 distances, mm (``inf`` without segments).
    """
    n, m = len(samples), len(a)
    if m == 0:
        return np.full(n, np.inf)
    if n == 0:
        return np.zeros(0, dtype=np.float64)
    if nearest_exact._pair_kernels(nearest_exact.PAIR_KERNELS_FROM) is None:
        return None
    samples = np.ascontiguousarray(samples, dtype=np.float64)
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    first = np.arange(0, n, ALONG_BLOCK)
    size = np.minimum(ALONG_BLOCK, n - first)
    centre = samples[first + size // 2]
    rho = np.empty(len(first), dtype=np.float64)
    part = ALONG_BLOCK * ALONG_PART_BLOCKS
    for lo in range(0, n, part):  # each block's spread, the temporaries a part at a time
        k0, k1 = lo // ALONG_BLOCK, min(len(first), (lo + part) // ALONG_BLOCK)
        hi = min(n, lo + part)
        spread = np.hypot(*(samples[lo:hi] - np.repeat(centre[k0:k1], size[k0:k1], axis=0)).T)
        rho[k0:k1] = np.maximum.reduceat(spread, first[k0:k1] - lo)
    rho *= 1.0 + 1e-9
    sets = [_Ends(a, b, index, centre) for index in _by_length(a, b)]
    upper = np.min([e.r0 for e in sets], axis=0)  # the centre's nearest end
    reach = [e.reach(upper, rho) for e in sets]
    count = np.sum([e.count(centre, r) for e, r in zip(sets, reach, strict=True)], axis=0)
    out = np.empty(n, dtype=np.float64)
    wide = count > ALONG_MAX_CANDIDATES
    if wide.any():  # GEOS's query over every segment for these
        rows = np.flatnonzero(np.repeat(wide, size))
        out[rows] = nearest_exact._all_exact(samples[rows], a, b)
    narrow = np.flatnonzero(~wide)
    lo = 0
    while lo < len(narrow):  # blocks whose pairs fit at once: their lists of ends only
        pairs = np.cumsum(count[narrow[lo:]] * size[narrow[lo:]])
        hi = lo + max(1, int(np.searchsorted(pairs, nearest_exact.NEARBY_MAX_PAIRS, "right")))
        blocks = narrow[lo:hi]
        found = [e.within(centre[blocks], r[blocks]) for e, r in zip(sets, reach, strict=True)]
        got, segments = _merged(found, len(blocks))
        rows = _spans(first[blocks], size[blocks])
        per_row = np.repeat(got, size[blocks])  # the segments of each sample's block
        owner = np.repeat(np.arange(len(rows)), per_row)
        at = _spans(np.repeat(np.cumsum(got) - got, size[blocks]), per_row)
        out[rows] = nearest_exact._nearby_min(samples[rows], owner, segments[at], a, b)
        lo = hi
    return out


def _spans(start: IntArray, length: IntArray) -> IntArray:
    """``concatenate([arange(s, s + n) for s, n in zip(start, length)])``."""
    total = int(np.sum(length))
    return np.repeat(start - (np.cumsum(length) - length), length) + np.arange(total)


def _merged(found: list[tuple[IntArray, IntArray]], blocks: int) -> tuple[IntArray, IntArray]:
    """Each block's segments of every set, block after block: ``(count, segments)``."""
    if len(found) == 1:
        return found[0]
    count = np.sum([c for c, _ in found], axis=0)
    block = np.concatenate([np.repeat(np.arange(blocks), c) for c, _ in found])
    order = np.argsort(block, kind="stable")
    return count, np.concatenate([s for _, s in found])[order]


LONG_FACTOR = 4.0
"""Segments longer than this many times the median are searched apart (:func:`_by_length`)."""


def _by_length(a: FloatArray, b: FloatArray) -> list[IntArray]:
    """The segments' numbers: those up to :data:`LONG_FACTOR` × the median length, the longer.

    Each set is searched within the reach of its own longest segment, so a few long ones
    do not widen every search. One set when none is longer.
    """
    length = np.hypot(*(b - a).T)
    long = length > LONG_FACTOR * float(np.median(length))
    if not long.any():
        return [np.arange(len(a), dtype=np.int64)]
    return [np.flatnonzero(~long), np.flatnonzero(long)]


class _Ends:
    """The ends of the segments ``index`` in a k-d tree, and each block centre's nearest."""

    def __init__(self, a: FloatArray, b: FloatArray, index: IntArray, centre: FloatArray) -> None:
        from scipy.spatial import cKDTree

        self.index = index
        self.half = float(np.max(np.hypot(*(b[index] - a[index]).T))) / 2.0
        self.tree = cKDTree(np.concatenate([a[index], b[index]]))
        r0 = self.tree.query(centre, k=1, workers=nearest_exact.kd_workers(len(centre)))[0]
        self.r0 = np.asarray(r0, dtype=np.float64)

    def reach(self, upper: FloatArray, rho: FloatArray) -> FloatArray:
        """How far from a block's centre the segments nearest to its samples have an end.

        A sample within ``rho`` of its block's centre lies at most ``upper + rho`` from a
        segment (``upper``: an end's distance from the centre).
        """
        return nearest_exact.within_reach(upper + rho, self.half) + rho + 1e-12

    def count(self, centre: FloatArray, reach: FloatArray) -> IntArray:
        """How many ends lie within ``reach`` of each centre (no lists made)."""
        got = self.tree.query_ball_point(
            centre, reach, return_length=True, workers=nearest_exact.kd_workers(len(centre))
        )
        return np.asarray(got, dtype=np.int64)

    def within(self, centre: FloatArray, reach: FloatArray) -> tuple[IntArray, IntArray]:
        """Each block's ends within ``reach``: their count and segments, block after block."""
        workers = nearest_exact.kd_workers(len(centre))
        found = self.tree.query_ball_point(centre, reach, workers=workers)
        count = np.fromiter((len(f) for f in found), dtype=np.int64, count=len(found))
        ends = np.fromiter(
            itertools.chain.from_iterable(found), dtype=np.int64, count=int(np.sum(count))
        )
        return count, self.index[ends % len(self.index)]
