"""SVG importer: paths and basic shapes become contours in mm, Y up, arcs exact.

Built on svgelements (https://github.com/meerk40t/svgelements), which resolves CSS (``style``
attributes and ``<style>`` sheets), ``<use>``, nested transforms and every path command
(M L H V C S Q T A Z, absolute and relative, with ``S``/``T`` control-point reflection) into
segments. Around it, :mod:`camtool.importers.svgdoc` reads the page size and viewBox
exactly, checks syntax, selects Inkscape layers and counts what is skipped (with
:mod:`camtool.importers.svgtree`), and
:mod:`camtool.importers.svgcurves` maps each segment to mm: circular arcs (after the full
transform) become exact :class:`~camtool.model.shapes.Arc` objects, Béziers and elliptical arcs
are biarc-fitted within the tolerance.

Rules (docs/importers/svg.md for the user's view):

- ``<path>``, ``<rect>`` (rounded corners too), ``<circle>``, ``<ellipse>``, ``<line>``,
  ``<polyline>`` and ``<polygon>`` are read, whether filled, stroked or both; each subpath
  is one contour (each M starts one; Z closes it; so does ending on the start point).
- Not drawn, so not cut: ``display:none`` (also on a layer: a warning says so),
  ``visibility:hidden``/``collapse``, and shapes with neither fill nor stroke (a warning
  counts them).
- Contour.layer is the innermost Inkscape layer's name (``"0"`` outside any layer);
  Contour.source names the element: ``path#id`` or ``path[3]`` (the third ``<path>``), with
  ``use#u1 > path#p`` for a clone and `` subpath 2`` when an element has several.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import svgelements as se

from camtool.geometry.arcfit import check_tolerance
from camtool.importers import ImportOptions
from camtool.importers.svgcurves import Affine, affine_of, compose, convert
from camtool.importers.svgdoc import Prepared, prepare
from camtool.importers.svgtree import LAYER_ATTR, SOURCE_ATTR, USE_ATTR
from camtool.model.errors import GeometryError, InputError
from camtool.model.shapes import Contour, Drawing

DEFAULT_LAYER = "0"
"""Contour.layer of shapes outside any Inkscape layer (the DXF default layer's name)."""

_SHAPES = (se.Path, se.Rect, se.Circle, se.Ellipse, se.SimpleLine, se.Polyline, se.Polygon)


def read_svg(path: str | Path, options: ImportOptions | None = None) -> Drawing:
    """Read an SVG file into a drawing in mm, Y up.

    The page's bottom-left corner is the origin. ``width``/``height`` in mm, cm, in, pt,
    pc or px (1/96 in) with a ``viewBox`` set the scale; without an absolute size user units
    are px, with a warning.

    Args:
        path: the SVG file.
        options: ``layers`` (Inkscape layer labels or ids; hidden layers named here are read)
            and ``tolerance`` (mm, for Béziers and ellipses) are used; ``units`` does not
            apply (SVG files carry their own units).

    Returns:
        One contour per drawn subpath, and the warnings a user should see (assumed units,
        skipped elements by kind and count, hidden layers).

    Raises:
        UsageError: ``options.tolerance`` is not a positive number.
        InputError: the file is missing, malformed (XML, path data, transform, length,
            points, size, viewBox; the message names the element), names an unknown layer
            (the message lists the layers) or draws nothing.
    """
    path = Path(path)
    options = options or ImportOptions()
    check_tolerance(options.tolerance)
    prepared = prepare(path, options.layers, max_entities=options.max_entities)
    svg = _parse(path, prepared)
    warnings = list(prepared.warnings)
    contours: list[Contour] = []
    hidden = invisible = 0
    for shape in _shapes(svg):
        values = shape.values
        if str(values.get("visibility", "visible")).strip().lower() in ("hidden", "collapse"):
            hidden += 1
        elif _none(values.get("fill")) and _none(values.get("stroke")):
            invisible += 1
        else:
            contours.extend(_contours(path, shape, prepared.matrix, options.tolerance))
    if hidden:
        warnings.append(f"{path}: skipped {hidden} {_elements(hidden)} with visibility:hidden")
    if invisible:
        noun = _elements(invisible)
        warnings.append(f"{path}: skipped {invisible} {noun} with neither fill nor stroke")
    if not contours:
        where = " in the selected layers" if options.layers else ""
        raise InputError(
            f"{path}: nothing to cut{where}; camtool reads path, rect, circle, ellipse, "
            "line, polyline and polygon elements that are drawn"
        )
    return Drawing(tuple(contours), str(path), tuple(warnings))


def _parse(path: Path, prepared: Prepared) -> Any:
    width, height = prepared.viewport
    try:
        return se.SVG.parse(
            io.BytesIO(prepared.data), reify=False, ppi=96.0, width=width, height=height
        )
    except (ValueError, TypeError, IndexError, KeyError, ZeroDivisionError) as exc:
        raise InputError(f"{path}: svgelements cannot read this SVG ({exc!r})") from exc


def _shapes(node: Any) -> Iterator[Any]:
    """Drawn shapes under ``node`` in document order (groups, ``<svg>``, ``<use>`` clones)."""
    for child in node:
        if isinstance(child, _SHAPES):
            yield child
        elif isinstance(child, se.Group | se.Use):
            yield from _shapes(child)


def _none(paint: Any) -> bool:
    return paint is None or str(paint).strip().lower() == "none"


def _elements(count: int) -> str:
    return "element" if count == 1 else "elements"


def _contours(path: Path, shape: Any, page: Affine, tolerance: float) -> list[Contour]:
    values = shape.values
    label = str(values.get(SOURCE_ATTR, type(shape).__name__.lower()))
    use = values.get(USE_ATTR)
    if use and use != label:
        label = f"{use} > {label}"
    layer = str(values.get(LAYER_ATTR, DEFAULT_LAYER))
    m = compose(page, affine_of(shape.transform))
    try:
        subpaths = convert(shape.segments(transformed=False), m, tolerance)
    except (GeometryError, InputError) as exc:
        raise InputError(f"{path}: {label}: {exc}") from exc
    many = len(subpaths) > 1
    return [
        Contour(segs, closed, layer, f"{label} subpath {k}" if many else label)
        for k, (segs, closed) in enumerate(subpaths, start=1)
    ]
