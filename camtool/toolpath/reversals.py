"""Axis direction reversals of a cutting sequence, and an order that needs few of them.

The model (UNAM-GMM §5.1, L1707–L1709: the controller compensates backlash
"whenever any axis changes direction", on rapids as well as cuts):

Design notes: docs/internals.md, ``camtool/toolpath/reversals.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import SIGN_EPS, TAU, Arc, Line, Point, Segment
from camtool.toolpath.cuts import Cut
from camtool.toolpath.travel import Step, ends, oriented, rapid_mm, travel_order

MOVE_EPS_MM = 1e-9
"""A line moving an axis by less than this does not move it."""

IMPROVE_MAX_CUTS = 40
"""Neighbour swaps (each re-running the variant choice) only up to this many cuts."""
IMPROVE_PASSES = 4
"""Bound on the neighbour-swap passes."""
_TRAVEL_PER_REVERSAL_MM = 1e6
"""Travel worth one unit-weight reversal in the combined key (reversals dominate)."""


def segment_signs(seg: Segment) -> tuple[Sequence[int], Sequence[int]]:
    """Successive directions (+1/-1) in which ``seg`` moves X and Y (see the module).

    An arc's are its :attr:`~camtool.model.shapes.Arc.axis_signs` (computed once, shared
    tuples): callers read them, never change them.
    """
    if isinstance(seg, Line):
        return _line_signs(seg.end[0] - seg.start[0], seg.end[1] - seg.start[1])
    return seg.axis_signs


def _line_signs(dx: float, dy: float) -> tuple[list[int], list[int]]:
    """X and Y directions of a straight move by ``(dx, dy)`` mm (none for a still axis)."""
    return ([_sign(dx)] if abs(dx) > MOVE_EPS_MM else []), (
        [_sign(dy)] if abs(dy) > MOVE_EPS_MM else []
    )


def _sign(v: float) -> int:
    return 1 if v > 0 else -1


def _path_signs(segments: Sequence[Segment]) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
    """Per axis: ``(segment index, sign)`` of every motion piece, in path order."""
    xs: list[tuple[int, int]] = []
    ys: list[tuple[int, int]] = []
    for g, seg in enumerate(segments):
        sx, sy = segment_signs(seg)
        xs.extend((g, v) for v in sx)
        ys.extend((g, v) for v in sy)
    return xs, ys


def count_reversals(cuts: Sequence[Cut], start: Point) -> tuple[int, int]:
    """Axis direction reversals ``(rx, ry)`` of cutting ``cuts`` in the order given.

    Counts the rapids (start → first cut, each cut's end → next start) as lines
    and each cut's path as given (its start, its direction), with the model of
    this module: the first motion of each axis sets its direction without
    counting; an axis that does not move keeps its direction; arcs reverse X at
    their left/right extreme points and Y at their top/bottom ones (the signs of
    :func:`~camtool.model.shapes.arc_axis_signs`, every arc's at once:
    :func:`_arc_runs`).

    Args:
        cuts: cuts in cutting order, paths in mm.
        start: tool position before the first rapid, mm.

    Returns:
        ``(rx, ry)``: reversals of X and of Y. On a machine that compensates
        every reversal (pic-mmh, UNAM-GMM §5.1) this is the compensation count.
    """
    # each motion's direction per axis, in order: +1/-1, 0 where the axis stands
    # still, _ARC for an arc (its first and last directions come from _arc_runs)
    xs: list[int] = []
    ys: list[int] = []
    arcs: list[Arc] = []
    eps = MOVE_EPS_MM
    here = start
    for cut in cuts:
        path = cut.path
        to = path.start
        # the rapid here → to as a line (segment_signs of Line(here, to)), then the path
        dx, dy = to[0] - here[0], to[1] - here[1]
        xs.append(0 if -eps <= dx <= eps else (1 if dx > 0 else -1))
        ys.append(0 if -eps <= dy <= eps else (1 if dy > 0 else -1))
        for seg in path.segments:  # segment_signs, inlined: ~150 000 segments a drawing
            if isinstance(seg, Line):
                dx, dy = seg.end[0] - seg.start[0], seg.end[1] - seg.start[1]
                xs.append(0 if -eps <= dx <= eps else (1 if dx > 0 else -1))
                ys.append(0 if -eps <= dy <= eps else (1 if dy > 0 else -1))
            else:
                xs.append(_ARC)
                ys.append(_ARC)
                arcs.append(seg)
        here = path.end
    start_angle = np.fromiter((a.start_angle for a in arcs), np.float64, len(arcs))
    sweep = np.fromiter((a.sweep for a in arcs), np.float64, len(arcs))
    rx = _changes(np.array(xs, np.int8), *_arc_runs(start_angle, sweep, 0.0))
    ry = _changes(np.array(ys, np.int8), *_arc_runs(start_angle, sweep, math.pi / 2))
    return rx, ry


_ARC = 2
"""The mark of an arc among :func:`count_reversals`' line directions."""


def _arc_runs(
    start_angle: npt.NDArray[np.float64], sweep: npt.NDArray[np.float64], phase: float
) -> tuple[npt.NDArray[np.int8], npt.NDArray[np.int8], int]:
    """First and last direction (+1/-1) of one axis along each arc, and its reversals inside.

    :func:`~camtool.model.shapes.arc_axis_signs` of every arc at once, the same floats
    in the same order: X for ``phase`` 0, Y for π/2; ``start_angle`` and ``sweep`` are
    the arcs' (radians, ``(N,)``). An arc has at most two turning points inside it (a
    half turn apart), so at most three pieces; the third value is how many times the
    direction changes from piece to piece, summed over the arcs.
    """
    s = np.where(sweep > 0, 1.0, -1.0)
    total = np.abs(sweep)
    inside = []  # each turning point's distance along the arc (rad), NaN where not inside
    for q in (phase, phase + math.pi):
        d = (s * (q - start_angle)) % TAU
        inside.append(np.where((d > SIGN_EPS) & (d < total - SIGN_EPS), d, np.nan))
    low, high = np.fmin(*inside), np.fmax(*inside)
    zero = np.zeros_like(total)

    def direction(b0: npt.NDArray[np.float64], b1: npt.NDArray[np.float64]) -> npt.NDArray[np.int8]:
        """The direction in the middle of the piece from ``b0`` to ``b1`` (rad along)."""
        v = -s * np.sin(start_angle + s * (b0 + b1) / 2 - phase)
        return np.where(v > 0, 1, -1).astype(np.int8)

    first = direction(zero, np.where(np.isnan(low), total, low))
    last = direction(np.where(np.isnan(high), zero, high), total)
    two = low < high  # both inside (False where either is NaN)
    middle = direction(np.where(two, low, zero), np.where(two, high, total))
    one = ~np.isnan(low) & ~two
    turns = np.count_nonzero(two & (first != middle)) + np.count_nonzero(two & (middle != last))
    return first, last, int(turns + np.count_nonzero(one & (first != last)))


def _changes(
    directions: npt.NDArray[np.int8],
    first: npt.NDArray[np.int8],
    last: npt.NDArray[np.int8],
    inside: int,
) -> int:
    """Reversals of one axis: ``directions`` of every motion (see :func:`count_reversals`).

    The arcs (marked :data:`_ARC`, in order) start with ``first``, end with ``last`` and
    reverse ``inside`` times within them; a motion of 0 (the axis still) keeps the
    direction.
    """
    arc = directions == _ARC
    heads, tails = directions.copy(), directions.copy()  # each motion's first, last
    heads[arc], tails[arc] = first, last
    moving = heads != 0
    heads, tails = heads[moving], tails[moving]
    return inside + int(np.count_nonzero(tails[:-1] != heads[1:]))


@dataclass(frozen=True)
class _Variants:
    """The allowed variants of one cut and their reversal summary.

    ``first``, ``last``: ``(V, 2)`` first and last direction of X and Y (0: the
    axis does not move); ``inner``: ``(V, 2)`` reversals within the path;
    ``start``, ``end``: ``(V, 2)`` mm.
    """

    steps: list[Step]
    first: npt.NDArray[np.int64]
    last: npt.NDArray[np.int64]
    inner: npt.NDArray[np.int64]
    start: npt.NDArray[np.float64]
    end: npt.NDArray[np.float64]


def _axis_summary(pieces: list[tuple[int, int]], k: int, closed: bool) -> tuple[int, int, int]:
    """(first, last, reversals) of one axis when the path starts at vertex ``k``."""
    m = len(pieces)
    if m == 0:
        return 0, 0, 0
    signs = [v for _, v in pieces]
    if not closed:
        changes = sum(a != b for a, b in itertools.pairwise(signs))
        return signs[0], signs[-1], changes
    cyclic = sum(signs[i] != signs[(i + 1) % m] for i in range(m))
    p = next((i for i, (g, _) in enumerate(pieces) if g >= k), 0)
    return signs[p], signs[p - 1], cyclic - (signs[p - 1] != signs[p])


def _variants(cut: Cut, flip_open: bool) -> _Variants:
    path = cut.path
    n = len(path.segments)
    ks = range(n) if path.closed and cut.may_rotate else range(1)
    directions = [False]
    if cut.may_reverse and (path.closed or flip_open):
        directions.append(True)
    fwd = _path_signs(path.segments)
    back = _path_signs(path.reversed().segments)
    steps, first, last, inner, start, end = [], [], [], [], [], []
    for rev in directions:
        pieces = back if rev else fwd
        for k in ks:
            kk = (n - k) % n if (rev and path.closed) else k
            sx, sy = (
                _axis_summary(pieces[0], kk, path.closed),
                _axis_summary(pieces[1], kk, path.closed),
            )
            steps.append((0, k, rev))
            first.append((sx[0], sy[0]))
            last.append((sx[1], sy[1]))
            inner.append((sx[2], sy[2]))
            s, e = ends(cut, k, rev)
            start.append(s)
            end.append(e)
    return _Variants(
        steps,
        np.asarray(first, dtype=np.int64),
        np.asarray(last, dtype=np.int64),
        np.asarray(inner, dtype=np.int64),
        np.asarray(start, dtype=np.float64),
        np.asarray(end, dtype=np.float64),
    )


def weights(backlash_um: tuple[float, float]) -> tuple[float, float]:
    """Per-axis weight of a reversal: the backlash, µm, or 1 each when both are 0."""
    bx, by = backlash_um
    if bx <= 0 and by <= 0:
        return 1.0, 1.0
    return max(bx, 0.0), max(by, 0.0)


def weighted(counts: tuple[int, int], w: tuple[float, float]) -> float:
    """``wx·rx + wy·ry``."""
    return w[0] * counts[0] + w[1] * counts[1]


def _enter(
    state: npt.NDArray[np.int64], here: npt.NDArray[np.float64], var: _Variants
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64]]:
    """Reversals of the rapid into and the path of each variant, from ``state`` at ``here``.

    ``state``, ``here`` broadcast against the variants' ``(V, 2)`` arrays.
    Returns ``(reversals (.., 2), state after (.., 2), rapid length (..))``.
    """
    delta = var.start - here
    rapid = np.where(np.abs(delta) > MOVE_EPS_MM, np.sign(delta).astype(np.int64), 0)
    count = ((state != 0) & (rapid != 0) & (rapid != state)).astype(np.int64)
    state = np.where(rapid != 0, rapid, state)
    count = count + ((state != 0) & (var.first != 0) & (var.first != state)) + var.inner
    state = np.where(var.last != 0, var.last, state)
    return count, state, np.hypot(delta[..., 0], delta[..., 1])


