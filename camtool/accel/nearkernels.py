"""Compiled nearest-end searches of :func:`camtool.verify.nearest_search.nearest_distances` (numba).

Design notes: docs/internals.md, ``camtool/accel/nearkernels.py``.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

LEAF = 8
"""Ends per leaf (consecutive in the order given)."""
FAN = 8
"""Children per node above the leaves."""
CAP = 64
"""Most ends a query keeps at its k-th distance (ties included); more: the k-d tree answers."""


def tree(
    points: Any, *, segments: bool = False, merge: bool = True
) -> tuple[Any, Any, Any, Any, Any]:
    """The search tree of the ends ``points`` ``(P, 2)``: ``(places, boxes, offsets, start, ends)``.

    ``places`` ``(U, 2)`` are the distinct points among ``points`` (the same float64
    bits), numbered in the order of their first end; ``ends[start[u]:start[u + 1]]`` are
    the ends at place ``u``, in that order; ``boxes`` and ``offsets`` are :func:`build`'s
    of ``places``. The searches give the ends, as a tree of every end would. With
    ``segments``, ``points`` is ``concatenate([a, b])`` of ``P / 2`` segments and the order
    is along them (``a[0]``, ``b[0]``, ``a[1]``…), so that consecutive places lie together
    and the leaves' boxes stay small. ``merge=False`` keeps every end its own place.
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    n = len(points)
    if not merge or n == 0:
        start = np.arange(n + 1, dtype=np.int64)
        ends = np.arange(n, dtype=np.int64)
        return (points, *build(points), start, ends)
    if n >= 2**31:  # _merge numbers ends in int32
        return tree(points, merge=False)
    half = n // 2 if segments else 0
    start, ends = _merge(points.view(np.uint64), half)
    places = np.ascontiguousarray(points[ends[start[:-1]]])
    return (places, *build(places), start, ends)


@numba.njit(cache=True, nogil=True)
def _merge(bits: Any, half: int) -> tuple[Any, Any]:  # pragma: no cover - compiled
    """:func:`tree`'s places of the ends whose coordinates' bits are ``bits`` ``(P, 2)``.

    The ends are taken in order (``half > 0``: ``j // 2 + (j % 2) · half``, along the
    segments), each looked up by its bits in an open-addressing table of twice as many
    slots; a place is numbered when its first end comes. Returns ``start`` ``(U + 1,)``
    and ``ends`` ``(P,)``, the ends grouped by place, each group in the order taken.
    """
    n = len(bits)
    size = 1
    while size < 2 * n:
        size *= 2
    mask = np.uint64(size - 1)
    table = np.full(size, -1, dtype=np.int32)  # int32: less memory (P < 2**31)
    place_of = np.empty(n, dtype=np.int32)
    first = np.empty(n, dtype=np.int32)
    count = np.zeros(n + 1, dtype=np.int64)
    places = 0
    for j in range(n):
        e = j // 2 + (j % 2) * half if half > 0 else j
        x = bits[e, 0]
        y = bits[e, 1]
        h = x * np.uint64(0x9E3779B97F4A7C15) ^ y * np.uint64(0xC2B2AE3D27D4EB4F)
        h ^= h >> np.uint64(31)
        slot = h & mask
        while True:
            p = table[slot]
            if p < 0:
                table[slot] = places
                first[places] = e
                place_of[e] = places
                places += 1
                break
            f = first[p]
            if bits[f, 0] == x and bits[f, 1] == y:
                place_of[e] = p
                break
            slot = (slot + np.uint64(1)) & mask
        count[place_of[e] + 1] += 1
    start = np.cumsum(count[: places + 1])
    at = start[:places].copy()
    ends = np.empty(n, dtype=np.int64)
    for j in range(n):
        e = j // 2 + (j % 2) * half if half > 0 else j
        p = place_of[e]
        ends[at[p]] = e
        at[p] += 1
    return start, ends


