"""Travel order for large jobs: grid nearest neighbour and windowed, vectorised 2-opt.

:func:`camtool.toolpath.travel.travel_order` uses this above
:data:`~camtool.toolpath.travel.FULL_SEARCH_MAX_CUTS` cuts, where its full search
(an O(n) scan per nearest-neighbour step and O(n²) 2-opt sweeps) would take hours
on 10⁵–10⁶ cuts. The same steps, each in O(n) or O(n·w):

- nearest neighbour over the allowed entries (:func:`~camtool.toolpath.travel._candidates`)
  of the cuts whose predecessors are cut, found in a uniform grid of the entry
  points by rings of cells around the tool (exact: ties go to the lower entry,
  i.e. the lower cut, then vertex, as in the full search);
- 2-opt sweeps that reverse runs of at most :data:`TWO_OPT_WINDOW` cuts (no
  precedence pair inside a run), every improving run found at once and the
  non-overlapping ones applied left to right;
- start re-choice (vertex of a closed cut, direction of an open one) for the
  neighbours, even then odd positions; sweeps stop when one gains less than
  :data:`MIN_SWEEP_GAIN` of the rapids;
- the drawn order is compared (not improved): the result is never longer than it.

Sequences are arrays of entry indices (one entry per cut, in cutting order).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Point
from camtool.toolpath.cuts import Cut

TWO_OPT_WINDOW = 32
"""Longest run (in cuts) a windowed 2-opt move may reverse."""
_CHUNK = 32768
"""Positions evaluated together in a windowed 2-opt sweep (bounds memory to ~50 MB)."""
_GAIN_MM = 1e-9
MIN_SWEEP_GAIN = 1e-3
"""A sweep that shortens the rapids by less than this share ends the improvement."""
_PER_CELL = 2.0
"""Mean number of entry points per grid cell."""

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Entries:
    """Every allowed entry of every cut (see :func:`camtool.toolpath.travel._candidates`).

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
    from camtool.toolpath.travel import _candidates

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


def rapid(table: Entries, seq: IntArray, origin: Point) -> float:
    """Total rapid travel of the entries ``seq`` in order, origin first, mm."""
    if not len(seq):
        return 0.0
    s, e = table.starts[seq], table.finish[seq]
    first = math.hypot(s[0, 0] - origin[0], s[0, 1] - origin[1])
    return first + float(np.hypot(s[1:, 0] - e[:-1, 0], s[1:, 1] - e[:-1, 1]).sum())


def nearest_neighbour(table: Entries, before: Sequence[Sequence[int]], origin: Point) -> IntArray:
    """Greedy nearest-neighbour entries from ``origin``, predecessors first (see the module)."""
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
        x0, y0 = points.min(axis=0)
        x1, y1 = points.max(axis=0)
        w, h = float(x1 - x0), float(y1 - y0)
        count = max(1.0, len(points) / _PER_CELL)
        size = max(math.sqrt(w * h / count), max(w, h) / count)
        self.size = size if size > 0 else 1.0
        self.x0, self.y0 = float(x0), float(y0)
        ix = np.floor((points[:, 0] - x0) / self.size).astype(np.int64)
        iy = np.floor((points[:, 1] - y0) / self.size).astype(np.int64)
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


def improve(
    table: Entries,
    before: Sequence[Sequence[int]],
    seq: IntArray,
    origin: Point,
    sweeps: int,
) -> IntArray:
    """Windowed 2-opt and start re-choice sweeps on ``seq`` until they gain nothing."""
    owner_pred = np.asarray([a for a, bs in enumerate(before) for _ in bs], dtype=np.int64)
    pred = np.asarray([b for bs in before for b in bs], dtype=np.int64)
    best_seq, best = seq, rapid(table, seq, origin)
    for _ in range(sweeps):
        seq = two_opt(table, seq, origin, owner_pred, pred)
        seq = rechoose(table, seq, origin)
        total = rapid(table, seq, origin)
        if total >= best - _GAIN_MM:
            break
        best_seq, best, gain = seq, total, best - total
        if gain < MIN_SWEEP_GAIN * best:
            break
    return best_seq


def two_opt(
    table: Entries, seq: IntArray, origin: Point, owner_pred: IntArray, pred: IntArray
) -> IntArray:
    """One windowed sweep: every improving run found, the non-overlapping ones reversed."""
    from camtool.toolpath.travel import _latest_before

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


def rechoose(table: Entries, seq: IntArray, origin: Point) -> IntArray:
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