def reversal_order(
    cuts: Sequence[Cut],
    before: Sequence[Sequence[int]],
    origin: Point,
    backlash_um: tuple[float, float],
    candidates: Sequence[Sequence[Step]] = (),
    *,
    flip_open: bool = False,
) -> list[Step]:
    """A sequence with few weighted axis reversals (rapid travel breaks ties).

    Greedy from the origin on (added weighted reversals, rapid) over the variants
    of the cuts whose predecessors are cut; then, for that order, the travel order
    and each of ``candidates`` (e.g. the drawn order), start vertices and
    directions re-chosen by dynamic programming over the variants, and
    neighbouring cuts swapped where that helps (small jobs). The best of all
    by (:func:`count_reversals` weighted, rapid travel) is returned, so it is never
    worse than a candidate whose variants are allowed here (open cuts keep their
    direction unless ``flip_open``).

    Args:
        cuts: the cuts, mm.
        before: precedence (:func:`camtool.toolpath.travel.precedence`).
        origin: tool position before the first cut, mm.
        backlash_um: ``(bx, by)`` reversal weights, µm (see :func:`weights`).
        candidates: other valid sequences to improve and compare.
        flip_open: open cuts with ``may_reverse`` may be cut backwards (``--reverse-open``);
            ``False`` keeps every open cut's drawn direction.
    """
    if not cuts:
        return []
    w = weights(backlash_um)
    unit = min(v for v in w if v > 0)
    wn = (w[0] / unit, w[1] / unit)
    variants = [_variants(cut, flip_open=flip_open) for cut in cuts]
    greedy = _greedy(variants, before, origin, wn)
    options: list[Sequence[Step]] = [greedy, *candidates]
    if len(cuts) > 1:
        options.append(travel_order(cuts, before, origin, flip_open=flip_open))
    options += [_improve(variants, before, seq, origin, wn) for seq in options]

    def key(seq: Sequence[Step]) -> tuple[float, float]:
        done = [oriented(cuts[i], k, rev) for i, k, rev in seq]
        return weighted(count_reversals(done, origin), w), rapid_mm(cuts, seq, origin)

    return list(options[min(range(len(options)), key=lambda m: key(options[m]))])


