"""Along-path shortfall: how far the drawn path is from the trace, sampled along each move.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt

from camtool.model.program import Program, segment_of
from camtool.model.shapes import Arc, Point
from camtool.verify import contour_measures, dda, deviations, nearest_exact, nearest_search

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class AlongPath:
    """The programmed path seen from the trace: what the tool never reached, where moves ended.

    :func:`deviation` measures how far the tool strays *from* the path; a move
    that stops short (an uncompensated backlash on a return leg) strays nowhere
    and is invisible to it. Here the path is sampled finely and each sample's
    distance to the trace of its own contour is taken (the directed Hausdorff
    distance from path to trace), and the carriage is compared with the
    programmed end of every cutting move and every contour.

    Attributes:
        shortfall_um: largest distance of the sampled cutting path from the
            trace of its contour, µm (0 when nothing was cut).
        shortfall_at_mm: the path point where it occurs, mm.
        shortfall_block: index of the move of that point (-1 when none).
        block_end_um: largest distance of the carriage, after a cutting move's
            last row, from the move's programmed end, µm.
        block_end_at_mm: the programmed end where it occurs, mm.
        block_end_block: index of that move (-1 when none).
        contour_end_um: ``(C,)`` the same at the end of each contour, µm.
        samples: path points measured.
    """

    shortfall_um: float
    shortfall_at_mm: Point
    shortfall_block: int
    block_end_um: float
    block_end_at_mm: Point
    block_end_block: int
    contour_end_um: tuple[float, ...]
    samples: int


ALONG_SPACING_MM = 0.001
"""Largest spacing of the programmed path's samples for :func:`along_path`, mm."""


ALONG_MAX_SAMPLES = 400_000
"""Most path samples :func:`along_path` measures (the spacing grows beyond it)."""


ALONG_MAX_TRACE = 400_000
"""Most trace points per contour :func:`along_path` keeps (every k-th beyond it)."""


ALONG_RESOLUTION_MM = 0.0005
"""Spacing the trace is thinned to for :func:`along_path`, mm: a thinned-out point lies
within about this of the polyline kept, so it bounds the error of the shortfall."""


