"""Cut sequences: precedence, start vertex and direction of a cut, rapid-travel ordering.

A *variant* of a cut is ``(k, rev)``: start at vertex ``k`` (the start of
``path.segments[k]``; always 0 for an open path) and traverse the path backwards
when ``rev``. A *sequence* is a list of ``(cut index, k, rev)`` in cutting order.

Design notes: docs/internals.md, ``camtool/toolpath/travel.py``.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

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
above it, the windowed O(n) search of :func:`_large_travel_order`."""

_GAIN_MM = 1e-9
_PER_CELL = 2.0
"""Mean number of candidate or entry points per grid cell (:class:`_Cells`, :class:`_Grid`)."""

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


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
        path = cut.path
        if path.closed:  # every vertex (or the first) a start, where the cut also ends
            vertices = [seg.start for seg in path.segments] if cut.may_rotate else [path.start]
            starts += vertices
            finish += vertices
            steps += zip(itertools.repeat(i), range(len(vertices)), itertools.repeat(False))
            continue
        a, b = path.start, path.end
        starts.append(a)
        finish.append(b)
        steps.append((i, 0, False))
        if flip_open and cut.may_reverse:
            starts.append(b)
            finish.append(a)
            steps.append((i, 0, True))
    first.append(len(steps))
    flat = itertools.chain.from_iterable
    return (
        np.fromiter(flat(starts), np.float64, 2 * len(starts)).reshape(-1, 2),
        np.fromiter(flat(finish), np.float64, 2 * len(finish)).reshape(-1, 2),
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
    table, steps = entries(cuts, flip_open)
    seq = grid_nearest_neighbour(table, before, origin)
    seq = windowed_improve(table, before, seq, origin, MAX_SWEEPS)
    drawn = table.first[[i for i, _, _ in drawn_order(cuts, before)]]
    if entries_rapid_mm(table, drawn, origin) < entries_rapid_mm(table, seq, origin):
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
    vertices: dict[int, FloatArray] = {}
    for _ in range(MAX_SWEEPS):
        seq = _two_opt(cuts, before, seq, origin, flip_open)
        seq = rechoose_starts(cuts, seq, origin, flip_open, vertices)
        total = rapid_mm(cuts, seq, origin)
        if total >= best - _GAIN_MM:
            break
        best_seq, best = seq, total
    return best_seq


def _nearest_neighbour(
    cuts: Sequence[Cut], before: Sequence[Sequence[int]], origin: Point, flip_open: bool
) -> list[Step]:
    """Greedy nearest neighbour over every allowed start of the cuts whose predecessors are cut.

    Each step takes the active candidate start nearest to the tool (``np.hypot``), ties to
    the lowest candidate (the lower cut, then vertex). The candidates are searched by
    rings of grid cells around the tool (:class:`_Cells`), which answers exactly what a
    scan of them all answers (:func:`_nearest_neighbour_scan`, kept for the tests) at a
    fraction of the cost when the cuts have many vertices.
    """
    starts, finish, steps, first = _candidates(cuts, flip_open)
    waiting = [len(b) for b in before]
    after: list[list[int]] = [[] for _ in cuts]
    for a, bs in enumerate(before):
        for b in bs:
            after[b].append(a)
    active = np.zeros(len(steps), dtype=bool)
    for r, w in enumerate(waiting):
        if w == 0:
            active[first[r] : first[r + 1]] = True
    cells = _Cells(starts, active)
    hx, hy = float(origin[0]), float(origin[1])
    out: list[Step] = []
    for _ in range(len(cuts)):
        p = cells.nearest(hx, hy)
        i = int(steps[p][0])
        out.append(steps[p])
        hx, hy = float(finish[p, 0]), float(finish[p, 1])
        active[first[i] : first[i + 1]] = False
        for a in after[i]:
            waiting[a] -= 1
            if waiting[a] == 0:
                active[first[a] : first[a + 1]] = True
    return out


def _nearest_neighbour_scan(
    cuts: Sequence[Cut], before: Sequence[Sequence[int]], origin: Point, flip_open: bool
) -> list[Step]:
    """:func:`_nearest_neighbour` by a scan of every candidate at each step (the reference)."""
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


def _cell_grid(points: FloatArray) -> tuple[float, float, float, IntArray, IntArray]:
    """Square cells over ``points`` ``(P, 2)`` mm, :data:`_PER_CELL` points a cell on average.

    Returns the grid's corner ``x0, y0`` and cell ``size`` (mm), and each point's cell
    column and row ``(P,)``.
    """
    x0, y0 = points.min(axis=0)
    x1, y1 = points.max(axis=0)
    w, h = float(x1 - x0), float(y1 - y0)
    count = max(1.0, len(points) / _PER_CELL)
    size = max(math.sqrt(w * h / count), max(w, h) / count)
    size = size if size > 0 else 1.0
    ix = np.floor((points[:, 0] - x0) / size).astype(np.int64)
    iy = np.floor((points[:, 1] - y0) / size).astype(np.int64)
    return float(x0), float(y0), size, ix, iy


class _Cells:
    """Candidate points in square grid cells; the nearest active one as a full scan finds it.

    ``points``: ``(P, 2)`` mm; ``active``: ``(P,)`` mask, owned and updated by the caller.
    Distances are ``np.hypot`` of the same differences as the scan, so the answer (the
    least distance, the lowest index among equals) is the scan's bit for bit. The rings
    stop once the best distance is below the nearest a point outside them can be (less a
    millionth of a cell, far above the rounding of the cell indices); past
    :data:`_PER_CELL`-sized rings that cover the grid, a scan answers.
    """

    def __init__(self, points: FloatArray, active: npt.NDArray[np.bool_]) -> None:
        self.points, self.active = points, active
        self.xs, self.ys = points[:, 0], points[:, 1]
        self.x0, self.y0, self.size, ix, iy = _cell_grid(points)
        order = np.lexsort((iy, ix))  # stable: each cell's indices ascending
        keys = np.stack((ix[order], iy[order]), axis=1)
        cut = np.flatnonzero(np.any(keys[1:] != keys[:-1], axis=1)) + 1
        self.cells: dict[tuple[int, int], IntArray] = {
            (int(k[0]), int(k[1])): part
            for k, part in zip(keys[np.r_[0, cut]], np.split(order, cut), strict=True)
        }

    def nearest(self, hx: float, hy: float) -> int:
        """Index of the active point nearest to ``(hx, hy)`` mm; ties to the lowest index."""
        cx = math.floor((hx - self.x0) / self.size)
        cy = math.floor((hy - self.y0) / self.size)
        best_d, best_p = math.inf, -1
        r = 0
        while True:
            if (2 * r + 1) ** 2 > 4 * len(self.cells) + 16:
                return self._scan(hx, hy)
            cells = (self.cells.get(cell) for cell in _ring(cx, cy, r))
            found = [part for part in cells if part is not None]
            if found:
                idx = found[0] if len(found) == 1 else np.concatenate(found)
                idx = idx[self.active[idx]]
                if len(idx):
                    d = np.hypot(self.xs[idx] - hx, self.ys[idx] - hy)
                    m = float(d.min())
                    p = int(idx[d == m].min())
                    if m < best_d or (m == best_d and p < best_p):
                        best_d, best_p = m, p
            # every point not yet seen lies in ring r + 1 or further: at least r cells away
            if best_p >= 0 and best_d < (r - 1e-6) * self.size:
                return best_p
            r += 1

    def _scan(self, hx: float, hy: float) -> int:
        d = np.hypot(self.xs - hx, self.ys - hy)
        d[~self.active] = np.inf
        return int(np.argmin(d))  # first minimum: lowest index


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
    cuts: Sequence[Cut],
    seq: Sequence[Step],
    origin: Point,
    flip_open: bool,
    vertices: dict[int, FloatArray] | None = None,
) -> list[Step]:
    """Each cut's start re-chosen for its neighbours, first to last.

    The start vertex of closed cuts with ``may_rotate``, the direction of open
    cuts with ``may_reverse`` when ``flip_open``. ``vertices``: a cache of the closed
    cuts' vertex arrays ``(n, 2)`` mm by cut index, filled here, kept by a caller that
    sweeps again.
    """
    vertices = {} if vertices is None else vertices
    out = list(seq)
    for p, (i, _, rev) in enumerate(out):
        cut = cuts[i]
        prev = ends(cuts[out[p - 1][0]], *out[p - 1][1:])[1] if p else origin
        nxt = ends(cuts[out[p + 1][0]], *out[p + 1][1:])[0] if p + 1 < len(out) else None
        if cut.path.closed and cut.may_rotate:
            v = vertices.get(i)
            if v is None:
                v = np.asarray([seg.start for seg in cut.path.segments], dtype=np.float64)
                vertices[i] = v
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


