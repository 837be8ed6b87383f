"""Layers of a verification: the simulated trace coloured by deviation, the worst point, the inset.

Design notes: docs/internals.md, ``camtool/preview/trace_layers.py``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camtool.model.program import Rapid
from camtool.model.shapes import BBox, Point
from camtool.model.units import fmt_num
from camtool.preview.program_layers import CUT_COLOUR, cut_runs
from camtool.preview.scene import (
    Circle,
    Layer,
    Path,
    Polylines,
    Style,
    Text,
    place_labels,
    polyline,
    ramp_colour,
)

if TYPE_CHECKING:
    from collections.abc import Sequence

    from camtool.verify.not_cut import NotCut
    from camtool.verify.verifier import Verification

BINS = 16
"""Colour classes of the deviation scale."""
WORST_COLOUR = "#d62728"
"""The worst point's marker and annotation."""
NOT_CUT_COLOUR = "#e67e22"
"""Markers of the features not cut as drawn (orange)."""

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


def cutting_trace(v: Verification) -> tuple[FloatArray, IntArray, FloatArray]:
    """The trace points of cutting moves, their run ids and deviations.

    Returns:
        ``points (N, 2) float64`` mm, ``run (N,) int64`` (points of one run of
        cutting moves share it) and ``dev_um (N,) float64``, distance of each
        point from its block's programmed segment, µm.
    """
    from camtool.verify.deviations import nominal_arrays, point_distances

    program, trace = v.program, v.trace
    if len(trace.block_of_row) == 0 or not program.moves:
        return np.zeros((0, 2)), np.zeros(0, dtype=np.int64), np.zeros(0)
    rapid = np.asarray([isinstance(m, Rapid) for m in program.moves], dtype=bool)
    keep = np.flatnonzero(~rapid[trace.block_of_row])
    blocks = trace.block_of_row[keep]
    points = trace.carriage_mm[keep]
    run = np.cumsum(rapid)[blocks].astype(np.int64)
    dev_um = point_distances(points, blocks, nominal_arrays(program)) * 1000.0
    return points, run, dev_um


def binned_polylines(
    points: FloatArray, run: IntArray, dev_um: FloatArray, *, tolerance: float, top_um: float
) -> list[tuple[int, FloatArray]]:
    """The trace as polylines of one colour class each, thinned to ``tolerance`` mm.

    Args:
        points: ``(N, 2)`` mm, in trace order.
        run: ``(N,)`` run id; pieces join consecutive points of the same run only.
        dev_um: ``(N,)`` deviation of each point, µm.
        tolerance: travel, mm, below which consecutive points are merged.
        top_um: deviation of the top colour class, µm (> 0).

    Returns:
        ``(class, (M, 2) array)`` pairs in trace order, class in ``0..BINS-1``.
    """
    n = len(points)
    if n < 2:
        return []
    same = run[1:] == run[:-1]
    step = np.hypot(*np.diff(points, axis=0).T) * same
    cell = np.floor(np.concatenate(([0.0], np.cumsum(step))) / tolerance)
    keep = np.ones(n, dtype=bool)
    keep[1:] = (cell[1:] != cell[:-1]) | ~same
    keep[:-1] |= ~same
    keep[int(np.argmax(dev_um))] = True
    k = np.flatnonzero(keep)
    if len(k) < 2:
        return []
    piece_dev = np.maximum.reduceat(dev_um, k[:-1] + 1)
    valid = run[k[:-1]] == run[k[1:]]
    classes = np.minimum((piece_dev / top_um * BINS).astype(np.int64), BINS - 1)
    out: list[tuple[int, FloatArray]] = []
    current: list[int] = []
    current_class = -1
    for j in range(len(k) - 1):
        if not valid[j] or classes[j] != current_class:
            if len(current) > 1:
                out.append((current_class, points[current]))
            current, current_class = [int(k[j])], int(classes[j])
            if not valid[j]:
                current, current_class = [], -1
                continue
        current.append(int(k[j + 1]))
    if len(current) > 1:
        out.append((current_class, points[current]))
    return out


def trace_layer(layer_id: str, pieces: list[tuple[int, FloatArray]], width: float) -> Layer:
    """One :class:`Polylines` per colour class, lowest class first."""
    shapes = []
    for c in range(BINS):
        lines = tuple(polyline(p) for cls, p in pieces if cls == c)
        if lines:
            colour = ramp_colour((c + 0.5) / BINS)
            shapes.append(Polylines(lines, Style(colour, width)))
    return Layer(layer_id, tuple(shapes))