def build(points: Any) -> tuple[Any, Any]:
    """The box tree of ``points`` ``(P, 2)``: boxes ``(nodes, 4)`` and level offsets.

    Boxes are ``(xmin, ymin, xmax, ymax)``; level 0 (the leaves) comes first, the root
    last; ``offsets[l]`` is the first node of level ``l`` and ``offsets[-1]`` the count.
    """
    sizes = [max(1, -(-len(points) // LEAF))]
    while sizes[-1] > 1:
        sizes.append(-(-sizes[-1] // FAN))
    offsets = np.zeros(len(sizes) + 1, dtype=np.int64)
    offsets[1:] = np.cumsum(sizes)
    boxes = np.empty((int(offsets[-1]), 4), dtype=np.float64)
    _fill(np.ascontiguousarray(points, dtype=np.float64), boxes, offsets)
    return boxes, offsets


@numba.njit(cache=True, nogil=True)
def _fill(points: Any, boxes: Any, offsets: Any) -> None:  # pragma: no cover - compiled
    n = len(points)
    for node in range(offsets[1]):
        lo = node * LEAF
        hi = min(n, lo + LEAF)
        x0 = y0 = np.inf
        x1 = y1 = -np.inf
        for i in range(lo, hi):
            x0 = min(x0, points[i, 0])
            y0 = min(y0, points[i, 1])
            x1 = max(x1, points[i, 0])
            y1 = max(y1, points[i, 1])
        boxes[node, 0] = x0
        boxes[node, 1] = y0
        boxes[node, 2] = x1
        boxes[node, 3] = y1
    for level in range(1, len(offsets) - 1):
        below, here = offsets[level - 1], offsets[level]
        count_below = here - below
        for node in range(offsets[level + 1] - here):
            lo = node * FAN
            hi = min(count_below, lo + FAN)
            x0 = y0 = np.inf
            x1 = y1 = -np.inf
            for c in range(lo, hi):
                x0 = min(x0, boxes[below + c, 0])
                y0 = min(y0, boxes[below + c, 1])
                x1 = max(x1, boxes[below + c, 2])
                y1 = max(y1, boxes[below + c, 3])
            boxes[here + node, 0] = x0
            boxes[here + node, 1] = y0
            boxes[here + node, 2] = x1
            boxes[here + node, 3] = y1


@numba.njit(inline="always")
def _box2(boxes: Any, node: int, qx: float, qy: float) -> float:  # pragma: no cover
    """Squared distance from ``(qx, qy)`` to a box: never more than to a point in it."""
    dx = 0.0
    if qx < boxes[node, 0]:
        dx = boxes[node, 0] - qx
    elif qx > boxes[node, 2]:
        dx = qx - boxes[node, 2]
    dy = 0.0
    if qy < boxes[node, 1]:
        dy = boxes[node, 1] - qy
    elif qy > boxes[node, 3]:
        dy = qy - boxes[node, 3]
    return dx * dx + dy * dy


@numba.njit(inline="always")
def _point2(points: Any, i: int, qx: float, qy: float) -> float:  # pragma: no cover
    """The squared distance as scipy computes it: ``0 + (x − u)² + (y − v)²``."""
    s = 0.0
    d = qx - points[i, 0]
    s += d * d
    d = qy - points[i, 1]
    s += d * d
    return s


@numba.njit(inline="always")
def _insert(best: Any, k: int, d2: float) -> None:  # pragma: no cover - compiled
    """Put ``d2`` into the ascending ``best[:k]`` (the k smallest so far)."""
    j = k - 1
    while j > 0 and best[j - 1] > d2:
        best[j] = best[j - 1]
        j -= 1
    best[j] = d2


@numba.njit(inline="always")
def _scratch(offsets: Any) -> tuple[Any, Any, Any, Any, Any]:  # pragma: no cover - compiled
    """The scratch of one search in the tree of level ``offsets`` (:func:`build`).

    Node levels and numbers, a node's children and their distances, and room for every
    leaf (:func:`_leaves_within`).
    """
    return (
        np.empty(64 * FAN, dtype=np.int64),
        np.empty(64 * FAN, dtype=np.int64),
        np.empty(FAN, dtype=np.int64),
        np.empty(FAN, dtype=np.float64),
        np.empty(offsets[1], dtype=np.int64),
    )


@numba.njit(inline="always")
def _knn_one(
    qx: float,
    qy: float,
    points: Any,
    boxes: Any,
    offsets: Any,
    start: Any,
    ends: Any,
    k: int,
    last: int,
    best: Any,
    found: Any,
    found2: Any,
    work: tuple[Any, Any, Any, Any, Any],
) -> tuple[int, int, bool]:  # pragma: no cover - compiled
    """:func:`knn`'s search for one query ``(qx, qy)``.

    Fills ``best[:k]`` (the k smallest squared distances of the ends, ascending: a place
    counts once per end at it) and ``found[:count]``/``found2[:count]``: ends kept within
    the bound at the time, which holds every end within the k-th distance unless
    ``spill`` (more than :data:`CAP`). ``last`` is the previous query's nearest place (a
    warm start); ``work`` the scratch stacks. Returns ``(nearest place or -1, count,
    spill)``.
    """
    stack_level, stack_node, child, child2, _ = work
    npts = len(points)
    top = len(offsets) - 2  # the root's level
    # a bound to start from: the k-th nearest of the leaves around the last
    # query's nearest end (queries come along a path: it is near)
    for j in range(k):
        best[j] = np.inf
    leaf = last // LEAF
    for u in range(max(0, (leaf - 1) * LEAF), min(npts, (leaf + 2) * LEAF)):
        d2 = _point2(points, u, qx, qy)
        for _ in range(start[u], start[u + 1]):
            if d2 < best[k - 1]:
                _insert(best, k, d2)
    warm = best[k - 1]  # >= the k-th smallest of all: prunes nothing it needs
    for j in range(k):
        best[j] = np.inf
    nearest = -1
    count = 0  # ends kept within the bound at the time (every one within the k-th is)
    spill = False
    stack_level[0] = top
    stack_node[0] = 0
    sp = 1
    while sp > 0:
        sp -= 1
        level = stack_level[sp]
        node = stack_node[sp]
        bound = min(best[k - 1], warm)
        if _box2(boxes, offsets[level] + node, qx, qy) > bound:
            continue
        if level == 0:
            lo = node * LEAF
            hi = min(npts, lo + LEAF)
            for u in range(lo, hi):
                d2 = _point2(points, u, qx, qy)
                for e in range(start[u], start[u + 1]):  # each end at the place
                    if d2 < best[k - 1]:
                        if d2 < best[0]:
                            nearest = u
                        _insert(best, k, d2)
                    bound = min(best[k - 1], warm)
                    if d2 <= bound:
                        if count == CAP:  # drop what the bound has passed
                            kept = 0
                            for j in range(count):
                                if found2[j] <= bound:
                                    found[kept] = found[j]
                                    found2[kept] = found2[j]
                                    kept += 1
                            count = kept
                        if count < CAP:
                            found[count] = ends[e]
                            found2[count] = d2
                            count += 1
                        else:
                            spill = True
            continue
        below = offsets[level - 1]
        count_below = offsets[level] - below
        lo = node * FAN
        hi = min(count_below, lo + FAN)
        m = 0
        for c in range(lo, hi):
            c2 = _box2(boxes, below + c, qx, qy)
            if c2 <= bound:
                # insertion, farthest first: the nearest child is popped first
                j = m
                while j > 0 and child2[j - 1] < c2:
                    child2[j] = child2[j - 1]
                    child[j] = child[j - 1]
                    j -= 1
                child2[j] = c2
                child[j] = c
                m += 1
        for j in range(m):
            stack_level[sp] = level - 1
            stack_node[sp] = child[j]
            sp += 1
    return nearest, count, spill


@numba.njit(cache=True, nogil=True)
def knn(
    samples: Any, points: Any, boxes: Any, offsets: Any, start: Any, ends: Any, k: int
) -> tuple[Any, Any, Any, Any]:  # pragma: no cover - compiled
    """The ``k`` nearest ends to each sample, as scipy's k-d tree of the ends finds them.

    Args:
        samples: ``(N, 2)`` query points.
        points: ``(U, 2)`` the places of the ends (:func:`tree`).
        boxes: their boxes (:func:`tree`).
        offsets: the boxes' level offsets (:func:`tree`).
        start: ``(U + 1,)`` where each place's ends start in ``ends`` (:func:`tree`).
        ends: ``(P,)`` the ends at the places, place after place (:func:`tree`).
        k: neighbours, ``1 <= k <=`` the number of ends.

    Returns:
        ``r0`` ``(N,)`` the nearest end's squared distance and ``rk`` ``(N,)`` the k-th's
        (as the k-d tree computes them, before its square root), ``index`` ``(N, k)`` the
        ``k`` nearest ends, and ``state`` ``(N,)``: 0 where they are the only ``k``
        within ``rk`` (the k-d tree's set), 1 where more ends lie exactly at ``rk``
        (which of them the k-d tree keeps is its own choice: see :func:`within`).
    """
    n = len(samples)
    r0 = np.empty(n, dtype=np.float64)
    rk = np.empty(n, dtype=np.float64)
    index = np.zeros((n, k), dtype=np.int64)
    state = np.zeros(n, dtype=np.int8)
    best = np.empty(k, dtype=np.float64)
    found = np.empty(CAP, dtype=np.int64)
    found2 = np.empty(CAP, dtype=np.float64)
    work = _scratch(offsets)
    last = 0
    for q in range(n):
        qx, qy = samples[q, 0], samples[q, 1]
        nearest, count, spill = _knn_one(
            qx, qy, points, boxes, offsets, start, ends, k, last, best, found, found2, work
        )
        kth = best[k - 1]
        if nearest >= 0:
            last = nearest
        r0[q] = best[0]
        rk[q] = kth
        within_k = 0
        for j in range(count):
            if found2[j] <= kth:
                if within_k < k:
                    index[q, within_k] = found[j]
                within_k += 1
        if spill or within_k != k:
            state[q] = 1
    return r0, rk, index, state


@numba.njit(cache=True, nogil=True)
def within(
    samples: Any, points: Any, boxes: Any, offsets: Any, start: Any, ends: Any, bound2: Any
) -> tuple[Any, Any, Any]:  # pragma: no cover - compiled
    """Every end within ``bound2[i]`` (squared distance, inclusive) of each sample.

    ``points``, ``boxes``, ``offsets``, ``start``, ``ends``: :func:`tree` of the ends.

    Returns:
        ``found`` ``(N, CAP)`` ends, ``d2`` ``(N, CAP)`` their squared distances (as
        scipy computes them) and ``count`` ``(N,)`` how many there are (``> CAP``: only
        the first ``CAP`` are given).
    """
    n = len(samples)
    found = np.zeros((n, CAP), dtype=np.int64)
    found2 = np.full((n, CAP), np.inf)
    count = np.zeros(n, dtype=np.int64)
    work = _scratch(offsets)
    for q in range(n):
        row, row2 = found[q], found2[q]
        qx, qy = samples[q, 0], samples[q, 1]
        count[q] = _ends_within(
            qx, qy, points, boxes, offsets, start, ends, bound2[q], row, row2, work
        )
    return found, found2, count


@numba.njit(cache=True, nogil=True)
def pairs_within(
    samples: Any,
    points: Any,
    boxes: Any,
    offsets: Any,
    start: Any,
    ends: Any,
    reach: Any,
    limit: int,
) -> tuple[Any, Any]:  # pragma: no cover - compiled
    """Every ``(sample, end)`` pair closer than ``reach[sample]`` (or at it), sample-major.

    Args:
        samples: ``(N, 2)`` query points.
        points: ``(U, 2)`` the places of the ends (:func:`tree`).
        boxes: their boxes (:func:`tree`).
        offsets: the boxes' level offsets (:func:`tree`).
        start: ``(U + 1,)`` where each place's ends start in ``ends`` (:func:`tree`).
        ends: ``(P,)`` the ends at the places, place after place (:func:`tree`).
        reach: ``(N,)`` distances.
        limit: most pairs; beyond it none are given.

    Returns:
        ``owner`` and ``end`` ``(K,)`` of each pair; both empty when over ``limit``.
    """
    n = len(samples)
    counts = np.zeros(n, dtype=np.int64)
    total = 0
    stack_level, stack_node, _, _, leaves = _scratch(offsets)
    npts = len(points)
    for fill in range(2):
        if fill == 1:
            owner = np.empty(total, dtype=np.int64)
            end = np.empty(total, dtype=np.int64)
        else:
            owner = np.empty(0, dtype=np.int64)
            end = np.empty(0, dtype=np.int64)
        at = 0
        for q in range(n):
            qx = samples[q, 0]
            qy = samples[q, 1]
            bound = reach[q] * reach[q]
            c = 0
            m = _leaves_within(qx, qy, bound, boxes, offsets, stack_level, stack_node, leaves)[0]
            for j in range(m):
                node = leaves[j]
                for u in range(node * LEAF, min(npts, node * LEAF + LEAF)):
                    if _point2(points, u, qx, qy) <= bound:
                        for e in range(start[u], start[u + 1]):
                            if fill == 1:
                                owner[at] = q
                                end[at] = ends[e]
                                at += 1
                            c += 1
            counts[q] = c
            if fill == 0:
                total += c
                if total > limit:
                    return np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    return owner, end


@numba.njit(cache=True, nogil=True)
def nodes_within(samples: Any, boxes: Any, offsets: Any, reach: Any) -> Any:  # pragma: no cover
    """How many boxes of the tree (every level) lie within ``reach[i]`` of each sample.

    The nodes a search to that distance opens (:func:`pairs_within`'s work, and at least
    :func:`knn`'s to its k-th end): a measure of how much the boxes overlap where the
    samples are, not of the answer. ``boxes``, ``offsets``: :func:`build`'s.

    Returns:
        ``(N,)`` int64 counts.
    """
    n = len(samples)
    out = np.zeros(n, dtype=np.int64)
    stack_level, stack_node, _, _, leaves = _scratch(offsets)
    for q in range(n):
        bound = reach[q] * reach[q]
        qx, qy = samples[q, 0], samples[q, 1]
        out[q] = _leaves_within(qx, qy, bound, boxes, offsets, stack_level, stack_node, leaves)[1]
    return out


@numba.njit(inline="always")
def _leaves_within(
    qx: float,
    qy: float,
    bound: float,
    boxes: Any,
    offsets: Any,
    stack_level: Any,
    stack_node: Any,
    leaves: Any,
) -> tuple[int, int]:  # pragma: no cover - compiled
    """The leaves whose box lies within ``bound`` (squared) of ``(qx, qy)``, into ``leaves``.

    The tree is searched from its root, a node's children in order (the last pushed is
    searched first), a child only when its box is within ``bound``. ``stack_level``,
    ``stack_node``: scratch of ``64·FAN``; ``leaves``: room for every leaf
    (``offsets[1]``). Returns ``(m, opened)``: ``leaves[:m]`` in the order found, and the
    boxes within ``bound`` at every level.
    """
    stack_level[0] = len(offsets) - 2  # the root's level
    stack_node[0] = 0
    sp = 1
    m = 0
    opened = 0
    while sp > 0:
        sp -= 1
        level = stack_level[sp]
        node = stack_node[sp]
        if _box2(boxes, offsets[level] + node, qx, qy) > bound:
            continue
        opened += 1
        if level == 0:
            leaves[m] = node
            m += 1
            continue
        below = offsets[level - 1]
        count_below = offsets[level] - below
        for ch in range(node * FAN, min(count_below, node * FAN + FAN)):
            if _box2(boxes, below + ch, qx, qy) <= bound:
                stack_level[sp] = level - 1
                stack_node[sp] = ch
                sp += 1
    return m, opened


@numba.njit(inline="always")
def _segment(px: float, py: float, a: Any, b: Any, s: int) -> float:  # pragma: no cover - compiled
    """Distance of ``(px, py)`` to segment ``a[s] → b[s]``, the floats of numpy's form.

    :func:`camtool.verify.nearest_exact._to_segments` step for step: ``t`` the projection
    clipped to ``[0, 1]`` (0 for a point segment), then the length of ``ap − t·ab``;
    each product and sum as numpy takes them (two-term sums, no fused multiply-add).
    """
    abx = b[s, 0] - a[s, 0]
    aby = b[s, 1] - a[s, 1]
    apx = px - a[s, 0]
    apy = py - a[s, 1]
    length2 = abx * abx + aby * aby
    t = 0.0
    if length2 > 0:
        t = (apx * abx + apy * aby) / length2
    t = min(max(t, 0.0), 1.0)
    offx = apx - t * abx
    offy = apy - t * aby
    return math.sqrt(offx * offx + offy * offy)


@numba.njit(cache=True, nogil=True)
def near_segments(
    samples: Any,
    points: Any,
    boxes: Any,
    offsets: Any,
    start: Any,
    ends: Any,
    a: Any,
    b: Any,
    k: int,
) -> tuple[Any, Any, Any, Any]:  # pragma: no cover - compiled
    """The k-d tree path's distance to the segments of the ``k`` nearest ends, in one pass.

    For each sample, :func:`knn`'s ``k`` nearest ends (``points``, ``boxes``,
    ``offsets``, ``start``, ``ends``: :func:`tree` of ``concatenate([a, b])``, so end
    ``i`` belongs to segment ``i % len(a)``) and the least distance to their
    segments (:func:`_segment`). Where ends tie at the k-th distance the k-d tree keeps
    some of them; as :func:`camtool.verify.nearest_search._tied` does, every end within the
    k-th distance is looked at (the search's own list, or :func:`_ends_within` when it
    overflowed), and when any choice the k-d tree could make gives the same least
    distance it is that one; else ``ask`` (the caller asks the k-d tree).

    Returns:
        ``near`` ``(N,)`` (unset where ``ask``), ``r0_2`` and ``rk_2`` ``(N,)`` as
        :func:`knn` gives them, ``ask`` ``(N,)`` bool.
    """
    n = len(samples)
    m = len(a)
    r0_2 = np.empty(n, dtype=np.float64)
    rk_2 = np.empty(n, dtype=np.float64)
    near = np.empty(n, dtype=np.float64)
    ask = np.zeros(n, dtype=np.bool_)
    best = np.empty(k, dtype=np.float64)
    found = np.empty(CAP, dtype=np.int64)
    found2 = np.empty(CAP, dtype=np.float64)
    work = _scratch(offsets)
    last = 0
    for q in range(n):
        qx = samples[q, 0]
        qy = samples[q, 1]
        nearest, count, spill = _knn_one(
            qx, qy, points, boxes, offsets, start, ends, k, last, best, found, found2, work
        )
        kth2 = best[k - 1]
        if nearest >= 0:
            last = nearest
        r0_2[q] = best[0]
        rk_2[q] = kth2
        if spill:  # the list overflowed: every end within the k-th distance, searched again
            count = _ends_within(
                qx, qy, points, boxes, offsets, start, ends, kth2, found, found2, work
            )
            if count > CAP:  # _tied() sees only CAP of them: it asks the k-d tree
                ask[q] = True
                continue
        # the ends within the k-th distance (the list also holds some farther ones)
        low = np.inf
        low_nearer = np.inf
        nearer = 0
        at = 0
        for j in range(count):
            d2 = found2[j]
            if d2 <= kth2:
                value = _segment(qx, qy, a, b, found[j] % m)
                low = min(low, value)
                if d2 < kth2:
                    nearer += 1
                    low_nearer = min(low_nearer, value)
                else:
                    at += 1
        if nearer + at == k:  # the k nearest are one set: the k-d tree's
            near[q] = low
            continue
        reaching = 0  # the ends at the k-th distance whose segment reaches the least value
        for j in range(count):
            if found2[j] == kth2 and _segment(qx, qy, a, b, found[j] % m) == low:
                reaching += 1
        if low_nearer == low or at - reaching < k - nearer:
            near[q] = low
        else:
            ask[q] = True
    return near, r0_2, rk_2, ask


@numba.njit(inline="always")
def _ends_within(
    qx: float,
    qy: float,
    points: Any,
    boxes: Any,
    offsets: Any,
    start: Any,
    ends: Any,
    bound2: float,
    found: Any,
    found2: Any,
    work: tuple[Any, Any, Any, Any, Any],
) -> int:  # pragma: no cover - compiled
    """:func:`within` for one query: the ends within ``bound2`` into ``found``/``found2``.

    Returns how many there are (only the first :data:`CAP` are kept).
    """
    stack_level, stack_node, _, _, leaves = work
    npts = len(points)
    c = 0
    m = _leaves_within(qx, qy, bound2, boxes, offsets, stack_level, stack_node, leaves)[0]
    for j in range(m):
        node = leaves[j]
        for u in range(node * LEAF, min(npts, node * LEAF + LEAF)):
            d2 = _point2(points, u, qx, qy)
            if d2 <= bound2:
                for e in range(start[u], start[u + 1]):
                    if c < CAP:
                        found[c] = ends[e]
                        found2[c] = d2
                    c += 1
    return c


@numba.njit(inline="always")
def _geos_segment(px: float, py: float, a: Any, b: Any, s: int) -> float:  # pragma: no cover
    """GEOS's distance of ``(px, py)`` to segment ``a[s] → b[s]``, its floats exactly.

    ``Distance::pointToSegment`` of GEOS (``src/algorithm/Distance.cpp``), the distance
    ``shapely.distance`` gives between a point and a two-point line: the end's distance
    when the projection ``r`` falls at or before one end, else ``|s| · √L²``, every
    product and sum in GEOS's order (no fused multiply-add).
    """
    ax = a[s, 0]
    ay = a[s, 1]
    bx = b[s, 0]
    by = b[s, 1]
    if ax == bx and ay == by:
        dx = px - ax
        dy = py - ay
        return math.sqrt(dx * dx + dy * dy)
    length2 = (bx - ax) * (bx - ax) + (by - ay) * (by - ay)
    r = ((px - ax) * (bx - ax) + (py - ay) * (by - ay)) / length2
    if r <= 0.0:
        dx = px - ax
        dy = py - ay
        return math.sqrt(dx * dx + dy * dy)
    if r >= 1.0:
        dx = px - bx
        dy = py - by
        return math.sqrt(dx * dx + dy * dy)
    s_ = ((ay - py) * (bx - ax) - (ax - px) * (by - ay)) / length2
    return abs(s_) * math.sqrt(length2)


@numba.njit(cache=True, nogil=True)
def least_of_pairs(
    samples: Any, owner: Any, segment: Any, a: Any, b: Any
) -> Any:  # pragma: no cover - compiled
    """The least GEOS distance (:func:`_geos_segment`) of each sample over its pairs.

    Args:
        samples: ``(U, 2)`` query points.
        owner: ``(K,)`` the sample of each pair, ascending, naming every sample.
        segment: ``(K,)`` the segment of each pair (index into ``a``/``b``).
        a: ``(M, 2)`` segment starts.
        b: ``(M, 2)`` segment ends.

    Returns:
        ``(U,)`` float64 minima.
    """
    out = np.full(len(samples), np.inf)
    for j in range(len(owner)):
        q = owner[j]
        value = _geos_segment(samples[q, 0], samples[q, 1], a, b, segment[j])
        if value < out[q]:
            out[q] = value
    return out


def load_cached() -> None:
    """Load now the kernels a drawing comparison calls, for the types it calls them with.

    numba loads a kernel's machine code from its cache (or compiles it) at the kernel's
    first call in a process, ~10–15 ms for each of these. A verification that forks the
    error budget's workers (:func:`camtool.verify.drawing_compare.prepare_comparison`) calls this
    first, so the workers inherit them instead of each loading them again (the
    benchmark part: ~0.08 s of each worker's CPU, while every core is busy). The samples
    of a drawing come read-only (they are kept between comparisons), hence the second
    type of :func:`near_segments`. A signature no comparison uses would be loaded for
    nothing; the tests hold this list to the one a real verification uses. Only the time
    depends on it.
    """
    t = numba.types
    f1, f2, i1 = t.Array(t.float64, 1, "C"), t.Array(t.float64, 2, "C"), t.Array(t.int64, 1, "C")
    read_only = t.Array(t.float64, 2, "C", readonly=True)
    tree_of = (f2, f2, i1, i1, i1)  # points, boxes, offsets, start, ends (:func:`tree`)
    kernels = (
        (_fill, (f2, f2, i1)),
        (_merge, (t.Array(t.uint64, 2, "C"), t.int64)),
        (knn, (f2, *tree_of, t.int64)),
        (near_segments, (f2, *tree_of, f2, f2, t.int64)),
        (near_segments, (read_only, *tree_of, f2, f2, t.int64)),
        (pairs_within, (f2, *tree_of, f1, t.int64)),
        (nodes_within, (f2, f2, i1, f1)),
        (least_of_pairs, (f2, i1, i1, f2, f2)),
    )
    for kernel, types in kernels:
        kernel.compile(types)