# Large jobs (above FULL_SEARCH_MAX_CUTS): the same steps on entry arrays, O(n) or O(n·w).

TWO_OPT_WINDOW = 32
"""Longest run (in cuts) a windowed 2-opt move may reverse."""
_CHUNK = 4096
"""Positions evaluated together in a windowed 2-opt sweep (its arrays: ~13 MB at a time)."""
MIN_SWEEP_GAIN = 1e-3
"""A sweep that shortens the rapids by less than this share ends the improvement."""


@dataclass(frozen=True)
class Entries:
    """Every allowed entry of every cut (see :func:`_candidates`).

    ``starts``, ``finish``: ``(P, 2)`` mm; ``owner``: ``(P,)`` cut of each entry;
    ``first``: ``(n + 1,)`` first entry of each cut (``first[n] = P``); ``partner``:
    ``(P,)`` the entry of the same cut traversed the other way (itself for closed
    cuts, whose ends do not change); ``bias``: ``(P,)`` mm added to an entry's cost in
    the start re-choice (a reversed open cut must gain more than 1 nm);
    ``flippable``: ``(n,)`` a 2-opt run may hold the cut.
    """

    starts: FloatArray
    finish: FloatArray
    owner: IntArray
    first: IntArray
    partner: IntArray
    bias: FloatArray
    flippable: npt.NDArray[np.bool_]