def top_um(v: Verification) -> float:
    """Top of the colour scale: the largest deviation, µm (at least 0.001)."""
    return max(v.deviation.max_um, 1e-3)


def worst_label(v: Verification) -> str:
    """``"max 14.07 µm, line 12"``: the worst deviation and where it is in the code."""
    line = v.program.line_of(v.deviation.block)
    where = f"line {line}" if line is not None else f"block {v.deviation.block + 1}"
    return f"max {fmt_num(v.deviation.max_um, 2)} µm, {where}"


def not_cut_marker(at: Point, u: float) -> tuple[Polylines, ...]:
    """An orange diamond on ``at`` (mm), 2.4 u across."""
    x, y, a = at[0], at[1], 1.2 * u
    ring = polyline([(x - a, y), (x, y + a), (x + a, y), (x, y - a)])
    return (Polylines((ring,), Style("#ffffff", 0.5 * u, fill=NOT_CUT_COLOUR), closed=True),)


def not_cut_layer(
    layer_id: str, features: Sequence[NotCut], u: float, *, clear: Sequence[BBox] = ()
) -> Layer:
    """A diamond and a short label (``"tight corner"``) on each feature not cut as drawn.

    Labels are thinned and moved apart (:func:`camtool.preview.scene.place_labels`), and
    clear of the boxes ``clear`` (window units: the order numbers, the worst point's ring
    and label), each moved aside, or hidden where no place near its feature is free.
    """
    shapes: list[Polylines | Text] = []
    labels = []
    for f in features:
        shapes.extend(not_cut_marker(f.at, u))
        labels.append(
            Text(
                (f.at[0] + 1.8 * u, f.at[1] + 1.2 * u), f.label, 2.4 * u, NOT_CUT_COLOUR, halo=True
            )
        )
    shapes.extend(place_labels(labels, limit=12, taken=list(clear)))
    return Layer(layer_id, tuple(shapes))


def worst_layer(layer_id: str, v: Verification, u: float, *, view: BBox | None) -> Layer:
    """A red ring on the worst point; with ``view``, its annotation placed inside the view."""
    wx, wy = v.deviation.at_mm
    shapes: list[Circle | Text] = [
        Circle((wx, wy), 2.2 * u, Style(WORST_COLOUR, 0.45 * u)),
        Circle((wx, wy), 0.35 * u, Style(fill=WORST_COLOUR)),
    ]
    if view is not None:
        right = wx > (view[0] + view[2]) / 2
        below = wy > (view[1] + view[3]) / 2
        x = wx - 3.2 * u if right else wx + 3.2 * u
        y = wy - 5.5 * u if below else wy + 3.6 * u
        anchor = "end" if right else "start"
        label = Text((x, y), worst_label(v), 3.0 * u, WORST_COLOUR, anchor, bold=True, halo=True)
        shapes.append(label)
    return Layer(layer_id, tuple(shapes))


def inset_window(v: Verification) -> BBox:
    """The zoom window: a square centred on the worst point, 8 × the error wide (≥ 10 µm), mm."""
    wx, wy = v.deviation.at_mm
    half = max(v.deviation.max_um * 4e-3, 0.005)
    return (wx - half, wy - half, wx + half, wy + half)


def inset_layers(v: Verification, window: BBox) -> tuple[Layer, ...]:
    """Programmed path, trace and worst point inside the zoom ``window`` (window units)."""
    size = window[2] - window[0]
    grown = (window[0] - size, window[1] - size, window[2] + size, window[3] + size)

    def near(box: BBox) -> bool:
        return (
            box[0] <= grown[2] and box[2] >= grown[0] and box[1] <= grown[3] and box[3] >= grown[1]
        )

    chains = tuple((s,) for run in cut_runs(v.program) for s in run if near(s.bbox()))
    points, run, dev_um = cutting_trace(v)
    inside = np.flatnonzero(np.all((points >= grown[:2]) & (points <= grown[2:]), axis=1))
    pieces: list[tuple[int, FloatArray]] = []
    if len(inside) > 1:
        gap = np.concatenate(([0], np.cumsum(np.diff(inside) != 1)))
        pieces = binned_polylines(
            points[inside],
            run[inside] * (len(points) + 1) + gap,
            dev_um[inside],
            tolerance=size / 400.0,
            top_um=top_um(v),
        )
    u = size / 100.0
    return (
        trace_layer("inset-trace", pieces, 2.2 * u),
        Layer("inset-cuts", (Path(chains, Style(CUT_COLOUR, 0.6 * u)),) if chains else ()),
        worst_layer("inset-worst", v, u * 2.0, view=None),
    )
