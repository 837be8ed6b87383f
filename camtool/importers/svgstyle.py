"""A drawn SVG shape's colour, linetype and layer, as jobs and ``--layers`` select by them.

The colour is the stroke's, else the fill's (SVG 1.1 §11.2-11.4, paint); the linetype
says construction (:mod:`camtool.model.construction`): a stroke of dashes
(``stroke-dasharray``, §11.4), or a Shaper Origin guide (``shaper:cutType="guide"``, the
attribute Shaper Tools' own SVG export and many sheet-layout tools write). A shape outside
any Inkscape layer is on layer ``0`` (:data:`DEFAULT_LAYER`), or on the layer its Shaper cut
type names (:data:`SHAPER_LAYER`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import svgelements as se

from camtool.importers.options import layer_list
from camtool.importers.svgtree import LAYER_ATTR, LIBRECAD_NS
from camtool.importers.svgvalues import URL_REF
from camtool.model.errors import InputError
from camtool.model.shapes import Contour, Line

_LC_CONSTRUCTION = f"{{{LIBRECAD_NS}}}is_construction"
_SHAPER = "{http://www.shapertools.com/namespaces/shaper}"
_SHAPER_ATTRIBUTES = (_SHAPER + "cutType", _SHAPER + "pathType")
"""How Shaper Origin's format says a shape is cut: ``shaper:cutType`` (Shaper's SVG
reference), or ``shaper:pathType`` (Shaper's Fusion 360 add-in); ``guide``: not at all."""
_SHAPER_NAMES = {
    "outside": "outside", "exterior": "outside", "inside": "inside", "interior": "inside",
    "pocket": "pocket", "online": "online", "on-line": "online", "guide": "guide",
}  # fmt: skip
"""Each value those attributes take (any case: ``onLine``), by camtool's name for it."""
DEFAULT_LAYER = "0"
"""Contour.layer of shapes outside any Inkscape layer (the DXF default layer's name)."""
SHAPER_LAYER = "shaper "
"""The layer of a shape outside any Inkscape layer that Shaper's cut type says how to cut:
``"shaper outside"``, ``"shaper inside"``, ``"shaper pocket"``, ``"shaper online"``."""
SHAPER_CUTS = ("outside", "inside", "pocket", "online")


def _shaper_cut(values: Any) -> str | None:
    """The shape's Shaper cut type, by camtool's name (:data:`_SHAPER_NAMES`), or ``None``."""
    for key in _SHAPER_ATTRIBUTES:
        name = _SHAPER_NAMES.get(str(values.get(key, "")).strip().lower())
        if name:
            return name
    return None


_SHAPER_DEPTH = re.compile(r"\s*(\d+\.?\d*|\.\d+)\s*(mm|cm|in)\s*", re.IGNORECASE | re.ASCII)
"""A ``shaper:cutDepth`` camtool reads: a number and its unit (``6.0mm``, ``0.25in``)."""
_DEPTH_UNITS = {"mm": 1.0, "cm": 10.0, "in": 25.4}


def layer_of(values: Any) -> str:
    """The layer a shape is on: its Inkscape layer, else its Shaper cut's, else the default."""
    return str(values.get(LAYER_ATTR) or shaper_layer(values) or DEFAULT_LAYER)


def shaper_layer(values: Any) -> str | None:
    """The layer named for the shape's Shaper cut type and depth, or ``None``.

    ``"shaper pocket"``, with the depth when ``shaper:cutDepth`` gives one in mm, cm or in:
    ``"shaper pocket 4mm"`` (:data:`SHAPER_LAYER`; read back by :func:`shaper_cut_of`).
    """
    cut = _shaper_cut(values)
    if cut not in SHAPER_CUTS:
        return None
    depth = _SHAPER_DEPTH.fullmatch(str(values.get(_SHAPER + "cutDepth", "")))
    mm = float(depth[1]) * _DEPTH_UNITS[depth[2].lower()] if depth else 0.0
    return f"{SHAPER_LAYER}{cut}" + (f" {mm:g}mm" if mm > 0 else "")


def shaper_cut_of(layer: str) -> tuple[str, float | None] | None:
    """The cut type and depth (mm; ``None``: not given) a :func:`shaper_layer` name says.

    ``None`` for any other layer name.
    """
    words = layer.split(" ")
    if len(words) not in (2, 3) or words[0] != SHAPER_LAYER.strip() or words[1] not in SHAPER_CUTS:
        return None
    if len(words) == 2:
        return words[1], None
    depth = _SHAPER_DEPTH.fullmatch(words[2])
    return (words[1], float(depth[1])) if depth and depth[2] == "mm" else None


def style_of(values: Any) -> tuple[str, str]:
    """The shape's colour (its stroke, else its fill, as ``#rrggbb``) and linetype.

    A Shaper Origin guide (``shaper:cutType`` or ``pathType="guide"``, on it or a group: a sheet's
    border, a centre line) is ``"GUIDE"``; a shape on a LibreCAD construction layer
    (``lc:is_construction="true"``, written when its SVG export is asked for them) is
    ``"CONSTRUCTION"``; a stroke with a ``stroke-dasharray`` of dashes is ``"DASHED"``:
    construction lines (:mod:`camtool.model.construction`); else ``""``.
    """
    if _shaper_cut(values) == "guide":
        return _colour(values), "GUIDE"
    if str(values.get(_LC_CONSTRUCTION, "")).strip().lower() == "true":
        return _colour(values), "CONSTRUCTION"
    return _colour(values), ("DASHED" if _dashed(values) else "")


def _colour(values: Any) -> str:
    """The shape's stroke (of a width), else its fill, as ``#rrggbb`` (``""``: neither)."""
    colour = ""
    for key in ("stroke", "fill"):
        if key == "stroke" and zero_width(values.get("stroke-width")):
            continue  # a stroke of width 0 shows nothing: the fill's colour is seen
        paint = str(values.get(key) or "none").strip()
        if _none(paint) or paint.lower().startswith(("url(", "currentcolor")):
            continue
        try:
            rgb = se.Color(paint)
        except (ValueError, TypeError):
            continue
        if rgb.value is not None:
            colour = f"#{rgb.red:02x}{rgb.green:02x}{rgb.blue:02x}"
            break
    return colour


def _dashed(values: Any) -> bool:
    """Whether the shape is stroked with gaps: a ``stroke-dasharray`` with a gap > 0.

    The list repeats to an even count, its second, fourth... lengths the gaps; a negative
    length makes the value invalid, so ignored (SVG 2 §13.5.5): drawn as a line, as is
    ``40 0`` (no gap) or a sum of zero.
    """
    if _none(values.get("stroke")) or zero_width(values.get("stroke-width")):
        return False  # no stroke shows: the shape is its fill
    dashes = str(values.get("stroke-dasharray") or "").replace(",", " ").split()
    lengths = []
    for text in dashes:
        try:
            lengths.append(float(re.sub(r"[a-z%]+$", "", text.lower())))
        except ValueError:
            return False  # not a dash array camtool can read: drawn as a line
    if any(not v >= 0 for v in lengths):
        return False
    if len(lengths) % 2:
        lengths *= 2
    return any(gap > 0 for gap in lengths[1::2])


def _none(paint: Any) -> bool:
    return paint is None or str(paint).strip().lower() == "none"


def wanted_layers(
    path: Path, layers: tuple[str, ...] | None
) -> tuple[tuple[str, ...] | None, tuple[str, ...]]:
    """``--layers`` split: Inkscape layers, and layers of shapes outside them.

    The first are for :func:`camtool.importers.svgdoc.prepare`; the second (``0``, Shaper's
    ``shaper pocket 4mm``) are kept after reading (:func:`on_layers`).

    Raises:
        InputError: both kinds are named (the first would drop the second's shapes).
    """
    if layers is None:
        return None, ()
    named = tuple(n for n in layers if n == DEFAULT_LAYER or n.startswith(SHAPER_LAYER))
    inkscape = tuple(n for n in layers if n not in named)
    if named and inkscape:
        raise InputError(
            f"{path}: --layers names Inkscape layers ({', '.join(map(repr, inkscape))}) and "
            f"the layers of shapes outside them ({', '.join(map(repr, named))}); name one "
            "kind, or select them by operations of a job"
        )
    return (None if named else inkscape), named


def on_layers(
    path: Path, contours: list[Contour], named: tuple[str, ...], others: Iterable[str] = ()
) -> list[Contour]:
    """The contours on the layers ``named``; an unknown name is an InputError listing them.

    ``others``: the layers of what else the drawing holds (its marks), which are known too.
    """
    there = sorted({c.layer for c in contours} | set(others), key=str.casefold)
    unknown = [n for n in named if n not in there]
    if unknown:
        raise InputError(
            f"{path}: no layer named {', '.join(map(repr, unknown))}; its layers are "
            + layer_list(there)
        )
    return [c for c in contours if c.layer in named]


_ZERO_WIDTH = re.compile(
    r"\s*[+-]?(?:0+\.?0*|\.0+)(?:e[+-]?\d+)?"
    r"(?:px|pt|pc|mm|cm|in|q|em|ex|rem|ch|vw|vh|vmin|vmax|%)?\s*",
    re.IGNORECASE,
)


def zero_width(value: object) -> bool:
    """Whether a ``stroke-width`` value (``0``, ``0.0``, ``0px``, ``0%``) is zero.

    A stroke of width zero paints nothing (SVG 1.1 §11.4, ``stroke-width``: "A zero value
    causes no stroke to be painted"; SVG 2 §13.5.4). Absent, negative or not a length: no
    (a negative width is an error viewers draw differently; the shape is kept).
    """
    return value is not None and _ZERO_WIDTH.fullmatch(str(value)) is not None


def flattened(matrix: Any) -> bool:
    """Whether a shape's transform is not invertible: ``scale(0, 1)``, ``matrix(1 1 1 1 0 0)``.

    ``matrix``: svgelements' ``Matrix`` of the shape, its groups' transforms included.

    Such a shape is not displayed (CSS Transforms 1 §6, "The Transform Rendering Model":
    an object whose transformation matrix is non-invertible does not get displayed), though
    its points still exist, folded onto a line. Singular: ``|ad - bc|`` at most 10⁻¹⁴ of
    the largest of ``a``, ``b``, ``c``, ``d`` squared (the rounding of a product of
    transforms that is singular in exact arithmetic, such as ``rotate(10) matrix(1 2 2 4 0 0)
    rotate(20)``, whose determinant comes out 4.4e-16).
    """
    a, b, c, d = (float(matrix.a), float(matrix.b), float(matrix.c), float(matrix.d))
    size = max(abs(a), abs(b), abs(c), abs(d))
    if not 0.0 < size < math.inf:  # NaN or infinite: refused where the points are checked
        return size == 0.0
    a, b, c, d = a / size, b / size, c / size, d / size  # no overflow for scale(1e200)
    return not abs(a * d - b * c) > 1e-14


def unpainted(color: Any) -> bool:
    """Whether a shape's ``fill`` or ``stroke`` (svgelements' Color) paints nothing.

    ``none``, or an alpha of 0: ``transparent``, ``rgba(…, 0)``, ``#RRGGBB00``, or a
    ``fill-opacity``/``stroke-opacity`` of 0, which svgelements folds into the colour.
    """
    return color is None or color.value is None or color.alpha == 0


def _unstroked(shape: Any) -> bool:
    """Whether a shape's stroke paints nothing.

    It has no paint (:func:`unpainted`), or a ``stroke-width`` of zero, its own or
    inherited (:func:`zero_width`).
    """
    return unpainted(shape.stroke) or zero_width(shape.values.get("stroke-width"))


def unseen_fill(shape: Any) -> bool:
    """Whether a shape is filled white without a stroke: unseen on the white page."""
    fill = shape.fill
    white = not unpainted(fill) and (fill.red, fill.green, fill.blue) == (255, 255, 255)
    return white and _unstroked(shape)


def open_fills(shape: Any, contours: list[Contour]) -> list[Contour]:
    """The open contours of ``shape`` whose fill a viewer paints as if they were closed.

    A fill closes each open subpath with a straight line from its end to its start (SVG 1.1
    §11.3: "The fill operation implicitly closes open subpaths"; SVG 2 §13.3), so a viewer
    shows a region whose edge camtool, cutting the subpath as drawn, cuts only in part.
    None for a shape without a visible fill (:func:`unpainted`) or a ``<line>``, nor for a
    contour of one line, whose fill has no area (Inkscape's straight lines that kept a fill
    colour).
    """
    if isinstance(shape, se.SimpleLine) or unpainted(shape.fill):
        return []
    return [
        c
        for c in contours
        if not c.closed and (len(c.segments) > 1 or not isinstance(c.segments[0], Line))
    ]


def open_fills_warning(path: object, count: int, first: str) -> str:
    """The warning for ``count`` contours :func:`open_fills` found, the first labelled ``first``."""
    noun, verb, it = ("subpath", "is", "it") if count == 1 else ("subpaths", "are", "each")
    return (
        f"{path}: {count} filled open {noun} (first: {first}) {verb} cut as drawn, open, while "
        f"a viewer fills {it} as if a line joined its end to its start: close the path (Z) in "
        "the drawing program to cut the whole edge of the fill, or give it fill:none"
    )


def filter_of(shape: Any) -> str | None:
    """The id of the ``<filter>`` a shape is drawn through (its own or a group's), or ``None``.

    A filter changes what a viewer shows of the shape (Filter Effects 1: a blur, a shadow,
    ``feOffset`` moving it, ``feMorphology`` growing or shrinking it, a flood over it),
    while camtool cuts the shape's own outline.
    """
    match = URL_REF.fullmatch(str(shape.values.get("filter") or ""))
    return match.group(1) if match else None


def filtered_warning(path: object, count: int, first: str, name: str) -> str:
    """The warning for ``count`` shapes drawn through a filter, the first ``first``."""
    noun = "shape" if count == 1 else "shapes"
    return (
        f"{path}: {count} {noun} drawn through a filter (first: {first}, filter #{name}) cut "
        "along their own outline, not as the filter shows them (blurred, shadowed, moved by "
        "an offset, grown or shrunk); check the preview, or remove the filter in the drawing "
        "program (Inkscape: Filters > Remove Filters)"
    )