def entries(cuts: Sequence[Cut], flip_open: bool) -> tuple[Entries, list[tuple[int, int, bool]]]:
    """The :class:`Entries` of ``cuts`` and the step ``(cut, k, rev)`` of each entry."""
    starts, finish, steps, first = _candidates(cuts, flip_open)
    first_a = np.asarray(first, dtype=np.int64)
    owner = np.repeat(np.arange(len(cuts), dtype=np.int64), np.diff(first_a))
    partner = np.arange(len(steps), dtype=np.int64)
    bias = np.zeros(len(steps))
    for p, (i, _, rev) in enumerate(steps):
        if not cuts[i].path.closed and first[i + 1] - first[i] == 2:
            partner[p] = p + 1 if p == first[i] else p - 1
            bias[p] = _GAIN_MM if rev else 0.0
    flippable = np.asarray(
        [cut.path.closed or (flip_open and cut.may_reverse) for cut in cuts], dtype=bool
    )
    return Entries(starts, finish, owner, first_a, partner, bias, flippable), steps


def entries_rapid_mm(table: Entries, seq: IntArray, origin: Point) -> float:
    """Total rapid travel of the entries ``seq`` in order, origin first, mm."""
    if not len(seq):
        return 0.0
    s, e = table.starts[seq], table.finish[seq]
    first = math.hypot(s[0, 0] - origin[0], s[0, 1] - origin[1])
    return first + float(np.hypot(s[1:, 0] - e[:-1, 0], s[1:, 1] - e[:-1, 1]).sum())


def grid_nearest_neighbour(
    table: Entries, before: Sequence[Sequence[int]], origin: Point
) -> IntArray:
    """Greedy nearest-neighbour entries from ``origin``, predecessors first, by grid cells."""
    n = len(table.first) - 1
    grid = _Grid(table.starts)
    waiting = [len(b) for b in before]
    after: list[list[int]] = [[] for _ in range(n)]
    for a, bs in enumerate(before):
        for b in bs:
            after[b].append(a)
    first = table.first.tolist()
    for i in range(n):
        if waiting[i] == 0:
            grid.add(range(first[i], first[i + 1]))
    out = np.empty(n, dtype=np.int64)
    hx, hy = float(origin[0]), float(origin[1])
    finish = table.finish.tolist()
    owner = table.owner.tolist()
    for step in range(n):
        p = grid.nearest(hx, hy)
        i = owner[p]
        out[step] = p
        hx, hy = finish[p]
        grid.remove(range(first[i], first[i + 1]))
        for a in after[i]:
            waiting[a] -= 1
            if waiting[a] == 0:
                grid.add(range(first[a], first[a + 1]))
    return out


