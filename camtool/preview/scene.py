"""What a preview draws, independent of the file format: panels of layers of shapes.

Design notes: docs/internals.md, ``camtool/preview/scene.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import BBox, Point, Segment


@dataclass(frozen=True)
class Style:
    """How a shape is stroked and filled.

    Attributes:
        stroke: line colour ``#rrggbb``, ``None`` for no outline.
        width: line width in the panel's window units (mm on the page).
        fill: fill colour, ``None`` for no fill.
        opacity: 0..1 for the whole shape.
        dash: on/off lengths of a dashed line, window units; empty for solid.
    """

    stroke: str | None = None
    width: float = 0.0
    fill: str | None = None
    opacity: float = 1.0
    dash: tuple[float, ...] = ()


@dataclass(frozen=True)
class Path:
    """Chains of lines and exact arcs; each chain is drawn as one continuous stroke."""

    chains: tuple[tuple[Segment, ...], ...]
    style: Style


@dataclass(frozen=True, eq=False)
class Polylines:
    """Polylines, each an ``(N, 2) float64`` array (mm, read-only).

    ``closed`` ones are rings; filled rings use the even-odd rule (holes are
    rings inside rings).
    """

    lines: tuple[npt.NDArray[np.float64], ...]
    style: Style
    closed: bool = False


@dataclass(frozen=True, eq=False)
class Segments:
    """Separate straight strokes, drawn as one shape.

    ``xy`` is ``(M, 2, 2) float64`` (mm, read-only): stroke ``k`` goes from ``xy[k, 0]``
    to ``xy[k, 1]`` (a stroke from a point to itself is a dot).

    What :mod:`camtool.preview.thin` draws a big program with: one shape, one
    matplotlib collection, one SVG path, however many strokes.
    """

    xy: npt.NDArray[np.float64]
    style: Style


@dataclass(frozen=True)
class Circle:
    """A circle of ``radius`` around ``centre``."""

    centre: Point
    radius: float
    style: Style


@dataclass(frozen=True)
class Rect:
    """An axis-aligned rectangle ``box = (xmin, ymin, xmax, ymax)``."""

    box: BBox
    style: Style


@dataclass(frozen=True)
class Text:
    """One line of text; ``at`` is the start of its baseline (or middle/end, by ``anchor``).

    ``size`` is the font size (height of the em) in window units; ``halo`` draws
    a white outline under the letters so they read over lines.
    """

    at: Point
    text: str
    size: float
    colour: str = "#000000"
    anchor: str = "start"
    bold: bool = False
    halo: bool = False


Shape: TypeAlias = Path | Polylines | Segments | Circle | Rect | Text


@dataclass(frozen=True)
class Layer:
    """A named group of shapes (an SVG ``<g id=...>``), drawn in order."""

    id: str
    shapes: tuple[Shape, ...]


@dataclass(frozen=True)
class Panel:
    """Layers seen through ``window`` (world) and drawn into ``frame`` (page), same aspect.

    ``clip`` cuts what falls outside the frame; ``background`` fills the frame
    first and ``border`` outlines it (page units).
    """

    id: str
    frame: BBox
    window: BBox
    layers: tuple[Layer, ...]
    clip: bool = True
    background: str | None = None
    border: Style | None = None

    @property
    def scale(self) -> float:
        """Page mm per window unit (1 for the identity panels)."""
        return (self.frame[2] - self.frame[0]) / (self.window[2] - self.window[0])


@dataclass(frozen=True)
class Scene:
    """A whole preview: the page box, its width in pixels, and panels drawn in order."""

    page: BBox
    width_px: int
    panels: tuple[Panel, ...]

    @property
    def height_px(self) -> int:
        """Picture height in pixels (the page's aspect ratio kept)."""
        w, h = self.page[2] - self.page[0], self.page[3] - self.page[1]
        return max(1, round(self.width_px * h / w))


def polyline(points: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """``points`` as a read-only ``(N, 2) float64`` array."""
    arr = np.array(points, dtype=np.float64).reshape(-1, 2)
    arr.setflags(write=False)
    return arr


# The "plasma" colour map of matplotlib (CC0, van der Walt & Smith) sampled at
# 0, 0.2, ... 1: the trace colours are interpolated from these anchors so that
# the SVG does not depend on the installed matplotlib.
_RAMP = (
    (13, 8, 135),
    (106, 0, 168),
    (177, 42, 144),
    (225, 100, 98),
    (252, 166, 54),
    (240, 249, 33),
)


def ramp_colour(t: float) -> str:
    """Colour of the deviation scale at ``t`` in [0, 1] (dark blue → yellow), ``#rrggbb``."""
    t = min(max(t, 0.0), 1.0) * (len(_RAMP) - 1)
    i = min(math.floor(t), len(_RAMP) - 2)
    f = t - i
    rgb = (round(a + (b - a) * f) for a, b in zip(_RAMP[i], _RAMP[i + 1], strict=True))
    return "#" + "".join(f"{c:02x}" for c in rgb)


def nice_length(target: float) -> float:
    """The 1-2-5 number (×10^k) at or just below ``target`` (> 0): scale bar lengths."""
    k = math.floor(math.log10(target))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**k <= target * (1 + 1e-9):
            return m * 10.0**k
    return 10.0**k


def text_width(text: str, size: float, *, bold: bool = False) -> float:
    """Approximate width of ``text`` at font ``size`` (DejaVu Sans), for layout only."""
    return (0.68 if bold else 0.58) * size * len(text)


def expand(box: BBox, margin: float) -> BBox:
    """``box`` grown by ``margin`` on every side."""
    return (box[0] - margin, box[1] - margin, box[2] + margin, box[3] + margin)


MAX_LABELS = 60
"""Most labels of one kind a picture shows; past it every k-th is kept (first and last too)."""


def text_box(t: Text) -> BBox:
    """The box ``t`` takes (window units), from :func:`text_width`, on the generous side.

    A little wider and taller than the letters (DejaVu Sans Bold's digits are 0.70 em
    wide, its line 1.16 em from descent to ascent), so that labels kept apart by these
    boxes stay apart as matplotlib lays them out.
    """
    w = text_width(t.text, t.size, bold=t.bold) * 1.04 + 0.12 * t.size
    x = t.at[0] - {"start": 0.0, "middle": w / 2, "end": w}.get(t.anchor, 0.0)
    return (x, t.at[1] - 0.3 * t.size, x + w, t.at[1] + 0.9 * t.size)


def mark_box(shape: Text | Circle) -> BBox:
    """The box a label or a ring takes (window units): :func:`text_box`, or the circle's."""
    if isinstance(shape, Text):
        return text_box(shape)
    (x, y), r = shape.centre, shape.radius
    return (x - r, y - r, x + r, y + r)


def kept_indices(n: int, limit: int = MAX_LABELS) -> list[int]:
    """Which of ``n`` marks of one kind a picture shows: all up to ``limit``, else every k-th.

    Past ``limit``, every k-th (``k = ⌈n / (limit − 1)⌉``) and the last, at most ``limit``.
    """
    if n <= limit:
        return list(range(n))
    k = math.ceil(n / max(limit - 1, 1))
    return sorted({*range(0, n, k), n - 1})[:limit]


def place_labels(
    labels: list[Text],
    *,
    limit: int = MAX_LABELS,
    taken: list[BBox] | None = None,
    inside: BBox | None = None,
) -> list[Text]:
    """Labels that do not pile up: at most ``limit``, none overlapping another, all in ``inside``.

    Past ``limit`` every k-th label is kept (the first and the last always). Each
    kept label goes where it was asked, else moved up, down, left, right or
    diagonally by its own size (then twice up or down), else it is hidden.
    ``inside`` (a panel's frame, ``None``: no bound): a label that would cross its
    edge is moved in first, so no label is clipped.
    ``taken`` holds boxes already used (by other labels); the placed labels' boxes are
    added to it.
    """
    labels = [labels[i] for i in kept_indices(len(labels), limit)]
    boxes = taken if taken is not None else []
    placed: list[Text] = []
    for label in labels:
        s = label.size
        box = text_box(label)
        w, h = box[2] - box[0], box[3] - box[1]
        for dx, dy in _NEAR_PLACES:
            dx, dy = dx * w, dy * h
            moved = Text(
                (label.at[0] + dx, label.at[1] + dy),
                label.text,
                s,
                label.colour,
                label.anchor,
                label.bold,
                label.halo,
            )
            if inside is not None:
                kept = moved_inside(moved, inside)
                if kept is None:
                    continue
                moved = kept
            box = text_box(moved)
            if not any(_overlap(box, other) for other in boxes):
                boxes.append(box)
                placed.append(moved)
                break
    return placed


_NEAR_PLACES = (
    (0.0, 0.0),
    (0.0, 1.0),
    (0.0, -1.0),
    (-1.0, 0.0),
    (1.0, 0.0),
    (-1.0, 1.0),
    (1.0, 1.0),
    (-1.0, -1.0),
    (1.0, -1.0),
    (0.0, 2.0),
    (0.0, -2.0),
)
"""Where :func:`place_labels` tries a label, in label widths and heights from where asked."""


def moved_inside(label: Text, inside: BBox) -> Text | None:
    """``label`` shifted by the least that puts its box in ``inside``; None if it cannot fit."""
    x0, y0, x1, y1 = text_box(label)
    if x1 - x0 > inside[2] - inside[0] or y1 - y0 > inside[3] - inside[1]:
        return None
    dx = max(inside[0] - x0, 0.0) + min(inside[2] - x1, 0.0)
    dy = max(inside[1] - y0, 0.0) + min(inside[3] - y1, 0.0)
    if dx == 0.0 and dy == 0.0:
        return label
    at = (label.at[0] + dx, label.at[1] + dy)
    return Text(at, label.text, label.size, label.colour, label.anchor, label.bold, label.halo)


def _overlap(a: BBox, b: BBox) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]
