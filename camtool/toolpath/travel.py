"""Cut sequences: precedence, start vertex and direction of a cut, rapid-travel ordering.

A *variant* of a cut is ``(k, rev)``: start at vertex ``k`` (the start of
``path.segments[k]``; always 0 for an open path) and traverse the path backwards
when ``rev``. A *sequence* is a list of ``(cut index, k, rev)`` in cutting order.

Precedence (issue 4, "inside before outside"): cut ``a`` comes after cut ``b`` when
``a``'s group contains ``b``'s group (``cuts[a].group in parents[cuts[b].group]``),
and pocket cuts of one group keep the relative order the pocket stage gave them.

:func:`travel_order` minimises the rapid travel (origin → first start, then each
end → next start, mm): greedy nearest neighbour over (cut, start vertex,
direction) among the cuts whose predecessors are cut, then 2-opt sweeps that
reverse a run of the sequence only where no precedence pair lies inside the run,
alternating with a re-choice of each cut's start vertex (or direction) for its
neighbours. The drawn order is improved the same way as a second seed and the shorter
result wins, so the travel order is never longer than the drawing's own. Deterministic:
ties go to the lower cut index, then vertex.

Above :data:`FULL_SEARCH_MAX_CUTS` cuts the same steps run in O(n) each
(:mod:`camtool.toolpath.travel_large`): a grid nearest neighbour, 2-opt runs of at
most :data:`~camtool.toolpath.travel_large.TWO_OPT_WINDOW` cuts, and the drawn
order compared but not improved.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Contour, Point, distance
from camtool.toolpath.cuts import Cut

Step = tuple[int, int, bool]
"""One entry of a sequence: ``(cut index, start vertex k, reversed)``."""

MAX_SWEEPS = 8
"""Bound on the 2-opt / vertex re-choice sweeps of :func:`travel_order`."""
FULL_SEARCH_MAX_CUTS = 2000
"""Up to this many cuts :func:`travel_order` searches fully (O(n²) per 2-opt sweep);
above it, the windowed O(n) search of :mod:`camtool.toolpath.travel_large`."""

_GAIN_MM = 1e-9


def precedence(cuts: Sequence[Cut], parents: Sequence[Sequence[int]]) -> list[tuple[int, ...]]:
    """For each cut, the indices of the cuts that must be cut before it.

    Args:
        cuts: the cuts; ``cut.group`` indexes ``parents``.
        parents: ``parents[g]`` = groups (contours) containing group ``g``
            (:attr:`camtool.toolpath.order.Nesting.parents`).
    """
    by_group: dict[int, list[int]] = {}
    for i, cut in enumerate(cuts):
        by_group.setdefault(cut.group, []).append(i)
    before: list[set[int]] = [set() for _ in cuts]
    for b, cut in enumerate(cuts):
        for g in parents[cut.group]:
            for a in by_group.get(g, ()):
                before[a].add(b)
    for members in by_group.values():
        pockets = [i for i in members if cuts[i].kind == "pocket"]
        for prev, nxt in itertools.pairwise(pockets):
            before[nxt].add(prev)
    return [tuple(sorted(s)) for s in before]


def respects(order: Sequence[int], before: Sequence[Sequence[int]]) -> bool:
    """True when every cut of ``order`` comes after all cuts in its ``before`` list."""
    pos = {c: p for p, c in enumerate(order)}
    return all(pos[b] < pos[a] for a in order for b in before[a])


def oriented(cut: Cut, k: int, rev: bool) -> Cut:
    """``cut`` started at vertex ``k`` and reversed when ``rev`` (material side swapped)."""
    out = cut.reversed() if rev else cut
    if not cut.path.closed:
        return out
    segs = out.path.segments
    n = len(segs)
    j = (n - k) % n if rev else k % n
    if j == 0:
        return out
    path = Contour(segs[j:] + segs[:j], True, out.path.layer, out.path.source)
    return replace(out, path=path)


def vertex(path: Contour, k: int) -> Point:
    """Start point of ``path.segments[k]``, mm."""
    return path.segments[k].start


def ends(cut: Cut, k: int, rev: bool) -> tuple[Point, Point]:
    """Start and end point, mm, of ``cut`` cut as variant ``(k, rev)``."""
    if cut.path.closed:
        p = vertex(cut.path, k)
        return p, p
    a, b = cut.path.start, cut.path.end
    return (b, a) if rev else (a, b)


def drawn_order(cuts: Sequence[Cut], before: Sequence[Sequence[int]]) -> list[Step]:
    """The cuts as given (start and direction as drawn), in the given order where precedence allows.

    Repeatedly the lowest-index cut whose predecessors are all cut.
    """
    waiting = [len(b) for b in before]
    after: list[list[int]] = [[] for _ in cuts]
    for a, bs in enumerate(before):
        for b in bs:
            after[b].append(a)
    heap = [i for i, w in enumerate(waiting) if w == 0]
    heapq.heapify(heap)
    out: list[Step] = []
    while heap:
        i = heapq.heappop(heap)
        out.append((i, 0, False))
        for a in after[i]:
            waiting[a] -= 1
            if waiting[a] == 0:
                heapq.heappush(heap, a)
    if len(out) != len(cuts):
        raise ValueError("cyclic precedence between cuts")
    return out


def rapid_mm(cuts: Sequence[Cut], seq: Sequence[Step], origin: Point) -> float:
    """Total rapid travel of ``seq``: origin → first start plus each end → next start, mm."""
    here, total = origin, 0.0
    for i, k, rev in seq:
        start, end = ends(cuts[i], k, rev)
        total += distance(here, start)
        here = end
    return total


def _candidates(
    cuts: Sequence[Cut], flip_open: bool
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], list[Step], list[int]]:
    """Every allowed entry of every cut.

    Returns starts ``(P, 2)``, ends ``(P, 2)`` (mm), the steps, and ``first``:
    ``first[i]`` is the index of cut ``i``'s first candidate (``first[-1] = P``).
    """
    starts: list[Point] = []
    finish: list[Point] = []
    steps: list[Step] = []
    first: list[int] = []
    for i, cut in enumerate(cuts):
        first.append(len(steps))
        if cut.path.closed:
            ks = range(len(cut.path.segments)) if cut.may_rotate else range(1)
            variants = [(k, False) for k in ks]
        else:
            variants = [(0, False)] + ([(0, True)] if flip_open and cut.may_reverse else [])
        for k, rev in variants:
            s, e = ends(cut, k, rev)
            starts.append(s)
            finish.append(e)
            steps.append((i, k, rev))
    first.append(len(steps))
    return (
        np.asarray(starts, dtype=np.float64).reshape(-1, 2),
        np.asarray(finish, dtype=np.float64).reshape(-1, 2),
        steps,
        first,
    )


def travel_order(
    cuts: Sequence[Cut],
    before: Sequence[Sequence[int]],
    origin: Point,
    *,
    flip_open: bool = True,
) -> list[Step]:
    """A short-rapid cutting sequence that respects ``before`` (see the module).

    Args:
        cuts: the cuts, mm.
        before: :func:`precedence` of ``cuts``.
        origin: tool position before the first cut, mm.
        flip_open: open cuts with ``may_reverse`` may be cut backwards.

    Returns:
        ``(cut index, start vertex, reversed)`` for every cut, in cutting order.
    """
    if not cuts:
        return []
    if len(cuts) > FULL_SEARCH_MAX_CUTS:
        return _large_travel_order(cuts, before, origin, flip_open)
    seeds = (_nearest_neighbour(cuts, before, origin, flip_open), drawn_order(cuts, before))
    improved = [_improve(cuts, before, seed, origin, flip_open) for seed in seeds]
    # The drawn order is a seed too, so the result is never longer than the drawing's own.
    return min(improved, key=lambda seq: rapid_mm(cuts, seq, origin))


def _large_travel_order(
    cuts: Sequence[Cut], before: Sequence[Sequence[int]], origin: Point, flip_open: bool
) -> list[Step]:
    from camtool.toolpath import travel_large as large

    table, steps = large.entries(cuts, flip_open)
    seq = large.nearest_neighbour(table, before, origin)
    seq = large.improve(table, before, seq, origin, MAX_SWEEPS)
    drawn = table.first[[i for i, _, _ in drawn_order(cuts, before)]]
    if large.rapid(table, drawn, origin) < large.rapid(table, seq, origin):
        seq = drawn
    return [steps[p] for p in seq.tolist()]


def _improve(
    cuts: Sequence[Cut],
    before: Sequence[Sequence[int]],
    seq: list[Step],
    origin: Point,
    flip_open: bool,
) -> list[Step]:
    """2-opt and start re-choice sweeps on ``seq`` until they gain nothing (or MAX_SWEEPS)."""
    best_seq, best = seq, rapid_mm(cuts, seq, origin)
    for _ in range(MAX_SWEEPS):
        seq = _two_opt(cuts, before, seq, origin, flip_open)
        seq = rechoose_starts(cuts, seq, origin, flip_open)
        total = rapid_mm(cuts, seq, origin)
        if total >= best - _GAIN_MM:
            break
        best_seq, best = seq, total
    return best_seq


def _nearest_neighbour(
    cuts: Sequence[Cut], before: Sequence[Sequence[int]], origin: Point, flip_open: bool
) -> list[Step]:
    starts, finish, steps, first = _candidates(cuts, flip_open)
    waiting = np.asarray([len(b) for b in before])
    after: list[list[int]] = [[] for _ in cuts]
    for a, bs in enumerate(before):
        for b in bs:
            after[b].append(a)
    active = np.zeros(len(steps), dtype=bool)
    for r in np.flatnonzero(waiting == 0):
        active[first[r] : first[r + 1]] = True
    here = np.asarray(origin, dtype=np.float64)
    out: list[Step] = []
    for _ in range(len(cuts)):
        d = np.hypot(starts[:, 0] - here[0], starts[:, 1] - here[1])
        d[~active] = np.inf
        p = int(np.argmin(d))  # first minimum: lowest cut, then vertex
        i = int(steps[p][0])
        out.append(steps[p])
        here = finish[p]
        active[first[i] : first[i + 1]] = False
        for a in after[i]:
            waiting[a] -= 1
            if waiting[a] == 0:
                active[first[a] : first[a + 1]] = True
    return out


def _two_opt(
    cuts: Sequence[Cut],
    before: Sequence[Sequence[int]],
    seq: list[Step],
    origin: Point,
    flip_open: bool,
) -> list[Step]:
    """One sweep of precedence-safe 2-opt moves (best ``j`` for each ``i``)."""
    n = len(seq)
    seq = list(seq)
    owner = np.asarray([a for a, bs in enumerate(before) for _ in bs], dtype=np.int64)
    pred = np.asarray([b for bs in before for b in bs], dtype=np.int64)
    flippable = np.asarray(
        [cut.path.closed or (flip_open and cut.may_reverse) for cut in cuts], dtype=bool
    )
    pts = [ends(cuts[i], k, rev) for i, k, rev in seq]
    s = np.asarray([p[0] for p in pts], dtype=np.float64).reshape(-1, 2)
    e = np.asarray([p[1] for p in pts], dtype=np.float64).reshape(-1, 2)
    order = np.asarray([c for c, _, _ in seq], dtype=np.int64)
    latest = _latest_before(order, owner, pred, len(cuts))
    for i in range(n):
        bad = (latest[i:] >= i) | ~flippable[order[i:]]
        stop = int(np.argmax(bad)) if bad.any() else n - i
        if stop == 0:
            continue
        j = np.arange(i, i + stop)
        prev = e[i - 1] if i > 0 else np.asarray(origin, dtype=np.float64)
        nxt_ok = j + 1 < n
        nxt = s[np.minimum(j + 1, n - 1)]
        gain = _dist(prev, e[j]) - _dist(prev, s[i])
        gain = gain + np.where(nxt_ok, _dist(s[i], nxt) - _dist2(e[j], nxt), 0.0)
        m = int(np.argmin(gain))
        if gain[m] >= -_GAIN_MM:
            continue
        jj = i + m
        seq[i : jj + 1] = [
            (c, k, not rev if not cuts[c].path.closed else rev)
            for c, k, rev in reversed(seq[i : jj + 1])
        ]
        s[i : jj + 1], e[i : jj + 1] = e[i : jj + 1][::-1].copy(), s[i : jj + 1][::-1].copy()
        order[i : jj + 1] = order[i : jj + 1][::-1].copy()
        latest = _latest_before(order, owner, pred, len(cuts))
    return seq


def _dist(p: npt.NDArray[np.float64], q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.hypot(q[..., 0] - p[..., 0], q[..., 1] - p[..., 1])


def _dist2(p: npt.NDArray[np.float64], q: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.hypot(q[:, 0] - p[:, 0], q[:, 1] - p[:, 1])


def _latest_before(
    order: npt.NDArray[np.int64], owner: npt.NDArray[np.int64], pred: npt.NDArray[np.int64], n: int
) -> npt.NDArray[np.int64]:
    """``(len(order),)``: position of the latest predecessor of the cut at each position."""
    pos = np.empty(n, dtype=np.int64)
    pos[order] = np.arange(len(order))
    latest = np.full(n, -1, dtype=np.int64)
    if len(pred):
        np.maximum.at(latest, owner, pos[pred])
    return latest[order]


def rechoose_starts(
    cuts: Sequence[Cut], seq: Sequence[Step], origin: Point, flip_open: bool
) -> list[Step]:
    """Each cut's start re-chosen for its neighbours, first to last.

    The start vertex of closed cuts with ``may_rotate``, the direction of open
    cuts with ``may_reverse`` when ``flip_open``.
    """
    out = list(seq)
    for p, (i, _, rev) in enumerate(out):
        cut = cuts[i]
        prev = ends(cuts[out[p - 1][0]], *out[p - 1][1:])[1] if p else origin
        nxt = ends(cuts[out[p + 1][0]], *out[p + 1][1:])[0] if p + 1 < len(out) else None
        if cut.path.closed and cut.may_rotate:
            v = np.asarray([seg.start for seg in cut.path.segments], dtype=np.float64)
            cost = np.hypot(v[:, 0] - prev[0], v[:, 1] - prev[1])
            if nxt is not None:
                cost = cost + np.hypot(v[:, 0] - nxt[0], v[:, 1] - nxt[1])
            out[p] = (i, int(np.argmin(cost)), rev)
        elif not cut.path.closed and flip_open and cut.may_reverse:
            costs = []
            for r in (False, True):
                s, e = ends(cut, 0, r)
                costs.append(distance(prev, s) + (distance(e, nxt) if nxt is not None else 0.0))
            out[p] = (i, 0, costs[1] < costs[0] - _GAIN_MM)
    return out