class _Grid:
    """Active entry points in square cells; exact nearest by rings of cells."""

    def __init__(self, points: FloatArray) -> None:
        self.points = points
        self.xs: list[float] = points[:, 0].tolist()
        self.ys: list[float] = points[:, 1].tolist()
        self.x0, self.y0, self.size, ix, iy = _cell_grid(points)
        self.cell_of: list[tuple[int, int]] = list(zip(ix.tolist(), iy.tolist(), strict=True))
        self.cells: dict[tuple[int, int], list[int]] = {}
        self.active = np.zeros(len(points), dtype=bool)
        self.live = 0

    def add(self, ps: range) -> None:
        for p in ps:
            self.cells.setdefault(self.cell_of[p], []).append(p)
        self.active[ps.start : ps.stop] = True
        self.live += len(ps)

    def remove(self, ps: range) -> None:
        for p in ps:
            cell = self.cells[self.cell_of[p]]
            cell.remove(p)
            if not cell:
                del self.cells[self.cell_of[p]]
        self.active[ps.start : ps.stop] = False
        self.live -= len(ps)

    def nearest(self, hx: float, hy: float) -> int:
        """The active entry nearest to ``(hx, hy)``; ties to the lowest index."""
        cx = math.floor((hx - self.x0) / self.size)
        cy = math.floor((hy - self.y0) / self.size)
        xs, ys, cells = self.xs, self.ys, self.cells
        best_d, best_p = math.inf, -1
        r = 0
        while True:
            if (2 * r + 1) ** 2 > 4 * self.live + 16:
                return self._scan(hx, hy)
            for cell in _ring(cx, cy, r):
                for p in cells.get(cell, ()):
                    d = math.hypot(xs[p] - hx, ys[p] - hy)
                    if d < best_d or (d == best_d and p < best_p):
                        best_d, best_p = d, p
            # every point not yet seen lies in ring r + 1 or further: at least r cells away
            if best_p >= 0 and best_d < (r - 1e-6) * self.size:
                return best_p
            r += 1

    def _scan(self, hx: float, hy: float) -> int:
        idx = np.flatnonzero(self.active)
        pts = self.points[idx]
        d = np.hypot(pts[:, 0] - hx, pts[:, 1] - hy)
        return int(idx[int(np.argmin(d))])  # first minimum: lowest entry


def _ring(cx: int, cy: int, r: int) -> list[tuple[int, int]]:
    if r == 0:
        return [(cx, cy)]
    out = [(cx + dx, cy - r) for dx in range(-r, r + 1)]
    out += [(cx + dx, cy + r) for dx in range(-r, r + 1)]
    out += [(cx - r, cy + dy) for dy in range(-r + 1, r)]
    out += [(cx + r, cy + dy) for dy in range(-r + 1, r)]
    return out


def windowed_improve(
    table: Entries,
    before: Sequence[Sequence[int]],
    seq: IntArray,
    origin: Point,
    sweeps: int,
) -> IntArray:
    """Windowed 2-opt and start re-choice sweeps on ``seq`` until they gain nothing."""
    owner_pred = np.asarray([a for a, bs in enumerate(before) for _ in bs], dtype=np.int64)
    pred = np.asarray([b for bs in before for b in bs], dtype=np.int64)
    best_seq, best = seq, entries_rapid_mm(table, seq, origin)
    for _ in range(sweeps):
        seq = windowed_two_opt(table, seq, origin, owner_pred, pred)
        seq = rechoose_entries(table, seq, origin)
        total = entries_rapid_mm(table, seq, origin)
        if total >= best - _GAIN_MM:
            break
        best_seq, best, gain = seq, total, best - total
        if gain < MIN_SWEEP_GAIN * best:
            break
    return best_seq