def along_path(
    points: FloatArray, block_start: IntArray, start_mm: Point, program: Program
) -> AlongPath:
    """The path-to-trace measures of a trace (see :class:`AlongPath`).

    Args:
        points: ``(N, 2)`` float64 trace, mm.
        block_start: ``(B + 1,)`` offsets of each move's points in ``points``.
        start_mm: the carriage position before the first point.
        program: the program the trace executed.

    The path is sampled at most :data:`ALONG_SPACING_MM` apart (wider when it
    would take more than :data:`ALONG_MAX_SAMPLES`), every move's ends
    included; each contour's trace is a polyline through its points (the point
    before the contour included), thinned to points about
    :data:`ALONG_RESOLUTION_MM` apart (never more than :data:`ALONG_MAX_TRACE`).

    Only the samples that can hold the largest shortfall are measured exactly
    (:class:`_Bounded`): every sample's distance is first bounded by the trace
    segments at its place, and the contours are measured from the likeliest, each
    one's samples only where their bound reaches the largest found so far. The
    figures are those of measuring every sample, contours in order (the first of
    equal ones named), bit for bit; a part's 400 000 samples took 0.85 s that way and
    take about 0.15 s.
    """
    starts = deviations.move_starts(program)
    runs = contour_measures.contour_runs(program)
    total = sum(
        segment_of(starts[i], program.moves[i]).length for a, b in runs for i in range(a, b + 1)
    )
    spacing = max(ALONG_SPACING_MM, total / ALONG_MAX_SAMPLES)
    start = np.asarray(start_mm, dtype=np.float64).reshape(1, 2)
    ends: list[float] = []
    end_worst = (0.0, (0.0, 0.0), -1)
    count = 0
    reach: list[tuple[float, int]] = []  # (-largest bound, contour) of contours with samples
    nominal = deviations.nominal_arrays(program)
    floor = 0.0  # the largest shortfall measured so far, mm
    found: list[tuple[int, float, Point, int]] = []  # (contour, shortfall, at, move)
    bounds: dict[int, FloatArray] = {}

    def measured(c: int, far: float, k: int, samples: FloatArray, owner: IntArray) -> None:
        nonlocal floor
        floor = max(floor, far)
        found.append((c, far, (float(samples[k, 0]), float(samples[k, 1])), int(owner[k])))

    def contour(c: int) -> tuple[FloatArray, IntArray, FloatArray, FloatArray, IntArray]:
        first, last = runs[c]
        lo, hi = int(block_start[first]), int(block_start[last + 1])
        before = points[lo - 1 : lo] if lo > 0 else start
        run = np.vstack([before, points[lo:hi]])
        samples, owner, t = _sample_moves(program, starts, first, last, spacing)
        return samples, owner, t, run, block_start[first + 1 : last + 2] - lo

    def bounded(
        c: int, samples: FloatArray, owner: IntArray, t: FloatArray, run: FloatArray, keep: IntArray
    ) -> _Bounded:
        first, last = runs[c]
        part = {k: v[first : last + 1] for k, v in nominal.items()}
        made = _Bounded.of_run(samples, owner - first, t, run, keep, part, bounds.get(c))
        bounds[c] = made.reach
        return made

    for c, (first, last) in enumerate(runs):
        for b in range(first, last + 1):
            here = _carriage_after(points, block_start, start, b)
            gap = math.dist(here, starts[b + 1]) * 1000.0
            if gap > end_worst[0]:
                end_worst = (gap, starts[b + 1], b)
        ends.append(math.dist(_carriage_after(points, block_start, start, last), starts[last + 1]))
        samples, owner, t, run, keep = contour(c)
        count += len(samples)
        if len(samples) == 0:
            continue
        if len(samples) < SHORTFALL_BOUND_FROM:  # a small contour: measured at once
            measured(c, *_farthest_from_trace(samples, _thinned(run, keep)), samples, owner)
        else:
            reach.append((-bounded(c, samples, owner, t, run, keep).reach_max, c))
    # the long contours that can hold the largest shortfall, the likeliest first: the
    # others are left out once one measured is larger than every bound of theirs
    for _, c in sorted(reach):
        samples, owner, t, run, keep = contour(c)
        got = bounded(c, samples, owner, t, run, keep).farthest(floor)
        if got is not None:
            measured(c, *got, samples, owner)
    worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
    for _, far, at, block in sorted(found):  # in contour order, as one pass over them
        if far * 1000.0 > worst[0]:
            worst = (far * 1000.0, at, block)
    return AlongPath(
        shortfall_um=worst[0],
        shortfall_at_mm=worst[1],
        shortfall_block=int(worst[2]),
        block_end_um=end_worst[0],
        block_end_at_mm=(float(end_worst[1][0]), float(end_worst[1][1])),
        block_end_block=int(end_worst[2]),
        contour_end_um=tuple(e * 1000.0 for e in ends),
        samples=count,
    )


def _farthest_from_trace(
    samples: FloatArray, trace: FloatArray, ends: nearest_search._LazyTree | None = None
) -> tuple[float, int]:
    """Largest distance of a path sample to the polyline ``trace`` and the first sample at it.

    Distances in mm, to the one point when ``trace`` has one (:func:`farthest_nearest`);
    ``ends``: the k-d tree of the segment ends, shared by the batches of one trace.
    """
    return nearest_search.farthest_nearest(samples, *_segments(trace), ends=ends)


