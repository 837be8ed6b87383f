"""SVG document pass before geometry: XML, page units, layers, what is skipped, syntax checks.

The SVG importer reads geometry with svgelements (CSS, ``<use>``, transforms); this module
prepares the document for it with the standard library's XML parser and decides what
svgelements is not asked to decide:

- the page: ``width``/``height`` (mm, cm, in, pt, pc, px; px = 1/96 in) and ``viewBox``
  with ``preserveAspectRatio`` give one affine map from user units to mm with Y up (the page's
  bottom-left corner is the origin). These root attributes are then removed, so svgelements
  works in user units; its own unit factors are rounded (0.0393701 in/mm).
- Inkscape layers and what is not drawn (:mod:`camtool.importers.svgtree`); with a layer
  selection, unselected content is moved into a ``<defs>`` (not drawn, still usable by
  ``<use>``) and the selected layers are shown even if hidden.
- what is skipped, counted per kind: ``<defs>`` with content, ``<clipPath>``, ``<mask>``,
  ``<text>`` (and Inkscape's ``<flowRoot>``), ``<image>``, ``<use>`` of a ``<symbol>`` with
  a ``viewBox``.
- syntax: path data, transforms, lengths and point lists are checked strictly
  (:mod:`camtool.importers.svgcheck`); every element gets a source label (``path#id`` or
  ``path[3]``, the third ``<path>`` in document order) and its layer as private attributes.

Sources: SVG 1.1 §7.2 and §7.8 (viewport, viewBox, preserveAspectRatio), §4.2 (lengths).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from camtool.importers import MAX_ENTITIES, svgcheck
from camtool.importers.svgcurves import Affine
from camtool.importers.svgtree import (
    SOURCE_ATTR,
    SVG_NS,
    USE_ATTR,
    check_size,
    check_use_cycles,
    count_skipped,
    hold_undrawn,
    local_name,
    select_layers,
)
from camtool.model.errors import InputError
from camtool.model.units import LENGTH_UNITS, PX

_LENGTH_ATTRS = {
    "rect": ("x", "y", "width", "height", "rx", "ry"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
    "line": ("x1", "y1", "x2", "y2"),
}
_SIZES = frozenset({"width", "height", "r", "rx", "ry"})
_PAGE_UNITS_MM = {**{u: LENGTH_UNITS[u] for u in ("mm", "cm", "in", "pt", "px")}, "pc": 25.4 / 6}
_SKIP_REASONS = {
    "defs": "definitions are cut only where a <use> places them",
    "clipPath": "clipping is not applied: clipped shapes are cut whole",
    "mask": "masks are not applied",
    "text": "convert text to paths in the drawing program to cut it",
    "image": "raster images cannot be cut",
    "use": "a <use> of a <symbol> with a viewBox is not supported; unlink the clone",
}


@dataclass(frozen=True)
class Prepared:
    """An SVG document made ready for svgelements.

    Attributes:
        data: the document as XML bytes, root size attributes removed, labels added.
        matrix: user units to mm, Y up (the page's bottom-left corner at the origin).
        viewport: ``(width, height)`` in user units, for percentage lengths.
        warnings: messages for the user (assumed units, skipped elements, hidden layers).
    """

    data: bytes
    matrix: Affine
    viewport: tuple[float, float]
    warnings: tuple[str, ...]


def prepare(
    path: Path, layers: tuple[str, ...] | None, *, max_entities: int = MAX_ENTITIES
) -> Prepared:
    """Read, check and prepare the SVG file at ``path`` (see the module docstring).

    Args:
        path: the SVG file.
        layers: Inkscape layer names (labels or ids) to keep; ``None`` keeps everything.
        max_entities: most elements the document may expand to, ``<use>`` clones
            included (:func:`camtool.importers.svgtree.check_size`).

    Raises:
        InputError: the file is missing, is not well-formed XML, is not an SVG document,
            has malformed path data, transforms, lengths, points, size or viewBox, a
            name in ``layers`` matches no layer (the message lists the layers there are),
            a ``<use>`` that places itself, nesting deeper than
            :data:`~camtool.importers.svgtree.MAX_DEPTH` or more than ``max_entities``
            elements.
    """
    root = _parse(path)
    warnings: list[str] = []
    matrix, viewport = page_matrix(root, str(path), warnings)
    parents = {child: parent for parent in root.iter() for child in parent}
    _label_and_check(root, str(path))
    check_use_cycles(root, str(path))
    check_size(root, str(path), max_entities)
    hold = ET.SubElement(root, _tag(root, "defs"))
    parents[hold] = root
    counts: Counter[str] = Counter()
    select_layers(root, layers, parents, hold, str(path), warnings)
    hold_undrawn(root, parents, hold, counts)
    count_skipped(root, hold, counts)
    for kind in ("defs", "clipPath", "mask", "text", "image", "use"):
        if counts[kind]:
            noun = "element" if counts[kind] == 1 else "elements"
            reason = _SKIP_REASONS[kind]
            warnings.append(f"{path}: skipped {counts[kind]} <{kind}> {noun} ({reason})")
    return Prepared(ET.tostring(root), matrix, viewport, tuple(warnings))


def _tag(root: ET.Element, name: str) -> str:
    return f"{{{SVG_NS}}}{name}" if root.tag.startswith("{") else name


def _parse(path: Path) -> ET.Element:
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        line, column = exc.position
        raise InputError(
            f"{path}: malformed XML at line {line}, column {column + 1} ({exc}); is it an SVG file?"
        ) from exc
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc})") from exc
    except LookupError as exc:  # <?xml encoding="..."?> names no codec Python knows
        raise InputError(
            f"{path}: the XML declaration names an {exc}; save the file as UTF-8"
        ) from exc
    if local_name(root) != "svg":
        raise InputError(f"{path}: not an SVG document (the root element is <{root.tag}>)")
    return root


# ---------------------------------------------------------------------------- page


def page_matrix(
    root: ET.Element, name: str, warnings: list[str]
) -> tuple[Affine, tuple[float, float]]:
    """Map from user units to mm, Y up, and the viewport size in user units.

    Removes ``width``, ``height``, ``viewBox``, ``preserveAspectRatio``, ``x`` and ``y`` from
    ``root``. Without an absolute ``width`` and ``height`` (missing, or in %) the user unit
    is the px (1/96 in), with a warning; with a viewBox, one missing side is taken from the
    viewBox's aspect ratio. Without a page height the Y flip is about the user-unit origin.

    Raises:
        InputError: a malformed size or viewBox, or a size in a unit with no physical length.
    """
    width, width_text = _page_length(root, "width", name)
    height, height_text = _page_length(root, "height", name)
    box = _viewbox(root, name)
    if box is not None and width is not None and height is None:
        height = width * box[3] / box[2]
    elif box is not None and height is not None and width is None:
        width = height * box[2] / box[3]
    if width is None and height is None:
        relative = [t for t in (width_text, height_text) if t]
        what = f"relative size {' x '.join(relative)}" if relative else "no width/height"
        warnings.append(f"{name}: {what}; user units taken as px (1/96 in)")
    if box is None:
        sx = sy = PX
        tx = ty = 0.0
        viewport = (width / PX, height / PX) if width and height else (1000.0, 1000.0)
    elif width is None or height is None:
        sx = sy = PX
        tx, ty = -box[0] * PX, -box[1] * PX
        height = box[3] * PX
        viewport = (box[2], box[3])
    else:
        sx, sy, tx, ty = _fit_viewbox(width, height, box, root.get("preserveAspectRatio"), name)
        viewport = (box[2], box[3])
    for attr in ("width", "height", "viewBox", "preserveAspectRatio", "x", "y"):
        root.attrib.pop(attr, None)
    top = height if height is not None else 0.0
    return (sx, 0.0, 0.0, -sy, tx, top - ty), viewport


def _page_length(root: ET.Element, attr: str, name: str) -> tuple[float | None, str]:
    """``(mm, "")`` for an absolute length, ``(None, text)`` for a % one, else ``(None, "")``."""
    text = root.get(attr)
    if text is None or text.strip() in ("", "auto"):
        return None, ""
    match = re.fullmatch(r"\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([a-zA-Z%]*)\s*", text)
    if match is None:
        raise InputError(f"{name}: <svg> {attr} {text!r} is not a length")
    value, unit = float(match.group(1)), match.group(2)
    if unit == "%":
        return None, f"{attr}={text.strip()!r}"
    if unit and unit not in _PAGE_UNITS_MM:
        known = ", ".join(_PAGE_UNITS_MM)
        raise InputError(f"{name}: <svg> {attr} {text!r}: unit {unit!r} unknown; use {known}")
    if value <= 0:
        raise InputError(f"{name}: <svg> {attr} {text!r} must be positive")
    return value * _PAGE_UNITS_MM[unit or "px"], ""


def _viewbox(root: ET.Element, name: str) -> tuple[float, float, float, float] | None:
    text = root.get("viewBox")
    if text is None:
        return None
    try:
        x, y, w, h = (float(v) for v in re.split(r"[\s,]+", text.strip()))
    except ValueError:
        raise InputError(f"{name}: viewBox {text!r} must be four numbers") from None
    if not (w > 0 and h > 0):
        raise InputError(f"{name}: viewBox {text!r} must have a positive width and height")
    return (x, y, w, h)


def _fit_viewbox(
    width: float,
    height: float,
    box: tuple[float, float, float, float],
    aspect: str | None,
    name: str,
) -> tuple[float, float, float, float]:
    """``(sx, sy, tx, ty)``: user units to mm, Y down (SVG 1.1 §7.8 preserveAspectRatio)."""
    words = (aspect or "xMidYMid meet").split()
    if words and words[0] == "defer":
        words = words[1:]
    align = words[0] if words else "xMidYMid"
    mode = words[1] if len(words) > 1 else "meet"
    aligns = {"none"} | {f"x{a}Y{b}" for a in ("Min", "Mid", "Max") for b in ("Min", "Mid", "Max")}
    if align not in aligns or mode not in ("meet", "slice") or len(words) > 2:
        raise InputError(f"{name}: preserveAspectRatio {aspect!r} is not valid")
    sx, sy = width / box[2], height / box[3]
    if align != "none":
        sx = sy = min(sx, sy) if mode == "meet" else max(sx, sy)
    share = {"Min": 0.0, "Mid": 0.5, "Max": 1.0}
    fx = share[align[1:4]] if align != "none" else 0.0
    fy = share[align[5:8]] if align != "none" else 0.0
    tx = -box[0] * sx + fx * (width - box[2] * sx)
    ty = -box[1] * sy + fy * (height - box[3] * sy)
    return sx, sy, tx, ty


# ---------------------------------------------------------------------------- labels, checks


def _label_and_check(root: ET.Element, name: str) -> None:
    seen: Counter[str] = Counter()
    for element in root.iter():
        kind = local_name(element)
        if kind is None:
            continue
        seen[kind] += 1
        ident = element.get("id")
        label = f"{kind}#{ident}" if ident else f"{kind}[{seen[kind]}]"
        element.set(SOURCE_ATTR, label)
        if kind == "use":
            element.set(USE_ATTR, label)
        try:
            _check(element, kind)
        except ValueError as exc:
            raise InputError(f"{name}: {label}: {exc}") from exc


def _check(element: ET.Element, kind: str) -> None:
    transform = element.get("transform")
    if transform is not None:
        try:
            svgcheck.check_transform(transform)
        except ValueError as exc:
            raise ValueError(f"bad transform {transform!r}: {exc}") from exc
    if kind == "path" and element.get("d") is not None:
        try:
            svgcheck.check_path_data(element.get("d", ""))
        except ValueError as exc:
            raise ValueError(f"bad path data: {exc}") from exc
    if kind == "path" and element.get("d") is None:
        element.set("d", "")  # no path data: nothing drawn (svgelements fails on a missing d)
    for attr in _LENGTH_ATTRS.get(kind, ()):
        value = element.get(attr)
        if value is not None:
            try:
                svgcheck.check_length(value, negative=attr not in _SIZES)
            except ValueError as exc:
                raise ValueError(f"bad {attr} {value!r}: {exc}") from exc
    if kind in ("polyline", "polygon") and element.get("points") is not None:
        svgcheck.check_points(element.get("points", ""))
