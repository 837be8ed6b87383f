"""The exact stage of the nearest-segment search: GEOS distances to the segments near each sample.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import itertools
import sys
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool import accel
from camtool.accel.pool import each_threaded

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


NEAREST_TOLERANCE_MM = 1e-5
"""Largest error :func:`nearest_distances` accepts from its vertex bound, mm (0.01 µm)."""


NEAREST_ENDS = 4
"""Segment ends :func:`nearest_distances` looks at around each sample."""


KD_WORKERS = -1
"""Threads of the k-d tree queries (scipy's ``workers``; -1: one per core). Each query is
answered alone, so the distances do not depend on it; only the wall time does."""

KD_THREADS_FROM = 1024
"""Query points from which a k-d tree query runs on :data:`KD_WORKERS` threads
(:func:`kd_workers`)."""


def kd_workers(points: int) -> int:
    """The ``workers`` of a scipy k-d tree query of ``points`` points.

    scipy starts its threads anew for every query; below :data:`KD_THREADS_FROM` points
    that costs more than the second core saves (a job's shortfall asks a small query for
    each of thousands of contours), so such a query runs on one thread.
    """
    return KD_WORKERS if points >= KD_THREADS_FROM else 1


def beyond_kth(d: FloatArray, rk: FloatArray, half: float) -> npt.NDArray[np.bool_]:
    """Where no segment with both ends ``rk`` or farther can come nearer than ``d``.

    A segment of length ``L <= 2·half`` whose ends both lie at least ``rk`` from a
    sample comes no nearer than ``sqrt(rk² − half²)``: its nearest point is an end, or the
    foot of the perpendicular, within ``L/2`` of an end along the segment. So ``d`` (the
    distance to some segment) is the least when ``d² + half² < rk²``. This holds wherever
    the looser ``d + half < rk`` (the triangle inequality) does.
    """
    return np.asarray(d * d + half * half < rk * rk)


def within_reach(upper: FloatArray, half: float) -> FloatArray:
    """How far from a sample the ends of every segment nearer than ``upper`` lie, at most, mm.

    ``sqrt(upper² + half²)`` (:func:`beyond_kth`: a segment at most ``2·half`` long with
    both ends farther lies farther than ``upper``), widened by a billionth and 1e-12 mm for
    the rounding of the distances: a float margin that never leaves one out.
    """
    return np.sqrt(upper * upper + half * half) * (1.0 + 1e-9) + 1e-12


def _to_segments(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """``(N, K)`` distances of points ``p`` ``(N, 2)`` to segments ``a → b`` ``(N, K, 2)``."""
    ab = b - a
    ap = p[:, None, :] - a
    length2 = np.einsum("nkj,nkj->nk", ab, ab)
    t = np.divide(
        np.einsum("nkj,nkj->nk", ap, ab), length2, out=np.zeros_like(length2), where=length2 > 0
    )
    t = np.clip(t, 0.0, 1.0)
    off = ap - t[..., None] * ab
    return np.sqrt(np.einsum("nkj,nkj->nk", off, off))


def _reaching(upper: FloatArray, settled: FloatArray, samples: FloatArray) -> npt.NDArray[np.bool_]:
    """Which unsure samples (distance at most ``upper``) may reach the largest ``settled``.

    A sample's exact distance is at most ``upper`` (the segments of its nearest ends)
    up to the rounding of two formulas for one distance: a few ulps of the distance,
    and near a segment a few ulps of the coordinates. The margin (a billionth, plus
    1e-12 mm and 64 ulps of the largest coordinate of ``samples``) covers both, so a
    sample left out is strictly below the largest settled distance, which is at most
    the largest of all.
    """
    if len(settled) == 0:
        return np.ones(len(upper), dtype=bool)
    return np.asarray(widened(upper, samples) >= float(np.max(settled)))


def rounding_slack(samples: FloatArray) -> float:
    """1e-12 mm and 64 ulps of the largest coordinate of ``samples``, mm (:func:`_reaching`)."""
    return 1e-12 + 64.0 * float(np.spacing(np.max(np.abs(samples))))


def widened(upper: FloatArray, samples: FloatArray) -> FloatArray:
    """Upper bounds of distances widened by :func:`_reaching`'s margin for two formulas."""
    return upper * (1.0 + 1e-9) + rounding_slack(samples)


def _settle_unsure(
    samples: FloatArray,
    d: FloatArray,
    unsure: npt.NDArray[np.bool_],
    a: FloatArray,
    b: FloatArray,
    nearby: Callable[..., FloatArray | None],
    *,
    only_max: bool,
) -> FloatArray:
    """The exact stage of both searches: GEOS's distance where the cheap tests were unsure.

    ``nearby(samples, upper, need=...)`` measures the segments near each unsure sample
    (:func:`_nearby_boxes` or :func:`_nearby_exact`, ``None`` over the pair limit, then
    :func:`_all_exact_where`); with ``only_max`` only the samples that can be the largest
    (:func:`_reaching`). ``d`` is updated in place and returned.
    """
    if unsure.any():
        need = _reaching(d[unsure], d[~unsure], samples) if only_max else None
        exact = nearby(samples[unsure], d[unsure], need=need)
        if exact is None:
            exact = _all_exact_where(samples[unsure], d[unsure], a, b, need)
        d[unsure] = exact
    return d


def _all_exact_where(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    need: npt.NDArray[np.bool_] | None,
) -> FloatArray:
    """:func:`_all_exact` of the samples ``need`` names (all when ``None``); ``upper`` elsewhere."""
    if need is None:
        return _all_exact(samples, a, b)
    out = upper.copy()
    if need.any():
        out[need] = _all_exact(samples[need], a, b)  # GEOS answers each sample alone
    return out


def _all_exact(samples: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """The GEOS distance (shapely) from each sample to the nearest of all segments, mm.

    What :func:`nearest_distances` gave before :func:`_nearby_exact` (its fallback, and
    the reference the tests compare it with, bit for bit).

    The samples are asked :data:`ALL_EXACT_CHUNK` at a time against one tree, a chunk
    per core at once (shapely releases the GIL while GEOS works): GEOS answers each
    point alone, so the distances are those of one query of them all, while only a few
    chunks' point geometries (~100 bytes each) exist at once (5.9 M unsure samples of a
    213-icon drawing took 1.3 GB in one query).
    """
    import shapely

    tree = shapely.STRtree(shapely.linestrings(np.stack([a, b], axis=1)))
    out = np.empty(len(samples), dtype=np.float64)

    def nearest(lo: int) -> None:
        points = shapely.points(samples[lo : lo + ALL_EXACT_CHUNK])
        _, exact = tree.query_nearest(points, return_distance=True, all_matches=False)
        out[lo : lo + len(points)] = exact

    each_threaded(nearest, range(0, len(samples), ALL_EXACT_CHUNK))  # each fills its rows
    return out


ALL_EXACT_CHUNK = 1 << 16
"""Samples :func:`_all_exact` asks GEOS's nearest query at once (memory, not the answer)."""


NEARBY_MAX_PAIRS = 4_000_000
"""Most (sample, segment) pairs :func:`_nearby_exact` measures for a few samples (and the
box tree gives at once); beyond :func:`pair_limit`, :func:`_all_exact` answers."""


NEARBY_PAIRS_PER_SAMPLE = 64
"""(Sample, segment) pairs per sample :func:`pair_limit` allows beyond
:data:`NEARBY_MAX_PAIRS`: below it the compiled pairs cost less than GEOS's nearest query
over every segment (docs/performance.md); only the time depends on it."""


def pair_limit(samples: int) -> int:
    """Most (sample, segment) pairs the exact stage measures for ``samples`` samples.

    :data:`NEARBY_MAX_PAIRS`, or :data:`NEARBY_PAIRS_PER_SAMPLE` a sample when more;
    beyond it :func:`_all_exact` answers (GEOS's nearest query over every segment).
    """
    return max(NEARBY_MAX_PAIRS, NEARBY_PAIRS_PER_SAMPLE * samples)


@dataclass(frozen=True)
class LongSegments:
    """The few segments of a trace much longer than the rest, searched apart.

    :func:`_nearby_exact` takes a sample's segments from the ends within
    :func:`within_reach` of ``upper`` and ``half``, half the longest segment: on a trace of
    0.9 µm steps with a few 18 µm jumps (a backlash take-up, a budget's trace without
    interpolation), 40 ends a sample where 4 would do. With these, the other segments are
    searched within the reach of ``short_half`` and only these within that of ``half``.

    Attributes:
        short_half: half the longest of the other segments, mm.
        index: ``(L,)`` the long segments' numbers.
        tree: scipy's k-d tree of their ends, ``concatenate([a[index], b[index]])``.
    """

    short_half: float
    index: IntArray
    tree: Any


LONG_SEGMENTS_FEW = 64
"""At most this many segments, or one in :data:`LONG_SEGMENTS_PER`, are searched apart."""
LONG_SEGMENTS_PER = 1000
LONG_SEGMENTS_GAIN = 4.0
"""Segments are searched apart only where the others' half is this many times smaller."""


def long_segments(
    a: FloatArray, b: FloatArray, half: float, lengths: FloatArray | None = None
) -> LongSegments | None:
    """The segments ``a → b`` to search apart (:class:`LongSegments`), or ``None``.

    With ``few`` = :data:`LONG_SEGMENTS_FEW` (or one in :data:`LONG_SEGMENTS_PER`): the
    segments longer than the ``few + 1``-th longest (at most ``few``; fewer where lengths
    tie), where that one is at most ``2 · half / GAIN`` long (``half``: half the longest
    segment, mm). ``short_half`` is half its length; lengths are computed as ``half`` is,
    so every other segment is at most ``2 · short_half`` long. ``lengths``: those lengths,
    ``np.hypot(*(b - a).T)``, when the caller has them already.
    """
    n = len(a)
    few = max(LONG_SEGMENTS_FEW, n // LONG_SEGMENTS_PER)
    if n <= few:
        return None
    lengths = np.hypot(*(b - a).T) if lengths is None else lengths
    cut = float(np.partition(lengths, n - few - 1)[n - few - 1])
    if cut / 2.0 * LONG_SEGMENTS_GAIN > half:
        return None
    from scipy.spatial import cKDTree

    index = np.flatnonzero(lengths > cut).astype(np.int64)
    return LongSegments(cut / 2.0, index, cKDTree(np.concatenate([a[index], b[index]])))


def _nearby_exact(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    ends: Any,
    half: float,
    need: npt.NDArray[np.bool_] | None = None,
    long: LongSegments | None = None,
) -> FloatArray | None:
    """:func:`_all_exact` over only the segments that can be the nearest, or ``None``.

    A segment whose ends both lie farther than ``sqrt(upper² + half²)`` from a sample
    lies farther than ``upper``, the distance to a segment already found
    (:func:`beyond_kth`, :func:`within_reach`): it cannot be the nearest. The same GEOS distance is
    taken over the rest, so the minimum is the one :func:`_all_exact` finds, without
    building a tree of every segment for a few samples. ``None`` when the segments near
    the samples are too many (over :func:`pair_limit` pairs).

    Args:
        samples: ``(U, 2)`` query points, mm.
        upper: ``(U,)`` distance of each to some segment ``a → b``, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        ends: the k-d tree of ``concatenate([a, b])``.
        half: half the longest segment, mm.
        need: ``(U,)`` the samples to measure (``None``: all); the others keep ``upper``.
            The limit counts the pairs of all samples, so which of the two ways gives a
            sample's distance does not depend on ``need``.
        long: the long segments (:func:`long_segments`): the ends of ``ends`` are then
            searched within the reach of ``long.short_half``, the long segments' within
            that of ``half``; every segment within ``upper`` is still among them, so the
            minimum is the same. The limit still counts the pairs within that of ``half``:
            over it, :func:`_all_exact` answers, whose GEOS nearest query can differ from
            the least GEOS distance in the last bit where segments tie, so the choice
            between the two ways must not depend on ``long``.
    """
    reach = within_reach(upper, half)
    counts = _counts_within(ends, samples, reach)
    if counts is None:  # the limit counts these pairs, with or without ``long``: see above
        return None
    out = upper.copy() if need is not None else np.empty(len(samples), dtype=np.float64)
    for lo in range(0, len(samples), NEARBY_BLOCK):  # each sample's minimum is its own
        part = slice(lo, lo + NEARBY_BLOCK)
        at = samples[part]
        sources = [_Reach(ends, reach[part], counts[part], None)]
        if long is not None:
            near = within_reach(upper[part], long.short_half)
            sources = [_Reach(ends, near, _count_all(ends, at, near), None)]
            sources.append(
                _Reach(long.tree, reach[part], _count_all(long.tree, at, reach[part]), long.index)
            )
        total = sources[0].counts if len(sources) == 1 else sources[0].counts + sources[1].counts
        if total.min() == 0:
            return None  # cannot happen (the segment of ``upper`` is within reach): be safe
        if need is None:
            out[part] = _nearby_pairs(at, sources, a, b)
            continue
        keep = need[part]
        if keep.any():
            out[part][keep] = _nearby_pairs(  # a view of out: written through
                at[keep], [s.where(keep) for s in sources], a, b
            )
    return out


NEARBY_BLOCK = 1 << 20
"""Unsure samples :func:`_nearby_exact` measures at once once the pair limit is passed: a
block's reaches, counts and pairs take ~100 bytes a sample, and a big drawing comparison
has millions of unsure samples. Each sample's minimum is its own: blocks do not change it."""


@dataclass(frozen=True)
class _Reach:
    """Ends of one k-d tree within ``reach`` of each sample (``counts`` of them).

    ``index``: the segment of each of the tree's ends, ``index[end % len(index)]``
    (``None``: ``end % len(a)``, the tree of every segment's ends).
    """

    tree: Any
    reach: FloatArray
    counts: IntArray
    index: IntArray | None

    def where(self, keep: npt.NDArray[np.bool_]) -> _Reach:
        """The same for the samples ``keep`` names."""
        return _Reach(self.tree, self.reach[keep], self.counts[keep], self.index)

    def pairs(self, samples: FloatArray, lo: int, hi: int, m: int) -> tuple[IntArray, IntArray]:
        """``(owner, segment)`` of samples ``lo:hi`` (owner from 0), sample-major.

        Every end within reach of each sample, and where it is cheaper, a few more: the
        ``k`` nearest ends of each (``k`` the most any of them has within reach), which
        hold every end within its reach (one left out would have ``k`` ends nearer, so
        more than ``k`` within reach). More segments give the same minimum.
        """
        counts = self.counts[lo:hi]
        rows = np.flatnonzero(counts)  # the samples with an end within reach
        if len(rows) == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        counts = counts[rows]
        total, k = int(np.sum(counts)), int(np.max(counts))
        at = samples[lo:hi][rows]
        if k * len(rows) <= 2 * total + KNN_SLACK_PAIRS:  # arrays, not a list per sample
            got = self.tree.query(at, k=k, workers=kd_workers(len(at)))[1]
            end = np.asarray(got, dtype=np.int64).reshape(-1)
            owner = np.repeat(rows, k)
        else:
            found = self.tree.query_ball_point(
                at, self.reach[lo:hi][rows], workers=kd_workers(len(at))
            )
            owner = np.repeat(rows, counts)
            end = np.fromiter(itertools.chain.from_iterable(found), dtype=np.int64, count=total)
        seg = end % m if self.index is None else self.index[end % len(self.index)]
        return owner, seg


KNN_SLACK_PAIRS = 1024
"""Pairs :meth:`_Reach.pairs` may add to a chunk's to ask the k nearest ends instead of lists."""


def _counts_within(ends: Any, samples: FloatArray, reach: FloatArray) -> IntArray | None:
    """How many ends lie within ``reach`` of each sample, or ``None`` over the pair limit.

    Counted :data:`NEARBY_COUNT_CHUNK` samples at a time (scipy's count holds a list per
    sample while it runs: ~400 MB for 5.9 M samples in one call), stopping as soon as the
    running total passes :func:`pair_limit`: the answer of one count of them all.
    """
    parts: list[IntArray] = []
    total, limit = 0, pair_limit(len(samples))
    for lo in range(0, len(samples), NEARBY_COUNT_CHUNK):
        part = slice(lo, lo + NEARBY_COUNT_CHUNK)
        near = ends.query_ball_point(
            samples[part], reach[part], return_length=True, workers=kd_workers(len(samples))
        )
        total += int(np.sum(near))
        if total > limit:
            return None
        parts.append(np.asarray(near, dtype=np.int64))
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


def _count_all(ends: Any, samples: FloatArray, reach: FloatArray) -> IntArray:
    """How many ends lie within ``reach`` of each sample (:func:`_counts_within`, no limit)."""
    parts = [
        np.asarray(
            ends.query_ball_point(
                samples[lo : lo + NEARBY_COUNT_CHUNK],
                reach[lo : lo + NEARBY_COUNT_CHUNK],
                return_length=True,
                workers=kd_workers(len(samples)),
            ),
            dtype=np.int64,
        )
        for lo in range(0, len(samples), NEARBY_COUNT_CHUNK)
    ]
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


NEARBY_COUNT_CHUNK = 1 << 16
"""Samples :func:`_counts_within` counts at once (memory, and an early end over the limit)."""


def _nearby_pairs(
    samples: FloatArray, sources: list[_Reach], a: FloatArray, b: FloatArray
) -> FloatArray:
    """:func:`_nearby_exact`'s GEOS minimum over the ends each source finds within reach."""
    out = np.empty(len(samples), dtype=np.float64)
    counts = np.sum([s.counts for s in sources], axis=0)
    ends_before = np.concatenate([[0], np.cumsum(counts)])
    lo = 0
    while lo < len(samples):  # a few samples at a time: their lists of ends are Python ints
        hi = int(np.searchsorted(ends_before, ends_before[lo] + NEARBY_CHUNK_PAIRS, "right")) - 1
        hi = min(max(hi, lo + 1), len(samples))
        found = [s.pairs(samples, lo, hi, len(a)) for s in sources]
        if len(found) == 1:
            owner, seg = found[0]
        else:  # sample-major again: each source's pairs are
            owner = np.concatenate([f[0] for f in found])
            order = np.argsort(owner, kind="stable")
            owner, seg = owner[order], np.concatenate([f[1] for f in found])[order]
        out[lo:hi] = _nearby_min(samples[lo:hi], owner, seg, a, b)
        lo = hi
    return out


def _nearby_boxes(
    samples: FloatArray,
    upper: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    half: float,
    kernels: ModuleType,
    need: npt.NDArray[np.bool_] | None = None,
) -> FloatArray | None:
    """:func:`_nearby_exact` with the ends within reach from the box tree (numba).

    The same GEOS distances over the segments with an end within reach (a margin wider:
    any set holding those gives the same minimum), so the same answer.

    Args:
        samples: ``(U, 2)`` query points, mm.
        upper: ``(U,)`` distance of each to some segment ``a → b``, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        tree: the ends' search tree (:func:`camtool.accel.nearkernels.tree`).
        half: half the longest segment, mm.
        kernels: :mod:`camtool.accel.nearkernels`.
        need: as for :func:`_nearby_exact` (the limit counts every sample's pairs).
    """
    reach = within_reach(upper, half) * (1.0 + 1e-12)
    samples = np.ascontiguousarray(samples)
    out = upper.copy()
    budget = pair_limit(len(samples))
    lo, step = 0, NEARBY_BOX_SAMPLES
    while lo < len(samples):
        hi = min(len(samples), lo + step)
        cap = min(NEARBY_MAX_PAIRS, budget)
        owner, seg = kernels.pairs_within(samples[lo:hi], *tree, reach[lo:hi], cap)
        if len(owner) == 0 and cap == NEARBY_MAX_PAIRS and hi - lo > 1:
            step = max(1, (hi - lo) // 2)  # too many pairs at once: fewer samples
            continue
        # ``owner`` ascends (sample-major): its distinct values are one more than its steps
        if len(owner) == 0 or np.count_nonzero(owner[1:] != owner[:-1]) + 1 < hi - lo:
            return None  # over the limit (or, which cannot happen, a sample without one)
        budget -= len(owner)
        part = slice(lo, hi)
        if need is None:
            out[part] = _nearby_min(samples[part], owner, seg, a, b)
        elif need[part].any():
            wanted = need[part]
            keep = wanted[owner]
            renumber = np.cumsum(wanted) - 1  # a needed sample's place among the needed
            out[lo:hi][wanted] = _nearby_min(
                samples[part][wanted], renumber[owner[keep]], seg[keep], a, b
            )
        lo = hi
    return out


NEARBY_BOX_SAMPLES = 1 << 16
"""Samples :func:`_nearby_boxes` asks the box tree for at once (fewer when their pairs
are over :data:`NEARBY_MAX_PAIRS`): memory, not the answer."""


NEARBY_CHUNK_PAIRS = 50_000
"""Most ``(sample, segment)`` pairs :func:`_nearby_min` hands GEOS at once (memory)."""


def _nearby_min(
    samples: FloatArray,
    owner: IntArray,
    seg: IntArray,
    a: FloatArray,
    b: FloatArray,
    chunk: int = NEARBY_CHUNK_PAIRS,
) -> FloatArray:
    """The least GEOS distance of each sample over its ``(owner, end)`` pairs (sample-major).

    ``owner`` is ascending and names every sample at least once. The pairs are measured
    a few samples at a time (about ``chunk`` pairs, a sample's pairs never split), which
    bounds the memory GEOS's points and lines take; each pair's distance and each
    sample's minimum are the same whatever the grouping. With numba
    (:func:`_pair_kernels`) the same GEOS distances are taken compiled, in one pass
    (:func:`camtool.accel.nearkernels.least_of_pairs`).
    """
    kernels = _pair_kernels(len(owner))
    if kernels is not None:  # the same GEOS floats, compiled: no line objects
        return np.asarray(
            kernels.least_of_pairs(
                np.ascontiguousarray(samples, dtype=np.float64),
                np.ascontiguousarray(owner, dtype=np.int64),
                np.ascontiguousarray(seg % len(a), dtype=np.int64),
                np.ascontiguousarray(a, dtype=np.float64),
                np.ascontiguousarray(b, dtype=np.float64),
            ),
            dtype=np.float64,
        )
    out = np.empty(len(samples), dtype=np.float64)
    pos, count = 0, len(owner)
    while pos < count:
        end = min(pos + max(1, chunk), count)
        if end < count:  # back to the first pair of the sample ``end`` falls in
            end = int(np.searchsorted(owner, owner[end], side="left"))
            if end <= pos:  # one sample has more pairs than ``chunk``: take them all
                end = int(np.searchsorted(owner, owner[pos], side="right"))
        first, last = int(owner[pos]), int(owner[end - 1])
        out[first : last + 1] = _nearby_group(samples, owner[pos:end], seg[pos:end], a, b)
        pos = end
    return out


PAIR_KERNELS_FROM = 200_000
"""Pairs from which :func:`_nearby_min` loads the compiled GEOS distance when numba is not
loaded yet (loading it costs about 0.5 s once; GEOS through shapely ~1 µs a pair)."""


def _pair_kernels(pairs: int) -> ModuleType | None:
    """:mod:`camtool.accel.nearkernels` for :func:`_nearby_min`, or ``None`` (GEOS).

    Loaded when numba already is (its cached kernel loads in milliseconds) or for at
    least :data:`PAIR_KERNELS_FROM` pairs; ``None`` without numba.
    """
    if not accel.enabled() or ("numba" not in sys.modules and pairs < PAIR_KERNELS_FROM):
        return None
    try:
        from camtool.accel import nearkernels
    except ImportError:
        return None
    return nearkernels


def _nearby_group(
    samples: FloatArray, owner: IntArray, seg: IntArray, a: FloatArray, b: FloatArray
) -> FloatArray:
    """:func:`_nearby_min` of consecutive samples ``owner[0]..owner[-1]`` (each with a pair)."""
    import shapely

    seg = seg % len(a)
    pair = np.unique(owner * len(a) + seg)  # each (sample, segment) once, sample-major
    owner, seg = pair // len(a), pair % len(a)
    used, local = np.unique(seg, return_inverse=True)
    lines = shapely.linestrings(np.stack([a[used], b[used]], axis=1))
    first_sample = int(owner[0])
    points = shapely.points(samples[first_sample : int(owner[-1]) + 1])
    dist = shapely.distance(points[owner - first_sample], lines[local])
    first = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    return np.asarray(np.minimum.reduceat(dist, first), dtype=np.float64)


def _nearest_chunk(
    samples: FloatArray,
    a: FloatArray,
    b: FloatArray,
    ends: Any,
    half: float,
    long: LongSegments | None = None,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """:func:`nearest_distances` of a few samples from the k-d tree of segment ``ends``.

    ``long``: the few long segments (:func:`long_segments`), tested apart (:func:`settled`).

    Returns:
        The distances and which of them the tests could not settle.
    """
    k = min(NEAREST_ENDS, 2 * len(a))
    r, index = ends.query(samples, k=k, workers=kd_workers(len(samples)))
    r = np.asarray(r, dtype=np.float64).reshape(len(samples), k)
    seg = np.asarray(index).reshape(len(samples), k) % len(a)
    d = _to_segments(samples, a[seg], b[seg]).min(axis=1)
    lower = np.sqrt(np.maximum(r[:, 0] ** 2 - half * half, 0.0))
    if k == 2 * len(a):  # every segment's ends found
        return d, np.zeros(len(samples), dtype=bool)
    return d, ~settled(samples, d, r[:, -1], lower, half, long)


def settled(
    samples: FloatArray,
    d: FloatArray,
    rk: FloatArray,
    lower: FloatArray,
    half: float,
    long: LongSegments | None,
) -> npt.NDArray[np.bool_]:
    """Where ``d``, the distance to the segments of a sample's k nearest ends, is the least.

    Exact where no segment that could be nearer was left out (:func:`beyond_kth` of the
    k-th end's distance ``rk``), or where the vertex bound ``lower`` (``sqrt(r0² − half²)``,
    ``r0`` the nearest end) is within :data:`NEAREST_TOLERANCE_MM`. With the few long
    segments (``long``: :func:`long_segments`), a sample is also settled when no other
    segment can be nearer (:func:`beyond_kth` of ``rk`` and ``long.short_half``) and
    every long one lies farther (its nearest long end, ``half``). Both searches
    (:mod:`camtool.verify.nearest_search`) settle by this, so they give the same distances.

    Args:
        samples: ``(N, 2)`` the query points, mm.
        d: ``(N,)`` distances, mm.
        rk: ``(N,)`` the k-th nearest end's distance, mm.
        lower: ``(N,)`` the vertex bound, mm.
        half: half the longest segment, mm.
        long: the long segments, or ``None``.
    """
    sure = beyond_kth(d, rk, half) | (d - lower <= NEAREST_TOLERANCE_MM)
    if long is not None and not sure.all():
        ask = np.flatnonzero(~sure)
        far_long = np.asarray(long.tree.query(samples[ask], k=1, workers=kd_workers(len(ask)))[0])
        sure[ask] = beyond_kth(d[ask], rk[ask], long.short_half) & beyond_kth(
            d[ask], far_long, half
        )
    return sure
