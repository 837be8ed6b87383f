"""The measures of a trace as it is simulated: deviation, contours and shortfall, streamed.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.model.program import Program, segment_of
from camtool.model.shapes import Point
from camtool.verify import contour_measures, deviations, nearest_search, path_shortfall
from camtool.verify.circlefit import CircleFit

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

TREE_BESIDE_FROM = 100_000
"""Segment ends of the last contour's thinned trace from which its k-d tree is built in a
thread while its path is sampled and bounded (:meth:`nearest_search._LazyTree.build_beside`):
the simulation is over, so the other core is idle. The search then takes the k-d tree's
path, as for a tree built before (``_LazyTree.built``); both paths give the same
distances, only the time depends on it."""


@dataclass(frozen=True, eq=False)
class StreamedMeasures:
    """What :class:`TraceStream` measured on a trace seen chunk by chunk.

    Attributes:
        deviation: as :func:`deviation` of the whole trace; ``rms_um`` is the square
            root of the exact (correctly rounded) mean of the squares (see
            :class:`TraceStream`), which may differ in the last bits from numpy's
            pairwise mean of the whole array.
        along: as :func:`along_path` of the whole trace (the same figures).
        contours: as :func:`measure_contours` of the whole trace (the same figures).
        picture_rows: ``(K,) int64`` rows kept for the picture (every k-th row of the
            trace, k = ceil(rows / :data:`PICTURE_ROWS`), and the worst deviation's).
        picture_mm: ``(K, 2) float64`` the carriage at those rows, mm.
        picture_blocks: ``(K,) int64`` their move indices.
        picture_steps: ``(K, 2) int8`` their motor steps.
        picture_compensation: ``(K,) bool`` whether each is a compensation row.
        compensation_steps: compensation steps ``(x, y)`` of the whole trace.
    """

    deviation: deviations.Deviation
    along: path_shortfall.AlongPath
    contours: tuple[contour_measures.ContourMeasure, ...]
    picture_rows: IntArray
    picture_mm: FloatArray
    picture_blocks: IntArray
    picture_steps: npt.NDArray[np.int8]
    picture_compensation: npt.NDArray[np.bool_]
    compensation_steps: tuple[int, int]


class _Contour:
    """One contour's state while :class:`TraceStream` reads its rows."""

    def __init__(self, number: int, first: int, last: int, block_start: IntArray) -> None:
        self.number, self.first, self.last = number, first, last
        self.lo, self.hi = int(block_start[first]), int(block_start[last + 1])
        self.n = self.hi - self.lo + 1  # the run: the point before, then the rows
        self.keep = block_start[first + 1 : last + 2] - self.lo  # each move's last row
        self.top = [-math.inf, -math.inf]
        self.low = [math.inf, math.inf]
        self.before: FloatArray = np.zeros(2)
        self.last_point: FloatArray = np.zeros(2)
        self.every = 1 if self.n < 3 else 0  # 0: not known before the head is read
        self.pending: list[tuple[int, FloatArray]] = []
        self.pending_count = 0
        self.kept: list[FloatArray] = []
        self.circle: CircleFit | None = None  # a circle's fit, fed its run as it comes

    def add(self, j0: int, points: FloatArray) -> None:
        """The run's points ``j0, j0 + 1, ...`` (run index 0 is the point before), in order."""
        if self.circle is not None:
            self.circle.add(points)
        if self.every == 0:
            self.pending.append((j0, points))
            self.pending_count += len(points)
            if self.pending_count >= min(self.n, path_shortfall.THIN_HEAD):
                self._head_read()
            return
        self._select(j0, points)

    def _head_read(self) -> None:
        head = np.vstack([p for _, p in self.pending])[: min(self.n, path_shortfall.THIN_HEAD)]
        self.every = path_shortfall._thin_every(head, self.n)
        for j0, points in self.pending:
            self._select(j0, points)
        self.pending = []

    def _select(self, j0: int, points: FloatArray) -> None:
        """Keep what :func:`_thinned` keeps of the run's points ``j0 ...``."""
        if self.every == 1:
            self.kept.append(points.copy())
            return
        j1 = j0 + len(points)
        every = self.every
        first = -(-j0 // every) * every
        wanted = np.arange(first, j1, every, dtype=np.int64)
        a, b = np.searchsorted(self.keep, [j0, j1])
        extra = self.keep[a:b]
        if j0 <= self.n - 1 < j1:
            extra = np.append(extra, self.n - 1)
        if len(extra):  # np.union1d's sorted distinct values, without its hash table
            merged = np.concatenate([wanted, extra])
            merged.sort()
            wanted = merged[np.concatenate(([True], merged[1:] != merged[:-1]))]
        self.kept.append(points[wanted - j0])

    def trace(self) -> FloatArray:
        """The thinned trace (what :func:`_thinned` gives of the whole run)."""
        if self.every == 0:
            self._head_read()
        return np.vstack(self.kept) if self.kept else np.zeros((0, 2))

    def ends(self) -> FloatArray:
        """The segment ends of :meth:`trace`, ``concatenate(_segments(trace))``, from the pieces.

        The starts ``a``, then the ends ``b`` (:func:`_segments`), made from the kept
        pieces without the joined trace beside them (6 MB of a 400 000-point contour).
        """
        if self.every == 0:
            self._head_read()
        n = sum(len(p) for p in self.kept)
        if n <= 1:
            return np.concatenate(path_shortfall._segments(self.trace()))
        out = np.empty((2 * (n - 1), 2), dtype=np.float64)
        at = n - 2  # the trace from n - 2: its points 1.. are the segment ends b
        for piece in self.kept:
            out[at : at + len(piece)] = piece
            at += len(piece)
        at = 0  # then its points ..n - 2 are the starts a (the one at n - 2 set again)
        for piece in self.kept:
            take = min(len(piece), n - 1 - at)
            out[at : at + take] = piece[:take]
            at += take
        return out

    def extent(self) -> tuple[float, float]:
        """:func:`_extent` of the run."""
        if self.hi <= self.lo:
            return (0.0, 0.0)
        return (self.top[0] - self.low[0], self.top[1] - self.low[1])


class TraceStream:
    """The measures of a trace read chunk by chunk (no array of the whole trace).

    Every measure of :func:`deviation`, :func:`measure_contours` and :func:`along_path`,
    from chunks of whole moves.

    Feed the chunks in order with :meth:`add` (``first`` move, global row offsets, the
    carriage and steps of their rows), then :meth:`finish`. The figures are those of
    the whole-trace functions, bit for bit: each point's distance is computed by the
    same float operations, maxima and their positions compared in trace order (the
    first of equal maxima wins), extents by ``max``/``min`` (exact), each contour's
    trace thinned to the points :func:`_thinned` keeps of the whole contour (its
    every-k-th, read from the contour's first :data:`THIN_HEAD` points and its known
    length, the moves' last rows and its last point) and measured as
    :func:`along_path` measures it (:class:`_Bounded`, the samples that cannot pass the
    largest shortfall so far left out). A contour that is a circle feeds its rows to its
    fit as they come (:class:`~camtool.verify.circlefit.CircleFit`). The one exception
    is the deviation's rms: numpy's pairwise mean of the
    whole array cannot be reproduced chunk by chunk, so it is the square root of the
    exact sum of the squares (an integer sum of their mantissas by exponent,
    :func:`camtool.accel.kernels.exact_sum_squares`; the squares are numpy's ``d * d``),
    correctly rounded, divided by the count: at least as accurate, and it may differ
    from the whole-array figure in the last bits.

    Args:
        program: the program the trace executed.
        block_start: ``(B + 1,) int64`` row offsets of every move in the whole trace.
        start_mm: the carriage before the first row.
        kernels: the compiled kernels (:mod:`camtool.accel.kernels`).
        rms: measure the deviation's rms; ``False`` (the error budget, whose figures do
            not include it): ``deviation.rms_um`` is NaN.
    """

    def __init__(
        self,
        program: Program,
        block_start: IntArray,
        start_mm: Point,
        kernels: Any,
        *,
        rms: bool = True,
    ):
        self.rms = rms
        nearest_search.near_kernels()  # numba is loaded: the compiled search costs its cache
        self.program = program
        self.block_start = block_start
        self.kernels = kernels
        self.starts = deviations.move_starts(program)
        self.nominal = deviations.nominal_arrays(program, self.starts)
        self.start = np.asarray(start_mm, dtype=np.float64).reshape(1, 2)
        self.prev: FloatArray = self.start[0]
        self.runs = contour_measures.contour_runs(program)
        self.next_run = 0
        self.open: _Contour | None = None
        self.contours: list[contour_measures.ContourMeasure] = []
        self.rows = int(block_start[-1])
        self.every_picture = max(1, -(-self.rows // path_shortfall.PICTURE_ROWS))
        self.picture: list[tuple[IntArray, FloatArray, IntArray, Any, Any]] = [
            (
                np.zeros(0, np.int64),
                np.zeros((0, 2)),
                np.zeros(0, np.int64),
                np.zeros((0, 2), np.int8),
                np.zeros(0, np.bool_),
            )
        ]
        self.comp_steps = [0, 0]
        # deviation
        self.dev_max = -1.0
        self.dev_where: tuple[Point, int, int] = ((0.0, 0.0), -1, -1)  # at, block, row
        self.dev_rows: tuple[IntArray, FloatArray, IntArray, Any, Any] | None = None  # near it
        self.dev_count = 0
        self.bins = np.zeros(kernels.EXACT_BINS, dtype=np.int64)
        # along the path
        total = sum(
            segment_of(self.starts[i], program.moves[i]).length
            for a, b in self.runs
            for i in range(a, b + 1)
        )
        self.spacing = max(
            path_shortfall.ALONG_SPACING_MM, total / path_shortfall.ALONG_MAX_SAMPLES
        )
        self.worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
        self.end_worst: tuple[float, Point, int] = (0.0, (0.0, 0.0), -1)
        self.ends: list[float] = []
        self.samples = 0

    def add(
        self,
        first: int,
        block_start: IntArray,
        points: FloatArray,
        steps: npt.NDArray[np.int8],
        compensation: npt.NDArray[np.bool_],
        measured: tuple[IntArray, FloatArray, list[tuple[int, int]]] | None = None,
    ) -> None:
        """Measure one chunk: moves ``first ..`` with global row offsets ``block_start``.

        ``measured``: :meth:`distances` of this chunk, when another thread took them.
        """
        r0 = int(block_start[0])
        blocks, dist, pieces = measured or self.distances(first, block_start, points)
        self._deviation(r0, points, blocks, steps, compensation, dist, pieces)
        self._picture(r0, points, blocks, steps, compensation)
        comp = steps[np.flatnonzero(compensation)]  # a few rows: 5 µs, where the mask took 76
        for axis in (0, 1):
            self.comp_steps[axis] += int(np.abs(comp[:, axis]).sum())
        self._contours(first, first + len(block_start) - 1, r0, points)
        if len(points):
            self.prev = points[-1].copy()

    def distances(
        self, first: int, block_start: IntArray, points: FloatArray
    ) -> tuple[IntArray, FloatArray, list[tuple[int, int]]]:
        """A chunk's move of each row and its rows' distances to their moves (:func:`_distances`).

        It reads only the chunk and the program's nominal moves, so another thread may
        take it while this one measures the chunk before (:func:`_stream`'s producer).
        """
        r0 = int(block_start[0])
        count = len(block_start) - 1
        blocks = np.repeat(np.arange(first, first + count, dtype=np.int64), np.diff(block_start))
        bounds = block_start - r0
        return blocks, *deviations._distances(
            points, blocks, self.nominal, bounds, first, self.kernels
        )

    def _deviation(
        self,
        r0: int,
        points: FloatArray,
        blocks: IntArray,
        steps: Any,
        compensation: Any,
        dist: FloatArray,
        pieces: list[tuple[int, int]],
    ) -> None:
        if not len(dist):
            return
        worst = int(np.argmax(dist))
        if float(dist[worst]) > self.dev_max:
            row = deviations._row_of(pieces, worst)
            self.dev_max = float(dist[worst])
            at = (float(points[row, 0]), float(points[row, 1]))
            self.dev_where = (at, int(blocks[row]), r0 + row)
            near = slice(max(0, row - path_shortfall.ZOOM_ROWS), row + path_shortfall.ZOOM_ROWS + 1)
            self.dev_rows = (
                np.arange(r0 + near.start, r0 + near.start + len(points[near]), dtype=np.int64),
                points[near].copy(),
                blocks[near].copy(),
                steps[near].copy(),
                compensation[near].copy(),
            )
        self.dev_count += len(dist)
        if self.rms:
            self.kernels.exact_sum_squares(dist, self.bins)

    def _picture(
        self, r0: int, points: FloatArray, blocks: IntArray, steps: Any, compensation: Any
    ) -> None:
        every = self.every_picture
        local = np.arange(-(-r0 // every) * every - r0, len(points), every, dtype=np.int64)
        self.picture.append(
            (local + r0, points[local], blocks[local], steps[local], compensation[local])
        )

    def _point(self, row: int, r0: int, points: FloatArray) -> FloatArray:
        """The carriage after global ``row`` (in this chunk or the row before it)."""
        return points[row - r0] if row >= r0 else self.prev

    def _contours(self, first: int, stop: int, r0: int, points: FloatArray) -> None:
        bs = self.block_start
        while True:
            c = self.open
            if c is None:
                if self.next_run >= len(self.runs) or self.runs[self.next_run][0] >= stop:
                    return
                a, b = self.runs[self.next_run]
                self.next_run += 1
                c = _Contour(self.next_run, a, b, bs)
                c.before = self._point(c.lo - 1, r0, points).copy()
                candidate = contour_measures._circle_candidate(
                    [segment_of(self.starts[i], self.program.moves[i]) for i in range(a, b + 1)]
                )
                if candidate is not None and math.dist(self.starts[a], self.starts[b + 1]) <= 1e-6:
                    c.circle = CircleFit(candidate[1])  # fed as the rows come
                for axis in (0, 1):
                    c.top[axis] = c.low[axis] = float(c.before[axis])
                c.add(0, c.before.reshape(1, 2))
                self.open = c
            g0, g1 = max(c.lo, r0), min(c.hi, r0 + len(points))
            if g1 > g0:
                part = points[g0 - r0 : g1 - r0]
                x_top, x_low, y_top, y_low = self.kernels.extent(part)  # one pass
                c.top[0], c.low[0] = max(x_top, c.top[0]), min(x_low, c.low[0])
                c.top[1], c.low[1] = max(y_top, c.top[1]), min(y_low, c.low[1])
                c.add(g0 - c.lo + 1, part)
            for b in range(max(c.first, first), min(c.last, stop - 1) + 1):
                here = self._point(int(bs[b + 1]) - 1, r0, points)
                gap = math.dist(here, self.starts[b + 1]) * 1000.0
                if gap > self.end_worst[0]:
                    self.end_worst = (gap, self.starts[b + 1], b)
            if c.last >= stop:
                return
            c.last_point = self._point(c.hi - 1, r0, points).copy() if c.hi > c.lo else c.before
            self._close(c)
            self.open = None

    def _close(self, c: _Contour) -> None:
        program, starts = self.program, self.starts
        self.ends.append(math.dist(c.last_point, starts[c.last + 1]))
        fitted = None if c.circle is None else c.circle.result()
        self.contours.append(
            contour_measures._contour_measure(
                program,
                starts,
                c.number,
                (c.first, c.last),
                c.before,
                c.last_point,
                c.extent(),
                lambda centre: None if fitted is None else fitted[2],
            )
        )
        ends = nearest_search._LazyTree(c.ends())  # one k-d tree for every batch (when one is used)
        segments = len(ends.points) // 2  # a and b: views of the tree's ends, not the trace
        a, b = ends.points[:segments], ends.points[segments:]
        c.kept = []  # the trace is let go: ~6 MB of a 400 000-point contour
        beside = self.next_run >= len(self.runs) and len(ends.points) >= TREE_BESIDE_FROM
        if beside:  # the last contour: the other core has nothing else to do
            ends.build_beside()
        try:
            self._shortfall(c, ends, a, b)
        finally:
            ends.settle()

    def _shortfall(
        self, c: _Contour, ends: nearest_search._LazyTree, a: FloatArray, b: FloatArray
    ) -> None:
        """The largest shortfall of contour ``c`` from its thinned trace ``a → b`` (``ends``)."""
        program, starts = self.program, self.starts
        places: path_shortfall._Places | None = None  # made for the first batch that is bounded
        batches = path_shortfall._sample_batches(
            program, starts, c.first, c.last, self.spacing, path_shortfall.STREAM_SAMPLES
        )
        for samples, owner, t in batches:  # each sample's distance is its own
            self.samples += len(samples)
            if len(samples) < path_shortfall.SHORTFALL_BOUND_FROM:  # few: measured at once
                got: tuple[float, int] | None = nearest_search.farthest_nearest(
                    samples, a, b, ends=ends
                )
            else:
                if places is None:
                    nominal = {k: v[c.first : c.last + 1] for k, v in self.nominal.items()}
                    places = path_shortfall._Places(
                        a, b, path_shortfall._move_spans(c.n, c.every, c.keep), nominal
                    )
                bounded = path_shortfall._Bounded(samples, owner - c.first, t, places, ends)
                got = bounded.farthest(self.worst[0] / 1000.0)  # none can pass the worst
            if got is None:
                continue
            far, k = got
            if far * 1000.0 > self.worst[0]:
                at = (float(samples[k, 0]), float(samples[k, 1]))
                self.worst = (far * 1000.0, at, int(owner[k]))

    def finish(self) -> StreamedMeasures:
        """The measures of the whole trace (after its last chunk)."""
        if self.dev_count == 0:
            dev = deviations.Deviation(0.0, 0.0, (0.0, 0.0), -1, 0)
        else:
            mean = self.kernels.exact_sum(self.bins) / self.dev_count if self.rms else math.nan
            at, block, _ = self.dev_where
            dev = deviations.Deviation(
                self.dev_max * 1000.0, math.sqrt(mean) * 1000.0, at, block, self.dev_count
            )
        along = path_shortfall.AlongPath(
            shortfall_um=self.worst[0],
            shortfall_at_mm=self.worst[1],
            shortfall_block=int(self.worst[2]),
            block_end_um=self.end_worst[0],
            block_end_at_mm=(float(self.end_worst[1][0]), float(self.end_worst[1][1])),
            block_end_block=int(self.end_worst[2]),
            contour_end_um=tuple(e * 1000.0 for e in self.ends),
            samples=self.samples,
        )
        if self.dev_rows is not None:  # the worst point and the rows around it, unless kept
            rows, *columns = self.dev_rows
            new = rows % self.every_picture != 0
            points, blocks, steps, comp = columns
            self.picture.append((rows[new], points[new], blocks[new], steps[new], comp[new]))
        order = np.argsort(np.concatenate([p[0] for p in self.picture]), kind="stable")

        def joined(k: int) -> Any:
            return np.concatenate([p[k] for p in self.picture])[order]

        return StreamedMeasures(
            deviation=dev,
            along=along,
            contours=tuple(self.contours),
            picture_rows=joined(0),
            picture_mm=joined(1).reshape(-1, 2),
            picture_blocks=joined(2),
            picture_steps=joined(3).reshape(-1, 2),
            picture_compensation=joined(4),
            compensation_steps=(self.comp_steps[0], self.comp_steps[1]),
        )
