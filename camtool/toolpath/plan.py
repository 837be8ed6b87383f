"""Plan a drawing into a Program: chain, offset for the tool, order, emit moves.

Offset modes (the ``--offset`` option):

- ``on``: the tool centre follows the drawing (the pic-mmh machine scribes with
  a point, seed-000 §6; S000-09);
- ``outside``: cut outside the material. Material is the even-odd region of the
  closed contours: an outer boundary (even nesting depth) grows by the tool
  radius, a hole (odd depth) shrinks by it;
- ``inside``: the opposite side: outer boundaries shrink, holes grow.

Open contours cannot be compensated to a side; they are cut on the line with a
warning when a side was asked for.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from camtool.errors import UsageError
from camtool.geometry import Arc, Contour, Drawing, Point
from camtool.program import ArcMove, Linear, Move, Program, Rapid
from camtool.toolpath.chain import chain
from camtool.toolpath.order import Nesting, nesting, order_contours

OFFSET_MODES = ("on", "outside", "inside")
"""Valid values of ``PlanOptions.offset``."""


@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """How to turn a drawing into a toolpath.

    Attributes:
        offset: one of :data:`OFFSET_MODES`.
        tool_diameter: tool diameter, mm (needed for ``outside``/``inside``).
        feed_mm_min: cutting feed, mm/min (> 0).
        tolerance: chaining tolerance, mm (> 0): ends closer than this meet.
        origin: tool position before the program, mm.
        scale: uniform scale applied to the drawing about its origin (> 0).
        fit_mm: ``(width, height)``: scale the drawing uniformly, about the
            lower-left corner of its bounding box, to the largest size that fits
            this box. Excludes ``scale``.
    """

    offset: str = "on"
    tool_diameter: float = 0.0
    feed_mm_min: float
    tolerance: float = 0.001
    origin: Point = (0.0, 0.0)
    scale: float = 1.0
    fit_mm: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.offset not in OFFSET_MODES:
            raise UsageError(
                f"unknown offset {self.offset!r}; choose one of {', '.join(OFFSET_MODES)}"
            )
        if self.offset != "on" and self.tool_diameter <= 0:
            raise UsageError(f"--offset {self.offset} needs --tool-diameter MM (> 0)")
        if self.tool_diameter < 0:
            raise UsageError(f"tool diameter must be ≥ 0 mm, got {self.tool_diameter!r}")
        if self.feed_mm_min <= 0:
            raise UsageError(f"feed must be > 0 mm/min, got {self.feed_mm_min!r}")
        if self.tolerance <= 0:
            raise UsageError(f"tolerance must be > 0 mm, got {self.tolerance!r}")
        if self.scale <= 0:
            raise UsageError(f"scale must be > 0, got {self.scale!r}")
        if self.fit_mm is not None:
            if self.scale != 1.0:
                raise UsageError("give either --scale or --fit, not both")
            if min(self.fit_mm) <= 0:
                raise UsageError(f"--fit needs a width and height > 0 mm, got {self.fit_mm!r}")


def plan(drawing: Drawing, options: PlanOptions) -> Program:
    """Turn a drawing into a program of rapids and cuts.

    Contours are chained within ``options.tolerance``, compensated for the tool
    (see the module docstring), ordered inside-first then nearest-first, and
    each is reached by one rapid to its start.

    Raises:
        UsageError: invalid options.
        ToolpathError: an offset fails or leaves nothing.
    """
    contours = chain(place(drawing, options).contours, options.tolerance)
    nest = nesting(contours)
    warnings = list(drawing.warnings)
    paths = list(contours)
    if options.offset != "on":
        paths = _compensate(contours, nest, options, warnings)
    order = order_contours(paths, nest, options.origin)
    moves: list[Move] = []
    for number, index in enumerate(order, start=1):
        moves.extend(_contour_moves(paths[index], number, options.feed_mm_min))
    return Program(tuple(moves), options.origin, tuple(warnings))


def place(drawing: Drawing, options: PlanOptions) -> Drawing:
    """The drawing scaled as ``options.scale`` or ``options.fit_mm`` ask (mm)."""
    if options.fit_mm is None:
        return drawing if options.scale == 1.0 else drawing.transformed(options.scale)
    x0, y0, x1, y1 = drawing.bbox()
    w, h = options.fit_mm
    k = min(w / (x1 - x0) if x1 > x0 else math.inf, h / (y1 - y0) if y1 > y0 else math.inf)
    if math.isinf(k):
        return drawing
    return drawing.transformed(k, x0 * (1 - k), y0 * (1 - k))


def _compensate(
    contours: Sequence[Contour], nest: Nesting, options: PlanOptions, warnings: list[str]
) -> list[Contour]:
    from camtool.toolpath.offset import offset_contour

    radius = options.tool_diameter / 2.0
    out: list[Contour] = []
    open_count = 0
    for i, c in enumerate(contours):
        if not c.closed:
            open_count += 1
            out.append(c)
            continue
        outer = nest.depth(i) % 2 == 0
        grow = outer == (options.offset == "outside")
        out.append(offset_contour(c, radius if grow else -radius))
    if open_count:
        warnings.append(
            f"{open_count} open contour(s) cut on the line: --offset {options.offset} needs "
            "closed contours"
        )
    return out


def _contour_moves(contour: Contour, number: int, feed: float) -> list[Move]:
    moves: list[Move] = [Rapid(*contour.start, contour=number)]
    for seg in contour.segments:
        x, y = seg.end
        if isinstance(seg, Arc):
            moves.append(ArcMove(x, y, *seg.centre, seg.clockwise, feed, contour=number))
        else:
            moves.append(Linear(x, y, feed, contour=number))
    return moves