def _greedy(
    variants: Sequence[_Variants],
    before: Sequence[Sequence[int]],
    origin: Point,
    w: tuple[float, float],
) -> list[Step]:
    wv = np.asarray(w, dtype=np.float64)
    every = _Variants(
        [(i, *st[1:]) for i, v in enumerate(variants) for st in v.steps],
        np.concatenate([v.first for v in variants]),
        np.concatenate([v.last for v in variants]),
        np.concatenate([v.inner for v in variants]),
        np.concatenate([v.start for v in variants]),
        np.concatenate([v.end for v in variants]),
    )
    owner = np.asarray([st[0] for st in every.steps], dtype=np.int64)
    # a cut's least internal cost is spent whatever its turn: rank by what is added to it
    least = np.full(len(variants), np.inf)
    np.minimum.at(least, owner, every.inner @ wv)
    waiting = np.asarray([len(b) for b in before])
    after: list[list[int]] = [[] for _ in variants]
    for a, bs in enumerate(before):
        for b in bs:
            after[b].append(a)
    active = waiting[owner] == 0
    state = np.zeros(2, dtype=np.int64)
    here = np.asarray(origin, dtype=np.float64)
    out: list[Step] = []
    for _ in range(len(variants)):
        idx = np.flatnonzero(active)
        sub = _Variants(
            [],
            every.first[idx],
            every.last[idx],
            every.inner[idx],
            every.start[idx],
            every.end[idx],
        )
        count, after_state, rapid = _enter(state, here, sub)
        key = (count @ wv - least[owner[idx]]) * _TRAVEL_PER_REVERSAL_MM
        m = int(np.argmin(key + rapid))  # first minimum: lowest cut, then variant
        p = int(idx[m])
        i = int(owner[p])
        state, here = after_state[m], every.end[p]
        out.append(every.steps[p])
        active[owner == i] = False
        for a in after[i]:
            waiting[a] -= 1
            if waiting[a] == 0:
                active[owner == a] = True
    return out