def windowed_two_opt(
    table: Entries, seq: IntArray, origin: Point, owner_pred: IntArray, pred: IntArray
) -> IntArray:
    """One windowed sweep: every improving run found, the non-overlapping ones reversed."""
    n = len(seq)
    cut = table.owner[seq]
    latest = _latest_before(cut, owner_pred, pred, len(table.first) - 1)
    ok = table.flippable[cut]
    s, e = table.starts[seq], table.finish[seq]
    prev = np.vstack((np.asarray(origin, dtype=np.float64)[None, :], e[:-1]))
    width = np.arange(TWO_OPT_WINDOW)
    best_gain = np.empty(n)
    best_end = np.empty(n, dtype=np.int64)
    for lo in range(0, n, _CHUNK):
        i = np.arange(lo, min(n, lo + _CHUNK))
        j = i[:, None] + width[None, :]
        inside = j < n
        jc = np.minimum(j, n - 1)
        bad = ~inside | ~ok[jc] | (latest[jc] >= i[:, None])
        bad = np.logical_or.accumulate(bad, axis=1)
        nc = np.minimum(j + 1, n - 1)
        pi, si = prev[i][:, None, :], s[i][:, None, :]
        gain = _hyp(pi, e[jc]) - _hyp(pi, si)
        gain = gain + np.where(j + 1 < n, _hyp(si, s[nc]) - _hyp(e[jc], s[nc]), 0.0)
        gain[bad] = np.inf
        m = np.argmin(gain, axis=1)
        best_gain[i] = gain[np.arange(len(i)), m]
        best_end[i] = i + m
    starts: list[int] = []
    ends: list[int] = []
    last = -2
    for p in np.flatnonzero(best_gain < -_GAIN_MM).tolist():
        if p > last + 1:
            last = int(best_end[p])
            starts.append(p)
            ends.append(last)
    return _reverse_runs(table, seq, np.asarray(starts, dtype=np.int64), np.asarray(ends))


def _hyp(p: FloatArray, q: FloatArray) -> FloatArray:
    return np.hypot(q[..., 0] - p[..., 0], q[..., 1] - p[..., 1])


def _reverse_runs(table: Entries, seq: IntArray, lo: IntArray, hi: IntArray) -> IntArray:
    """``seq`` with each run ``lo[k]..hi[k]`` reversed, its open cuts turned round."""
    if not len(lo):
        return seq
    out = seq.copy()
    lengths = hi - lo + 1
    pos = np.repeat(lo, lengths) + (
        np.arange(lengths.sum()) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    )
    src = np.repeat(lo + hi, lengths) - pos
    out[pos] = table.partner[seq[src]]
    return out


def rechoose_entries(table: Entries, seq: IntArray, origin: Point) -> IntArray:
    """Each cut's entry re-chosen for its neighbours: even positions, then odd ones."""
    seq = seq.copy()
    n = len(seq)
    counts_all = np.diff(table.first)
    origin_a = np.asarray(origin, dtype=np.float64)
    for parity in (0, 1):
        pos = np.arange(parity, n, 2)
        cut = table.owner[seq[pos]]
        counts = counts_all[cut]
        pos, cut, counts = pos[counts > 1], cut[counts > 1], counts[counts > 1]
        if not len(pos):
            continue
        prev = np.where((pos > 0)[:, None], table.finish[seq[pos - 1]], origin_a)
        has_next = pos + 1 < n
        nxt = table.starts[seq[np.minimum(pos + 1, n - 1)]]
        offsets = np.cumsum(counts) - counts
        cand = np.repeat(table.first[cut] - offsets, counts) + np.arange(counts.sum())
        cost = _hyp(np.repeat(prev, counts, axis=0), table.starts[cand])
        cost = cost + np.where(
            np.repeat(has_next, counts),
            _hyp(table.finish[cand], np.repeat(nxt, counts, axis=0)),
            0.0,
        )
        cost = cost + table.bias[cand]
        least = np.minimum.reduceat(cost, offsets)
        hit = np.flatnonzero(cost == np.repeat(least, counts))
        group = np.searchsorted(offsets, hit, side="right") - 1
        _, firsts = np.unique(group, return_index=True)
        seq[pos] = cand[hit[firsts]]
    return seq
