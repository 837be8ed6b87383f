"""The least-squares circle through a trace (Kåsa 1976), fed a few points at a time.

A circle cut in many turns (a hole in many depth passes) has a trace of millions of
points; the fit reads them block by block and keeps a 4 × 4 triangle, so a streamed
verification (:class:`camtool.verify.trace_measures.TraceStream`) never holds the contour's
trace. The blocks start at fixed offsets of the points (multiples of :data:`FIT_BLOCK`),
so the same points give the same floats however they are handed in.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Point

FloatArray = npt.NDArray[np.float64]

FIT_BLOCK = 1 << 16
"""Points reduced at a time (a block's matrix is 2 MB)."""


class CircleFit:
    """The circle ``(x − a)² + (y − b)² = r²`` nearest, in least squares, to points in order.

    Kåsa's algebraic fit: with ``u = x − cx``, ``v = y − cy`` taken about a point
    ``centre`` near the circle's centre, ``u² + v² = p·u + q·v + s`` is solved in least
    squares for ``(p, q, s)``; then ``a = cx + p/2``, ``b = cy + q/2`` and
    ``r = sqrt(s + p²/4 + q²/4)``. The residual is the same function of the circle
    whatever ``centre`` is, so ``centre`` (the nominal centre) only keeps the numbers
    small. Each block of :data:`FIT_BLOCK` points is reduced to the triangle ``R`` of
    its QR factorisation (Householder, LAPACK), and the triangles are merged pairwise
    as a binary tree (``[R1; R2]`` factorised again): the least-squares solution of
    ``R`` is that of all the points, and the tree keeps the rounding to a few ulps
    (within one of a fit by exactly summed normal equations on a 10.7 M-point trace).

    Args:
        centre: ``(cx, cy)`` mm, near the circle's centre.
    """

    def __init__(self, centre: Point) -> None:
        self.centre = (float(centre[0]), float(centre[1]))
        self.count = 0
        self._block = np.empty((FIT_BLOCK, 2), dtype=np.float64)
        self._held = 0
        self._tree: list[tuple[int, FloatArray]] = []  # (level, R): a binary counter

    def add(self, points: FloatArray) -> None:
        """The next points ``(N, 2)`` mm, in order."""
        at = 0
        while at < len(points):
            take = min(len(points) - at, FIT_BLOCK - self._held)
            self._block[self._held : self._held + take] = points[at : at + take]
            self._held += take
            at += take
            if self._held == FIT_BLOCK:
                self._push(self._reduce(self._block))
                self._held = 0
        self.count += len(points)

    def result(self) -> tuple[float, float, float] | None:
        """``(a, b, r)`` mm of the points so far; ``None`` for fewer than three."""
        if self.count < 3:
            return None
        tree = list(self._tree)
        r = self._reduce(self._block[: self._held]) if self._held else tree.pop()[1]
        while tree:
            r = _triangle(np.vstack([tree.pop()[1], r]))
        (p, q, s), *_ = np.linalg.lstsq(r[:, :3], r[:, 3], rcond=None)
        ca, cb = p / 2.0, q / 2.0
        return (self.centre[0] + ca, self.centre[1] + cb, math.sqrt(s + ca * ca + cb * cb))

    def _reduce(self, points: FloatArray) -> FloatArray:
        """The triangle of the block ``points``: the rows ``(u, v, 1, u² + v²)`` factorised."""
        a = np.empty((len(points), 4), dtype=np.float64)
        u, v = a[:, 0], a[:, 1]
        np.subtract(points[:, 0], self.centre[0], out=u)
        np.subtract(points[:, 1], self.centre[1], out=v)
        a[:, 2] = 1.0
        np.multiply(u, u, out=a[:, 3])
        a[:, 3] += v * v
        return _triangle(a)

    def _push(self, r: FloatArray) -> None:
        level = 0
        while self._tree and self._tree[-1][0] == level:
            r = _triangle(np.vstack([self._tree.pop()[1], r]))
            level += 1
        self._tree.append((level, r))


def _triangle(a: FloatArray) -> FloatArray:
    """``R`` of ``a = QR`` (at most 4 rows)."""
    return np.asarray(np.linalg.qr(a, mode="r"))


def fit_circle(points: FloatArray, centre: Point | None = None) -> tuple[float, float, float]:
    """Least-squares circle through points (Kåsa 1976): ``(cx, cy, r)``, mm.

    Args:
        points: ``(N, 2)`` float64, N >= 3, not collinear.
        centre: a point near the centre (:class:`CircleFit`); ``None``: the points' mean.

    Raises:
        ValueError: fewer than three points.
    """
    if centre is None:
        centre = (float(points[:, 0].mean()), float(points[:, 1].mean()))
    fit = CircleFit(centre)
    fit.add(points)
    got = fit.result()
    if got is None:
        raise ValueError(f"a circle needs 3 points or more, got {len(points)}")
    return got