def _improve(
    variants: Sequence[_Variants],
    before: Sequence[Sequence[int]],
    seq: Sequence[Step],
    origin: Point,
    w: tuple[float, float],
) -> list[Step]:
    """Swap neighbours where precedence allows and the best variants then cost less.

    Each try re-runs :func:`_dp`, so this runs only for up to :data:`IMPROVE_MAX_CUTS`
    cuts and :data:`IMPROVE_PASSES` passes.
    """
    order = [c for c, _, _ in seq]
    best, cost = _dp(variants, order, origin, w)
    if len(order) > IMPROVE_MAX_CUTS:
        return best
    for _ in range(IMPROVE_PASSES):
        better = False
        for p in range(len(order) - 1):
            if order[p] in before[order[p + 1]]:
                continue
            trial = [*order[:p], order[p + 1], order[p], *order[p + 2 :]]
            steps, trial_cost = _dp(variants, trial, origin, w)
            if trial_cost < cost - 1e-9:
                order, best, cost, better = trial, steps, trial_cost, True
        if not better:
            break
    return best


def _dp(
    variants: Sequence[_Variants], order: Sequence[int], origin: Point, w: tuple[float, float]
) -> tuple[list[Step], float]:
    """Variants for a fixed order by dynamic programming on (weighted reversals, rapid).

    The state is the variant of the last cut; its exit direction is the one along
    the best path to it (exact whenever the rapid and path into each cut move
    both axes, as they do for any closed cut).
    """
    wv = np.asarray(w, dtype=np.float64)
    var = variants[order[0]]
    count, state, rapid = _enter(np.zeros(2, dtype=np.int64), np.asarray(origin), var)
    cost = (count @ wv) * _TRAVEL_PER_REVERSAL_MM + rapid
    back: list[npt.NDArray[np.int64]] = []
    for i in order[1:]:
        prev, var = var, variants[i]
        count, new_state, rapid = _enter(state[:, None, :], prev.end[:, None, :], var)
        total = cost[:, None] + (count @ wv) * _TRAVEL_PER_REVERSAL_MM + rapid  # (U, V)
        pick = np.argmin(total, axis=0)
        cols = np.arange(len(var.steps))
        cost = total[pick, cols]
        state = new_state[pick, cols]
        back.append(pick)
    m = int(np.argmin(cost))
    chosen = [m]
    for pick in reversed(back):
        m = int(pick[m])
        chosen.append(m)
    chosen.reverse()
    steps = [(i, *variants[i].steps[m][1:]) for i, m in zip(order, chosen, strict=True)]
    return steps, float(cost.min())
