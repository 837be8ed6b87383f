"""The cutting part of a trace, thinned to what a comparison with the drawing can tell apart.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.verify import path_shortfall

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


AGAINST_RESOLUTION_MM = 0.0005
"""Spacing :func:`against_drawing` thins the cutting trace to by default, mm."""


def thin_cutting(
    points: FloatArray, runs: IntArray | None, resolution_mm: float = AGAINST_RESOLUTION_MM
) -> ThinTrace:
    """The cutting trace thinned as :func:`against_drawing` compares it with the drawing.

    Every k-th row (about ``resolution_mm`` apart, read from the first
    :data:`CUT_HEAD_ROWS` rows; at most :data:`CUT_MAX_ROWS` of them), each run's first
    and last row and the last row (:func:`_thin_index`). :class:`CuttingStream` gives
    the same from a trace read chunk by chunk.

    Args:
        points: ``(N, 2)`` cutting rows, mm.
        runs: ``(N,)`` the run (cut between rapids) of each row, or ``None`` (one run).
        resolution_mm: the spacing aimed at, mm.
    """
    n = len(points)
    if n < 2:
        return ThinTrace(points, runs, n)
    every = _cut_every(points[: min(n, CUT_HEAD_ROWS)], resolution_mm)
    keep = _thin_index(n, _cut_limit(n, every), runs)
    return ThinTrace(points[keep], None if runs is None else runs[keep], n)


CUT_HEAD_ROWS = 2000
"""Cutting rows whose median step sets the thinning of :func:`against_drawing`."""


CUT_MAX_ROWS = 400_000
"""Most every-k-th rows :func:`against_drawing` keeps of the cutting trace."""


def _cut_every(head: FloatArray, resolution_mm: float) -> int:
    """Every how many rows the trace is about ``resolution_mm`` long (``head``: its first rows)."""
    step = path_shortfall._median_step(head)
    return max(1, int(resolution_mm / step)) if step > 0 else 1


def _cut_limit(n: int, every: int) -> int:
    """The ``limit`` of :func:`_thin_index` for ``n`` cutting rows thinned ``every`` rows."""
    return min(CUT_MAX_ROWS, math.ceil(n / every))


@dataclass(frozen=True, eq=False)
class ThinTrace:
    """A cutting trace thinned as :func:`against_drawing` thins it.

    Attributes:
        points: ``(K, 2)`` the rows kept (every k-th, each run's first and last, the
            last), mm, in trace order.
        runs: ``(K,)`` the run (continuous cut between rapids) of each, or ``None``
            (one run).
        rows: the cutting rows of the whole trace (``N``; ``K <= N``).
    """

    points: FloatArray
    runs: IntArray | None
    rows: int


class CutDigest:
    """A digest of a trace's cutting rows and their run ids, fed chunk by chunk.

    Two traces whose cutting rows (mm, as float64 bytes) and runs between rapids are the
    same have the same :meth:`digest` however they were cut into chunks, so the drawing
    comparison of one (it reads nothing else of the trace) is the other's: the error
    budget tells so without holding either trace whole. A different digest says only
    that they may differ (a ``-0.0`` is not a ``0.0`` here).

    Args:
        rapid: ``(B,)`` bool, which moves are rapids (their rows do not cut).
    """

    def __init__(self, rapid: npt.NDArray[np.bool_]) -> None:
        self.rapid = rapid
        self.gaps = 0  # rows that do not cut, so far (the run id is their count)
        self._rows = hashlib.sha256()
        self._runs = hashlib.sha256()

    def add(self, points: FloatArray, blocks: IntArray) -> tuple[FloatArray, IntArray]:
        """One chunk: its rows ``(R, 2)`` mm and the move of each; returns its cutting rows.

        The cutting rows ``(C, 2)`` and their run ids ``(C,) int64`` (the count of rows
        that do not cut before each, from the first chunk on).
        """
        cutting = ~self.rapid[blocks] if len(blocks) else np.zeros(0, dtype=bool)
        runs = (self.gaps + np.cumsum(~cutting, dtype=np.int64))[cutting]
        self.gaps += int(len(cutting) - np.count_nonzero(cutting))
        cut = points[cutting]
        self._rows.update(np.ascontiguousarray(cut, dtype="<f8").tobytes())
        self._runs.update(np.ascontiguousarray(runs, dtype="<i8").tobytes())
        return cut, runs

    def digest(self) -> bytes:
        """The digest of every chunk added so far."""
        return self._rows.digest() + self._runs.digest()


class CuttingStream:
    """The thinned cutting trace of :func:`against_drawing`, from a trace read chunk by chunk.

    Feed every chunk of the whole trace in order with :meth:`add` (the chunk's rows, mm,
    and the move of each row), then :meth:`finish`: the rows and run ids are those
    :func:`against_drawing` keeps of the whole trace's cutting rows (what
    :func:`camtool.verify.streamed.cutting_rows` gives), bit for bit, while no more
    than a chunk and :data:`CUT_HEAD_ROWS` rows are held besides the kept ones. The
    cutting rows are known in advance (``rows``: from the moves' row counts), so the
    every-k-th is known as soon as the first :data:`CUT_HEAD_ROWS` of them are read;
    the last row of each chunk waits for the next chunk to say whether a run ends there.

    Args:
        rapid: ``(B,)`` bool, which moves are rapids (their rows do not cut).
        rows: the cutting rows of the whole trace.
        resolution_mm: as for :func:`against_drawing`.
    """

    def __init__(self, rapid: npt.NDArray[np.bool_], rows: int, resolution_mm: float) -> None:
        self.rapid = rapid
        self.n = rows
        self.resolution_mm = resolution_mm
        self.k = 0  # the every-k-th, once the head is read
        self.seen = 0  # cutting rows given to _take (the carried one included)
        self.head: list[tuple[FloatArray, IntArray]] = []
        self.head_rows = 0
        self.carry: tuple[FloatArray, IntArray, bool] | None = None
        self.kept: list[tuple[FloatArray, IntArray]] = []
        self.digest = CutDigest(rapid)
        """The digest of the cutting rows seen (:class:`CutDigest`)."""

    def add(self, points: FloatArray, blocks: IntArray) -> None:
        """One chunk: its rows ``(R, 2)`` mm and the move of each row ``(R,)``."""
        cut, runs = self.digest.add(points, blocks)
        if not len(cut):
            return
        if self.k:
            self._take(cut, runs)
            return
        self.head.append((cut, runs))
        self.head_rows += len(cut)
        if self.head_rows >= min(self.n, CUT_HEAD_ROWS):
            self._start()

    def _start(self) -> None:
        """The every-k-th from the head, then the head's rows taken."""
        cut = np.concatenate([c for c, _ in self.head]) if self.head else np.zeros((0, 2))
        runs = np.concatenate([r for _, r in self.head]) if self.head else np.zeros(0, np.int64)
        self.head = []
        every = _cut_every(cut[:CUT_HEAD_ROWS], self.resolution_mm)
        self.k = _thin_step(self.n, _cut_limit(self.n, every)) if self.n else 1
        if len(cut):
            self._take(cut, runs)

    def _take(self, cut: FloatArray, runs: IntArray) -> None:
        """Keep what :func:`_thin_index` keeps of these consecutive cutting rows.

        Each row is kept when its index is a multiple of k, is the last, or starts or
        ends a run (:func:`_picked`); the last row given waits (``carry``) for the row
        after it, which says whether a run ends there.
        """
        first = self.seen
        if self.carry is not None:
            point, run, picked_before = self.carry
            cut = np.concatenate([point, cut])
            runs = np.concatenate([run, runs])
            first -= 1
        picked = _picked(first, len(cut), self.k, self.n, runs)
        if self.carry is not None:
            picked[0] |= picked_before
        self.kept.append((cut[:-1][picked[:-1]], runs[:-1][picked[:-1]]))
        self.carry = (cut[-1:], runs[-1:], bool(picked[-1]))
        self.seen = first + len(cut)

    def finish(self) -> ThinTrace:
        """The thinned cutting trace (after the last chunk).

        Raises:
            RuntimeError: the chunks did not hold the ``rows`` cutting rows announced.
        """
        if not self.k:
            self._start()
        if self.carry is not None:  # the last cutting row (n − 1): always kept
            point, run, _ = self.carry
            self.carry = None
            self.kept.append((point, run))
        if self.seen != self.n:
            raise RuntimeError(f"{self.seen} cutting rows streamed, {self.n} announced")
        points = np.concatenate([p for p, _ in self.kept]) if self.kept else np.zeros((0, 2))
        runs = np.concatenate([r for _, r in self.kept]) if self.kept else np.zeros(0, np.int64)
        return ThinTrace(points, runs, self.n)


def _thin_index(n: int, limit: int, runs: IntArray | None) -> IntArray:
    """Indices of every k-th of ``n`` points, the last, and each run's first and last.

    Sorted, each once (a mask: what ``np.unique`` of the picks gives, without sorting).
    """
    return np.flatnonzero(_picked(0, n, _thin_step(n, limit), n, runs)).astype(np.int64)


def _thin_step(n: int, limit: int) -> int:
    """The k of :func:`_thin_index`: every k-th of ``n`` rows keeps at most ``limit``."""
    return max(1, math.ceil(n / limit))


def _picked(first: int, count: int, k: int, n: int, runs: IntArray | None) -> npt.NDArray[np.bool_]:
    """Which of the rows ``first .. first + count − 1`` (of ``n``) :func:`_thin_index` keeps.

    Every k-th row, the last one, and where ``runs`` (the run of each of these rows,
    ``None``: one run) changes the rows on both sides. A caller that gives a part of the
    rows (:class:`CuttingStream`) decides its last row with the part after it.
    """
    picked = np.zeros(count, dtype=bool)
    picked[(-first) % k :: k] = True
    if 0 <= n - 1 - first < count:
        picked[n - 1 - first] = True
    if runs is not None and count > 1:
        change = runs[1:] != runs[:-1]
        picked[1:] |= change
        picked[:-1] |= change
    return picked
