"""Dots: the zero-length subpaths of a stroke that a viewer draws by its round or square caps.

SVG 1.1 §11.4 (``stroke-linecap``; SVG 2 §13.5.4 "zero length subpath"): a subpath of zero
length, a ``moveto`` followed by a ``closepath`` or by segments that do not move, is stroked
as a dot when the stroke's caps are ``round`` or ``square`` (a disc or a square of the
stroke's width about the point), and not at all with ``butt`` caps; a lone ``moveto`` is never
stroked. Drawings mark holes so (a PCB footprint's pads, a drilling template's centres): a
dot has no path to cut, so it becomes a :class:`~camtool.model.shapes.Mark`, a point a job's
drill operation selects, as a DXF POINT does.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import svgelements as se

from camtool.importers.svgpage import Affine, apply
from camtool.importers.svgstyle import layer_of, style_of, unpainted, zero_width
from camtool.model.shapes import Mark, Point, distance

ZERO_MM = 1e-9
"""Points of a subpath within this distance (mm) of its start do not move it (the length
under which the importer drops a segment)."""
CAPS = ("round", "square")
"""``stroke-linecap`` values that draw a zero-length subpath."""


def draws_dots(shape: Any) -> bool:
    """Whether ``shape``'s stroke draws its zero-length subpaths (painted, wide, capped)."""
    values = shape.values
    cap = str(values.get("stroke-linecap") or "butt").strip().lower()
    if cap not in CAPS:
        return False
    return not (unpainted(shape.stroke) or zero_width(values.get("stroke-width")))


def shape_marks(shape: Any, segments: Sequence[Any] | None, m: Affine, label: str) -> list[Mark]:
    """The dots of a shape that :func:`draws_dots`, as marks in mm.

    ``segments``: its svgelements segments (``None``: not read, no dots); ``m``: its
    coordinates to mm, Y up; ``label``: how messages name it.
    """
    if not segments:
        return []
    values = shape.values
    layer = layer_of(values)
    colour = style_of(values)[0]
    return [Mark(at, layer, label, colour) for at in dots(segments, m)]


def unclipped(marks: list[Mark], clips: Sequence[Any]) -> list[Mark]:
    """The ``marks`` whose point each of ``clips`` shows (its region, grown by its slack).

    ``clips``: :class:`~camtool.importers.svgclip.Clip` with their regions worked out. A
    dot whose centre a clip hides is not shown where it would be drilled: it is left out,
    as a shape that a clip hides wholly is.
    """
    import shapely

    return [k for k in marks if all(c.grown.covers(shapely.Point(k.at)) for c in clips)]


def dots(segments: Sequence[Any], m: Affine) -> list[Point]:
    """The start of every subpath of ``segments`` that draws and does not move, mapped by ``m``.

    A subpath starts at a ``Move`` (or after a ``Close``); it draws when a segment other
    than a ``Move`` follows; it does not move when every point of those segments (ends and
    control points; an arc's ends) lies within :data:`ZERO_MM` of its start once mapped.
    """
    out: list[Point] = []
    start: Point | None = None
    drew = still = False
    for seg in segments:
        if isinstance(seg, se.Move):
            if start is not None and drew and still:
                out.append(start)
            start, drew, still = apply(m, float(seg.end.x), float(seg.end.y)), False, True
            continue
        if start is None:  # svgelements starts every path with a Move
            continue
        drew = True
        still = still and all(
            distance(apply(m, float(p.x), float(p.y)), start) <= ZERO_MM for p in _points(seg)
        )
        if isinstance(seg, se.Close):
            if still:
                out.append(start)
            drew, still = False, True  # a segment after it starts a subpath there
    if start is not None and drew and still:
        out.append(start)
    return out


def _points(seg: Any) -> list[Any]:
    """A drawing segment's points that place it: its ends, and a Bézier's control points."""
    points = [seg.start, seg.end]
    if isinstance(seg, se.CubicBezier):
        points += [seg.control1, seg.control2]
    elif isinstance(seg, se.QuadraticBezier):
        points.append(seg.control)
    return [p for p in points if p is not None]


def dots_warning(path: Path, marks: Sequence[Mark]) -> str:
    """The warning that ``marks`` (dots, at least one) are not cut, naming the first."""
    first = marks[0]
    n = len(marks)
    noun = "dot" if n == 1 else "dots"
    return (
        f"{path}: skipped {n} {noun} (zero-length strokes drawn by their round or square "
        f"caps; first: {first.source} at ({first.at[0]:.4f}, {first.at[1]:.4f}) mm): a dot "
        "has no path to cut; a drill operation of a job drills it"
    )
