"""Strokes at the picture's resolution: how a program too big to draw move by move is drawn.

Design notes: docs/internals.md, ``camtool/preview/thin.py``.
"""

from __future__ import annotations

from array import array

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Point

DETAIL_MOVES = 20_000
"""Most moves a picture draws one by one; a bigger program is drawn as :class:`Strokes`."""
CELL_PX = 0.5
"""Side of the grid's cells, pixels."""


FLUSH_POINTS = 1 << 18
"""Points :class:`Strokes` holds before it thins them into its strokes so far."""


class Strokes:
    """Polylines collected point by point (x, y in mm), thinned to a grid of ``cell_mm`` cells.

    Memory: 16 bytes a point for at most :data:`FLUSH_POINTS` points, then the distinct
    strokes so far (bounded by the grid's cells, not by the points given); no object per
    point.
    """

    def __init__(self, cell_mm: float) -> None:
        self.cell_mm = cell_mm
        self.xs = array("d")
        self.ys = array("d")
        self.starts = array("q")  # index of each polyline's first point
        self.strokes = np.zeros((0, 2, 2), dtype=np.int64)  # distinct strokes so far, cells
        self.count = 0  # polylines begun
        self.resumed = False  # the first polyline held goes on from the last one thinned

    def start(self, at: Point) -> None:
        """Begin a new polyline at ``at``."""
        if len(self.xs) >= FLUSH_POINTS:
            self._flush()
        self.starts.append(len(self.xs))
        self.xs.append(at[0])
        self.ys.append(at[1])
        self.count += 1

    def extend(self, points: list[Point]) -> None:
        """Continue the current polyline through ``points``."""
        for x, y in points:
            self.xs.append(x)
            self.ys.append(y)
        if len(self.xs) >= FLUSH_POINTS:  # go on from the last point: a polyline anew
            last = (self.xs[-1], self.ys[-1])
            self._flush()
            self.starts.append(0)
            self.xs.append(last[0])
            self.ys.append(last[1])
            self.resumed = True

    def __bool__(self) -> bool:
        return self.count > 0

    def thinned(self) -> npt.NDArray[np.float64]:
        """The distinct strokes between the grid's cells the polylines cross.

        Returns:
            ``(M, 2, 2) float64``, read-only: stroke ``k`` from ``[k, 0]`` to ``[k, 1]``
            (mm, cell centres), in the order the program first draws them. A polyline
            that stays in one cell is one stroke from that cell to itself (a dot).
        """
        self._flush()
        out = self.strokes.astype(np.float64) * self.cell_mm
        out.setflags(write=False)
        return out

    def _flush(self) -> None:
        """Thin the points held into :attr:`strokes` and let them go."""
        if self.starts:
            both = np.concatenate((self.strokes, self._cell_strokes()))
            a, b = both[:, 0], both[:, 1]
            self.strokes = both[_distinct(a, b)]
        self.xs, self.ys, self.starts = array("d"), array("d"), array("q")
        self.resumed = False

    def _cell_strokes(self) -> npt.NDArray[np.int64]:
        """``(M, 2, 2)`` the strokes of the points held, in cells, in program order."""
        xy = np.column_stack((np.frombuffer(self.xs), np.frombuffer(self.ys)))
        cells = np.rint(xy / self.cell_mm).astype(np.int64)
        first = np.zeros(len(cells), dtype=bool)
        first[np.frombuffer(self.starts, dtype=np.int64)] = True
        # drop a point in the same cell as the point before it, in the same polyline
        same = np.zeros(len(cells), dtype=bool)
        same[1:] = np.all(cells[1:] == cells[:-1], axis=1) & ~first[1:]
        cells, first = cells[~same], first[~same]
        follow = ~first[1:]  # point i + 1 continues the polyline of point i
        lone = np.ones(len(cells), dtype=bool)  # polylines of one cell only: their dot
        lone[:-1] = first[:-1] & first[1:]
        lone[-1] = first[-1]
        lone[0] &= not self.resumed  # its point ends a stroke thinned already
        a = np.concatenate((cells[:-1][follow], cells[lone]))
        b = np.concatenate((cells[1:][follow], cells[lone]))
        order = np.concatenate((np.nonzero(follow)[0] + 1, np.nonzero(lone)[0]))
        sort = np.argsort(order, kind="stable")
        return np.stack((a[sort], b[sort]), axis=1)


def _distinct(a: npt.NDArray[np.int64], b: npt.NDArray[np.int64]) -> npt.NDArray[np.intp]:
    """Indices of the first of each distinct stroke between cells ``a`` and ``b`` (either way)."""
    if len(a) == 0:
        return np.zeros(0, dtype=np.intp)
    low = np.minimum(a.min(axis=0), b.min(axis=0))
    a, b = a - low, b - low
    span = int(max(a.max(), b.max())) + 1
    ka, kb = a[:, 0] * span + a[:, 1], b[:, 0] * span + b[:, 1]
    lo, hi = np.minimum(ka, kb), np.maximum(ka, kb)
    if span**4 < 2**62:
        _, index = np.unique(lo * span * span + hi, return_index=True)
    else:  # a grid too fine for one 64-bit key (never at picture sizes)
        _, index = np.unique(np.column_stack((lo, hi)), axis=0, return_index=True)
    return np.sort(index)