def _segments(trace: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The segments ``a → b`` of the polyline ``trace`` (views): one of no length for one point."""
    if len(trace) == 1:
        return trace, trace
    return trace[:-1], trace[1:]


SHORTFALL_BOUND_FROM = 2048
"""Path samples from which a contour's shortfall is bounded before it is measured
(:class:`_Bounded`); a smaller contour is measured at once, all its samples. The bounds
cost about 1 ms a contour whatever its size, and save nothing where every contour's
shortfall ties (identical pockets): 1 000 such squares of 400 samples took 1.36 s bounded
against 0.41 s measured, 200 of 2 000 samples 0.62 s against 0.31 s; the benchmark part
(36 contours, ~11 000 samples each) 0.25 s bounded against 0.74 s. Only the time depends
on it."""


SHORTFALL_WINDOW = 4
"""Trace segments on each side of a path sample's place along the trace that
:class:`_Bounded` measures it against (its bound; only the time depends on it)."""


SHORTFALL_ROUND = 1024
"""Samples of largest bound :meth:`_Bounded.farthest` measures first (only the time
depends on it: the likeliest samples measured first leave most others out)."""


SHORTFALL_CHUNK = 1 << 15
"""Path samples or trace points :class:`_Bounded` works on at once (memory)."""


class _Places:
    """A contour's thinned trace, each point with its place along the contour's moves.

    The place of a trace point of move ``j`` is ``j + f``, ``f`` the fraction of the
    move's nominal segment at the foot of the point (lines: its projection; arcs: its
    angle; 0 to 1), made non-decreasing along the trace; a path sample's is ``j + t``
    (:func:`_fractions`). Where the backlash holds the carriage at a move's start, or
    the rows crowd, the place still finds the rows beside a sample.

    The trace is given as its segments ``a[i] → b[i]`` (``b[i] == a[i + 1]``; one
    segment of no length for a trace of one point): the streamed verify holds them as
    views of the k-d tree's array of segment ends, not the trace beside it (6 MB).

    Args:
        a: ``(S, 2)`` segment starts, mm (the trace less its last point).
        b: ``(S, 2)`` segment ends, mm (the trace less its first point).
        spans: ``(J,)`` each move's first and ``(J,)`` last index in the trace
            (:func:`_move_spans`).
        nominal: the contour's moves' nominal geometry (:func:`nominal_arrays` of the
            program, rows ``first..last``).

    Attributes:
        a, b: the segments.
        index: ``(K,)`` the trace points that moved (each unlike the one before; int32
            below 2**31 points): the same polyline without its segments of no length.
        keys: ``(K,)`` their places, non-decreasing.
    """

    def __init__(
        self,
        a: FloatArray,
        b: FloatArray,
        spans: tuple[IntArray, IntArray],
        nominal: dict[str, FloatArray],
    ) -> None:
        self.a, self.b = a, b
        first, last = spans
        # a row that did not move the carriage adds a segment of no length: the points
        # that moved make the same polyline, and the window then spans real segments
        points = len(a) + 1 if len(a) > 1 or np.any(a != b) else 1
        moved = np.ones(points, dtype=bool)
        for lo in range(0, points - 1, SHORTFALL_CHUNK):
            part = slice(lo, lo + SHORTFALL_CHUNK)
            sa, sb = a[part], b[part]
            moved[lo + 1 : lo + 1 + len(sa)] = (sa[:, 0] != sb[:, 0]) | (sa[:, 1] != sb[:, 1])
        self.index = np.flatnonzero(moved).astype(np.int32 if points < 2**31 else np.int64)
        del moved
        keys = np.empty(len(self.index), dtype=np.float64)
        for lo in range(0, len(keys), SHORTFALL_CHUNK):
            index = self.index[lo : lo + SHORTFALL_CHUNK].astype(np.int64)
            move = np.minimum(np.searchsorted(last, index), len(last) - 1)
            rows = np.maximum(last[move] - first[move], 1)
            by_row = (index - first[move]) / rows
            keys[lo : lo + len(index)] = move + _foot_fraction(
                self.point(index), move, nominal, by_row
            )
        self.keys = np.maximum.accumulate(keys, out=keys) if len(keys) else keys

    @cached_property
    def magnitude(self) -> float:
        """The largest coordinate magnitude of the segments (of every batch's samples' bound)."""
        return max(_largest_magnitude(self.a), _largest_magnitude(self.b))

    def point(self, index: IntArray) -> FloatArray:
        """The trace points ``index`` ``(N, 2)``: ``a[i]``, or ``b[i - 1]`` for the last."""
        out = self.b[np.maximum(index - 1, 0)]
        out[index == 0] = self.a[0]
        return out


def _foot_fraction(
    points: FloatArray, move: IntArray, nominal: dict[str, FloatArray], by_row: FloatArray
) -> FloatArray:
    """``(N,)`` where along its move's nominal segment each point's foot lies, 0 to 1.

    ``by_row``: each point's place among its move's rows, 0 to 1. An arc's angle turns
    over at its start: a point of a full circle just before its start (or just past its
    end) is taken at the end the rows put it at, not a turn away.
    """
    x0, y0 = nominal["x0"][move], nominal["y0"][move]
    dx, dy = nominal["x1"][move] - x0, nominal["y1"][move] - y0
    length2 = dx * dx + dy * dy
    dot = (points[:, 0] - x0) * dx + (points[:, 1] - y0) * dy
    out = np.divide(dot, length2, out=np.zeros_like(length2), where=length2 > 0)
    arc = nominal["kind"][move] == 1
    if arc.any():
        m = move[arc]
        sweep = nominal["sweep"][m]
        turn = np.arctan2(points[arc, 1] - nominal["cy"][m], points[arc, 0] - nominal["cx"][m])
        turn = np.mod(np.where(sweep < 0, -1.0, 1.0) * (turn - nominal["a0"][m]), 2 * math.pi)
        size = np.abs(sweep)
        past = turn > size  # beyond the arc: at the nearer of its ends
        turn = np.where(past & (turn > (size + 2 * math.pi) / 2), 0.0, turn)
        f = np.clip(np.divide(turn, size, out=np.zeros_like(size), where=size > 0), 0.0, 1.0)
        rows = by_row[arc]
        out[arc] = np.where(f - rows > 0.5, 0.0, np.where(rows - f > 0.5, 1.0, f))
    return np.clip(out, 0.0, 1.0)


class _Bounded:
    """Path samples of one contour, each with a cheap upper bound of its shortfall.

    The shortfall of a sample is its distance to the nearest segment of the contour's
    thinned trace (:func:`_farthest_from_trace`). The trace follows the path, so the
    trace segments at the sample's place (:class:`_Places`) are near it: the least
    distance to the :data:`SHORTFALL_WINDOW` segments on each side bounds its
    shortfall from above, in a few vector operations. :meth:`farthest` then measures,
    as :func:`_farthest_from_trace` measures them all, only the samples whose bound can
    reach the largest shortfall, and gives the same two numbers.

    A sample left out has a bound ``u`` with
    ``(u + NEAREST_TOLERANCE_MM)(1 + 1e-9) + slack`` below a shortfall known to be
    reached (a sample's own, or ``floor``). That is strictly below what
    :func:`nearest_distances` can give it: it gives the true distance ``d <= u``, or,
    settled by the vertex bound, at most :data:`NEAREST_TOLERANCE_MM` more; the
    ``slack`` (1e-12 mm and 64 ulps of the largest coordinate, as :func:`_reaching`)
    covers two formulas' rounding of one distance. So it can be neither the largest nor
    tie with it, and the first largest of the rest is the first largest of all.

    Args:
        samples: ``(N, 2)`` path samples, mm (:func:`_sample_moves`).
        move: ``(N,)`` each one's move, counted from the contour's first (0).
        t: ``(N,)`` how far along its move each lies, 0 to 1 (:func:`_fractions`).
        places: the contour's thinned trace (its segments) and its places.
        ends: the k-d tree of the trace's segment ends (:meth:`_Contour.ends`), shared
            by the batches of one trace; built when needed otherwise.
        reach: the bounds an earlier one of the same samples and trace made
            (:attr:`reach`), instead of making them again.
    """

    def __init__(
        self,
        samples: FloatArray,
        move: IntArray,
        t: FloatArray,
        places: _Places,
        ends: nearest_search._LazyTree | None = None,
        reach: FloatArray | None = None,
    ) -> None:
        self.samples, self.places, self.ends = samples, places, ends
        self.slack = 0.0
        if len(samples) == 0:
            self.reach = np.zeros(0)
        else:
            scale = max(_largest_magnitude(samples), places.magnitude)
            self.slack = 1e-12 + 64.0 * float(np.spacing(scale))
            if reach is None:
                upper = _window_bounds(samples, move + t, places)
                reach = (upper + nearest_exact.NEAREST_TOLERANCE_MM) * (1.0 + 1e-9) + self.slack
            self.reach = reach
        self.reach_max = float(np.max(self.reach)) if len(samples) else -math.inf

    @classmethod
    def of_run(
        cls,
        samples: FloatArray,
        move: IntArray,
        t: FloatArray,
        run: FloatArray,
        keep: IntArray,
        nominal: dict[str, FloatArray],
        reach: FloatArray | None = None,
    ) -> _Bounded:
        """The samples against a contour's whole run (thinned here, :func:`_thinned`).

        ``run``: the point before the contour, then its rows; ``keep``: each move's last
        row in ``run``; ``nominal``: the contour's moves' (:class:`_Places`); ``reach``:
        as for the class.
        """
        spans = _move_spans(len(run), _run_every(run), keep)
        a, b = _segments(_thinned(run, keep))
        return cls(samples, move, t, _Places(a, b, spans, nominal), reach=reach)

    def farthest(self, floor: float = 0.0) -> tuple[float, int] | None:
        """:func:`_farthest_from_trace` of the samples, or ``None`` when none can reach ``floor``.

        ``floor``: a shortfall already found, mm. A sample whose shortfall cannot reach
        it is not measured; ``None`` says that none can (their largest is below it).
        The answer may still be below ``floor`` (then the largest of those that may not).

        The samples are measured in two rounds: the :data:`SHORTFALL_ROUND` of largest
        bound, then the others whose bound reaches the largest shortfall of the first.
        Each sample's distance is its own (:func:`nearest_distances`) and each round
        gives its largest and the first sample at it, so the larger of the two and the
        first sample at it are those of measuring them all at once.
        """
        if len(self.samples) == 0:
            return None
        reach = self.reach
        if np.isnan(reach).any():  # never from finite samples: the sorted form's order
            return self._farthest_sorted(floor)
        if float(np.max(reach)) < floor:
            return None
        a, b = self.places.a, self.places.b
        ends = self._ends()
        best: tuple[float, int] | None = None
        known = floor
        taken = _largest(reach, SHORTFALL_ROUND)
        for mask in (taken, None):  # the likeliest first, then the others that may reach
            if mask is None:
                mask = ~taken & (reach >= known)
            else:
                mask &= reach >= known
            index = np.flatnonzero(mask)  # in sample order: the first of equal ones
            if len(index) == 0:
                break
            far, k = nearest_search.farthest_nearest(self.samples[index], a, b, ends=ends)
            best = _better(best, far, int(index[k]))
            known = max(known, far)
        return best

    def _ends(self) -> nearest_search._LazyTree:
        """The search trees of the trace's segment ends: the shared ones, else new ones."""
        if self.ends is not None:
            return self.ends
        return nearest_search._LazyTree(nearest_search._end_points(self.places.a, self.places.b))

    def _farthest_sorted(self, floor: float) -> tuple[float, int] | None:
        """:meth:`farthest` by one stable sort of the bounds (the reference; NaN bounds last)."""
        order = np.argsort(-self.reach, kind="stable")  # the likeliest first
        reach = self.reach[order]
        if reach[0] < floor:
            return None
        a, b = self.places.a, self.places.b
        ends = self._ends()
        best: tuple[float, int] | None = None
        known, at, size = floor, 0, SHORTFALL_ROUND
        while at < len(order):
            stop = min(len(order), at + size)  # of those whose bound reaches the largest known
            stop = min(stop, at + int(np.searchsorted(-reach[at:stop], -known, "right")))
            if stop <= at:
                break
            index = np.sort(order[at:stop])  # in sample order: the first of equal ones
            far, k = nearest_search.farthest_nearest(self.samples[index], a, b, ends=ends)
            best = _better(best, far, int(index[k]))
            known = max(known, far)
            at, size = stop, len(order)
        return best


def _better(best: tuple[float, int] | None, far: float, at: int) -> tuple[float, int]:
    """The larger of ``best`` and ``(far, at)``; of equal distances, the first sample's."""
    if best is None or far > best[0] or (far == best[0] and at < best[1]):
        return far, at
    return best


def _largest(values: FloatArray, count: int) -> npt.NDArray[np.bool_]:
    """``(N,)`` mask of the first ``count`` of ``values`` (no NaN) in a stable descending sort.

    The ``count`` largest; of those equal to the smallest taken, the first in order (as
    ``np.argsort(-values, kind="stable")[:count]``), by one partition instead of a sort.
    """
    n = len(values)
    if count >= n:
        return np.ones(n, dtype=bool)
    edge = float(np.partition(values, n - count)[n - count])  # the count-th largest
    mask = values > edge
    ties = np.flatnonzero(values == edge)[: count - int(np.count_nonzero(mask))]
    mask[ties] = True
    return mask


def _largest_magnitude(values: FloatArray) -> float:
    """``max(|values|)`` without an array of the magnitudes (a trace's would be ~6 MB)."""
    return max(abs(float(np.max(values))), abs(float(np.min(values))))


def _segment_formula(
    apx: FloatArray, apy: FloatArray, abx: FloatArray, aby: FloatArray
) -> FloatArray:
    """Distance of ``p`` to the segment ``a → b`` from the columns of ``p - a`` and ``b - a``."""
    length2 = abx * abx + aby * aby
    dot = apx * abx + apy * aby
    t = np.divide(dot, length2, out=np.zeros_like(length2), where=length2 > 0)
    np.clip(t, 0.0, 1.0, out=t)
    ox, oy = apx - t * abx, apy - t * aby
    return np.sqrt(ox * ox + oy * oy)


def _window_bounds(samples: FloatArray, place: FloatArray, places: _Places) -> FloatArray:
    """``(N,)`` each sample's least distance to the trace segments around its ``place``.

    The segments up to :data:`SHORTFALL_WINDOW` on each side of the trace points
    whose places (:class:`_Places`) enclose the sample's. Each is a distance to one
    segment of the trace, so no less than the distance to them all. Where the step
    kernels are loaded (a streamed verify), :func:`camtool.accel.kernels.window_bounds`
    takes the same floats in one pass.
    """
    a, b, moved = places.a, places.b, places.index
    m = len(moved) - 1
    if m == 0:  # the carriage never moved: the one point
        return np.hypot(samples[:, 0] - a[0, 0], samples[:, 1] - a[0, 1])
    out = np.empty(len(samples), dtype=np.float64)
    kernels = dda.KERNELS.loaded()
    for lo in range(0, len(samples), SHORTFALL_CHUNK):
        part = slice(lo, lo + SHORTFALL_CHUNK)
        centre = np.searchsorted(places.keys, place[part]) - 1
        if kernels is not None:
            kernels.window_bounds(samples[part], centre, a, b, moved, SHORTFALL_WINDOW, out[part])
            continue
        px, py = samples[part, 0], samples[part, 1]
        best = np.full(len(px), np.inf)
        for off in range(-SHORTFALL_WINDOW, SHORTFALL_WINDOW + 1):
            k = np.clip(centre + off, 0, m - 1)
            i, j = moved[k], moved[k + 1] - 1  # from point i (a[i]) to point j + 1 (b[j])
            ax, ay = a[i, 0], a[i, 1]
            d = _segment_formula(px - ax, py - ay, b[j, 0] - ax, b[j, 1] - ay)
            np.minimum(best, d, out=best)
        out[part] = best
    return out


def _move_spans(n: int, every: int, keep: IntArray) -> tuple[IntArray, IntArray]:
    """The first and last index of each move in a contour's thinned trace (:func:`_thinned`).

    Args:
        n: points of the run (the point before the contour, then its rows).
        every: the run's thinning step (:func:`_run_every`; 1: nothing left out).
        keep: ``(J,)`` each move's last row in the run, which :func:`_thinned` keeps.

    Returns:
        ``(J,)`` first and ``(J,)`` last indices: move ``j`` runs from the last row of
        move ``j - 1`` (the point before, 0, for the first) to its own. A kept row's
        index counts the kept rows before it: the multiples of ``every`` and the other
        kept rows (``keep`` and the run's last).
    """
    rows = np.clip(np.asarray(keep, dtype=np.int64), 0, max(n - 1, 0))
    if every == 1:
        at = rows
    else:
        inside = np.asarray(keep, dtype=np.int64)
        kept = np.unique(np.append(inside[(inside >= 0) & (inside < n)], n - 1))
        others = kept[kept % every != 0]
        at = -(-rows // every) + np.searchsorted(others, rows)
    return np.concatenate(([0], at[:-1])).astype(np.int64), at.astype(np.int64)


def _thinned(run: FloatArray, keep: IntArray) -> FloatArray:
    """``run``'s every k-th point, its last and the rows ``keep``, about 0.5 µm apart.

    The spacing is :data:`ALONG_RESOLUTION_MM`, never more than :data:`ALONG_MAX_TRACE`
    points (plus ``keep``). Keeping every move's last row keeps the corners, which a
    thinned polyline would cut.
    """
    every = _run_every(run)
    if every == 1:
        return run
    mask = np.zeros(len(run), dtype=bool)
    mask[::every] = True
    mask[-1] = True
    mask[keep[(keep >= 0) & (keep < len(run))]] = True
    return run[mask]


THIN_HEAD = 2000
"""Points at the start of a contour's trace whose median spacing :func:`_thinned` reads."""


def _run_every(run: FloatArray) -> int:
    """Every how many points :func:`_thinned` keeps of ``run`` (1: all of them)."""
    if len(run) < 3:
        return 1
    return _thin_every(run[: min(len(run), THIN_HEAD)], len(run))


def _thin_every(head: FloatArray, n: int) -> int:
    """Every how many points :func:`_thinned` keeps of a trace of ``n`` (>= 3) points.

    ``head`` is the trace's first ``min(n, THIN_HEAD)`` points: their median spacing
    against :data:`ALONG_RESOLUTION_MM`, and at most :data:`ALONG_MAX_TRACE` points.
    """
    step = _median_step(head)
    every = max(1, int(ALONG_RESOLUTION_MM / step) if step > 0 else 1)
    return max(every, -(-n // ALONG_MAX_TRACE))


def _median_step(head: FloatArray) -> float:
    """The median distance between consecutive points of ``head`` ``(n, 2)``, mm (0 if n < 2)."""
    steps = np.diff(head, axis=0)
    return float(np.median(np.hypot(steps[:, 0], steps[:, 1]))) if len(steps) else 0.0


def _carriage_after(
    points: FloatArray, block_start: IntArray, start: FloatArray, block: int
) -> FloatArray:
    """Carriage position after move ``block``'s last row (or before it, when it has none)."""
    row = int(block_start[block + 1]) - 1
    return points[row] if row >= 0 else start[0]


def _sample_moves(
    program: Program, starts: Sequence[Point], first: int, last: int, spacing: float
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Points along moves ``first..last`` at most ``spacing`` apart, ends included.

    Returns:
        ``(N, 2)`` points, mm; ``(N,)`` the move of each; ``(N,)`` how far along its
        move each lies (0 at its start, 1 at its end: :func:`_fractions`).
    """
    chunks = [_sample_move(program, starts, b, spacing) for b in range(first, last + 1)]
    if not chunks:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0)
    owners = [np.full(len(pts), b, dtype=np.int64) for b, pts in enumerate(chunks, first)]
    fractions = [_fractions(len(pts)) for pts in chunks]
    return np.vstack(chunks), np.concatenate(owners), np.concatenate(fractions)


def _fractions(count: int) -> FloatArray:
    """``(count,)``: how far along its move each of :func:`_sample_move`'s points lies, 0 to 1."""
    return np.arange(count, dtype=np.float64) / max(1, count - 1)


def _sample_move(program: Program, starts: Sequence[Point], b: int, spacing: float) -> FloatArray:
    """``(n + 1, 2)`` points along move ``b`` at most ``spacing`` apart, its ends included."""
    seg = segment_of(starts[b], program.moves[b])
    n = max(1, math.ceil(seg.length / spacing))
    t = np.arange(n + 1, dtype=np.float64) / n
    if isinstance(seg, Arc):
        r, c = seg.radius, seg.centre
        angle = math.atan2(seg.start[1] - c[1], seg.start[0] - c[0]) + seg.sweep * t
        pts = np.column_stack((c[0] + r * np.cos(angle), c[1] + r * np.sin(angle)))
        pts[-1] = seg.end
        return pts
    (x0, y0), (x1, y1) = seg.start, seg.end
    return np.column_stack((x0 + (x1 - x0) * t, y0 + (y1 - y0) * t))


def _sample_batches(
    program: Program, starts: Sequence[Point], first: int, last: int, spacing: float, size: int
) -> Iterator[tuple[FloatArray, IntArray, FloatArray]]:
    """:func:`_sample_moves` in consecutive pieces of ``size`` points (the last shorter).

    The pieces are exactly ``samples[i : i + size]`` (and owners and fractions) of the
    whole arrays, built move by move: never more than a piece and one move's points are
    held.
    """
    held: list[FloatArray] = []
    owners: list[IntArray] = []
    along: list[FloatArray] = []
    count = 0
    for b in range(first, last + 1):
        pts = _sample_move(program, starts, b, spacing)
        held.append(pts)
        owners.append(np.full(len(pts), b, dtype=np.int64))
        along.append(_fractions(len(pts)))
        count += len(pts)
        while count >= size:
            samples, owner, t = np.vstack(held), np.concatenate(owners), np.concatenate(along)
            yield samples[:size], owner[:size], t[:size]
            held, owners, along = [samples[size:]], [owner[size:]], [t[size:]]
            count -= size
    if count:
        yield np.vstack(held), np.concatenate(owners), np.concatenate(along)


STREAM_SAMPLES = 100_000
"""Path samples :class:`TraceStream` measures against a contour's trace at once: the
distance of each is found alone (:func:`nearest_distances`), so the pieces give the same
distances as one call, with about 30 MB less held on the bench program."""


ZOOM_ROWS = 256
"""Rows on each side of the worst deviation a streamed trace keeps for the picture's zoom
(within the worst point's chunk): every k-th row alone leaves the zoom on it empty."""


PICTURE_ROWS = 100_000
"""About how many rows of a streamed trace :class:`TraceStream` keeps for the picture
(on the 10 mm wide 13 M-row benchmark program, a kept row about every 20 µm of path,
a few pixels of a preview; the worst point is always kept)."""
