"""SVG document pass before geometry: XML, page units, layers, what is skipped, syntax checks.

The SVG importer reads geometry with svgelements (CSS, ``<use>``, transforms); this module
prepares the document for it with the standard library's XML parser and decides what
svgelements is not asked to decide:

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py``.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import svgelements as se

from camtool.importers import svgcheck, svgvalues
from camtool.importers.options import check_expansion, entity_limit, layer_list
from camtool.importers.svgcontent import hold_unrendered
from camtool.importers.svgcss import (
    apply_style_sheets,
    inline_style,
    labelled,
    local_name,
    normalize_styles,
    style_text,
)
from camtool.importers.svgcsstransform import move_css_transform
from camtool.importers.svgmasks import (
    clip_paths_first,
    clip_viewports,
    masks_as_clips,
    symbols_as_viewports,
)
from camtool.importers.svgpage import (
    Affine,
    decoded_id,
    illustrator_version,
    page_matrix,
    top_level_layers,
)
from camtool.importers.svgskipped import count_skipped
from camtool.importers.svgtree import (
    INKSCAPE_NS,
    LAYER_ATTR,
    LIBRECAD_NS,
    NOT_DRAWN,
    SOURCE_ATTR,
    USE_ATTR,
    XLINK_HREF,
    elements,
    has_shapes,
    href,
    is_drawn,
    tag,
)
from camtool.importers.svgvalues import LENGTH_ATTRS
from camtool.importers.svgvars import resolve_variables
from camtool.model.errors import InputError, not_a_file

_GROUPMODE = f"{{{INKSCAPE_NS}}}groupmode"
_LABEL = f"{{{INKSCAPE_NS}}}label"
_LC_LAYER = f"{{{LIBRECAD_NS}}}layername"
"""LibreCAD's "Export as MakerCAM SVG" writes each layer as a ``<g lc:layername="…">``."""
_RENDERED = frozenset(
    [
        "g",
        "a",
        "switch",
        "svg",
        "use",
        "path",
        "rect",
        "circle",
        "ellipse",
        "line",
        "polyline",
        "polygon",
        "text",
        "image",
        "flowRoot",
    ]
)
_SWITCHABLE = _RENDERED | {"foreignObject"}
"""What a ``<switch>`` may show: rendered elements, not an unknown one (``<random>``)."""
_HOLD_KINDS = frozenset({"symbol", "marker", "mask", "flowRoot"})


# ---------------------------------------------------------------------------- layers


def _layer_name(element: ET.Element) -> str:
    return (
        element.get(_LABEL)
        or element.get(_LC_LAYER)
        or element.get("data-name")
        or decoded_id(element.get("id"))
        or str(element.get(SOURCE_ATTR, "g"))
    )


def _layer_names(layer: ET.Element) -> set[str]:
    """The names ``--layers`` and a job's operations select ``layer`` by: label and id.

    An Illustrator or CorelDRAW layer also by its ``data-name`` and by its ``id`` with the
    characters an id cannot hold written back (``Layer_x0020_1`` is ``Layer 1``).
    """
    names = (
        layer.get(_LABEL),
        layer.get(_LC_LAYER),
        layer.get("data-name"),
        layer.get("id"),
        decoded_id(layer.get("id")),
    )
    return {n for n in names if n}


def _is_layer(element: ET.Element) -> bool:
    """An Inkscape layer, or a LibreCAD one (:data:`_LC_LAYER`)."""
    return local_name(element) == "g" and (
        element.get(_GROUPMODE) == "layer" or bool(element.get(_LC_LAYER))
    )


def _layers(root: ET.Element, top_level: bool) -> list[ET.Element]:
    """The document's layers: Inkscape's and LibreCAD's marked groups.

    Without them, in a file of a program whose layers are the root's groups
    (``top_level``, :func:`~camtool.importers.svgpage.top_level_layers`), the ``<g>``
    children of the ``<svg>`` element that have an ``id``.
    """
    layers = [e for e in root.iter() if _is_layer(e)]
    if layers or not top_level:
        return layers
    return [e for e in root if local_name(e) == "g" and e.get("id")]


def select_layers(
    root: ET.Element,
    wanted: tuple[str, ...] | None,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    name: str,
    warnings: list[str],
    shown: tuple[str, ...] = (),
    *,
    top_level: bool = False,
) -> None:
    """Mark layers with :data:`LAYER_ATTR`; keep only ``wanted`` ones (``None``: all).

    ``top_level``: the file is of a program whose layers are the root's groups
    (:func:`_layers`).

    Unselected drawn content moves into ``hold``; selected layers and their parents are
    shown. Without a selection, a hidden layer named in ``shown`` (by a job's operation,
    in any case) is shown with its parents, and each other hidden layer gets a warning.

    Raises:
        InputError: a name in ``wanted`` matches no layer label or id (the message lists
            the layers there are).
    """
    layers = _layers(root, top_level)
    for layer in layers:
        layer.set(LAYER_ATTR, _layer_name(layer))
    if wanted is None:
        named = {n.casefold() for n in shown}
        for layer in layers:
            if named & {n.casefold() for n in _layer_names(layer)}:
                node: ET.Element | None = layer
                while node is not None:
                    _show(node)
                    node = parents.get(node)
            elif _hidden(layer):
                warnings.append(
                    f"{name}: layer {_layer_name(layer)!r} is hidden and was skipped; "
                    "name it with --layers to cut it"
                )
        return
    names: dict[str, list[ET.Element]] = {}  # labels repeat: "Cut" in each part's layer
    for layer in layers:
        for label in _layer_names(layer):
            names.setdefault(label, []).append(layer)
    unknown = [w for w in wanted if w not in names]
    if unknown:
        there = layer_list([_layer_name(e) for e in layers])
        have = f"its layers are {there}" if layers else "it has no Inkscape layers"
        raise InputError(f"{name}: no layer named {', '.join(map(repr, unknown))}; {have}")
    selected = {layer for w in wanted for layer in names[w]}
    ancestors: set[ET.Element] = set()
    for layer in selected:
        node = layer
        while node in parents:
            node = parents[node]
            ancestors.add(node)
    _prune(root, selected, ancestors, parents, hold)


def _prune(
    node: ET.Element,
    selected: set[ET.Element],
    ancestors: set[ET.Element],
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
) -> None:
    for child in list(node):
        if child in selected or child in ancestors:
            _show(child)
            if child in ancestors:
                _prune(child, selected, ancestors, parents, hold)
        elif child is not hold and local_name(child) in _RENDERED:
            move(child, parents, hold)


def _hidden(element: ET.Element) -> bool:
    display = inline_style(element).get("display", element.get("display", ""))
    return display.strip().lower() == "none"


def _set_style(element: ET.Element, name: str, value: str) -> None:
    """Set ``name`` to ``value`` in ``element``'s style and its attribute (both say the same)."""
    style = {k: v for k, v in inline_style(element).items() if k != name}
    element.set("style", style_text({**style, name: value}))
    element.set(name, value)


def _show(element: ET.Element) -> None:
    if _hidden(element):
        _set_style(element, "display", "inline")


_OPACITY = re.compile(r"(?:^|;)\s*opacity\s*:\s*([^;]*)", re.IGNORECASE)


def zero_opacity(value: object) -> bool:
    """Whether an ``opacity`` value (``0``, ``0.0``, ``0%``) is 0; absent or not a number: no."""
    text = "" if value is None else str(value).strip()
    try:
        return (float(text[:-1]) / 100.0 if text.endswith("%") else float(text)) <= 0.0
    except ValueError:
        return False


def fade_under_transparent(root: ET.Element) -> None:
    """Give every element under an ``opacity:0`` element opacity 0 too.

    A group at opacity 0 shows nothing, whatever its children's own opacity; svgelements
    passes a group's ``opacity`` down only to children that set none, so a child with
    ``opacity="1"`` would be drawn, and cut. Its own value is replaced by 0 (the SVG
    importer then skips it as invisible and counts it).
    """
    stack = list(root)
    while stack:  # each subtree under an opacity-0 element is walked once, not per level
        element = stack.pop()
        style = element.get("style", "")
        found = _OPACITY.findall(style) if "opacity" in style else []  # a style's wins, its last
        if not zero_opacity(found[-1] if found else element.get("opacity")):
            stack.extend(element)
            continue
        for inner in element.iter():
            if inner is not element and (
                "opacity" in inner.attrib or "opacity" in inline_style(inner)
            ):
                _set_style(inner, "opacity", "0")


# ---------------------------------------------------------------------------- skipped


def hold_undrawn(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    counts: Counter[str],
    placed: frozenset[str] = frozenset(),
) -> None:
    """Move what svgelements would draw by mistake into ``hold`` and count it.

    svgelements draws the children of elements it does not know (``<mask>``, ``<symbol>``,
    ``<marker>``, ``<flowRoot>``) as if they were in a group, and draws a ``<symbol>``
    placed by ``<use>`` without the symbol's viewBox. A ``<symbol>`` whose id is not in
    ``placed`` (the ids the document's ``<use>`` elements named) is counted (``symbol``):
    a viewer draws a symbol only where a ``<use>`` places it, and Inkscape's symbol
    libraries are files of nothing else.
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    for element in list(root.iter()):
        kind = local_name(element)
        bad_use = kind == "use" and _refers_to_symbol_viewbox(element, ids)
        if kind not in _HOLD_KINDS and not bad_use:
            continue
        drawn = is_drawn(element, parents, hold)
        if kind == "mask":
            counts["mask"] += 1
        elif drawn and kind in ("flowRoot", "use"):
            counts["text" if kind == "flowRoot" else "use"] += 1
        elif kind == "symbol" and element.get("id") not in placed:
            counts["symbol"] += 1
        if drawn or kind != "use":
            move(element, parents, hold)


def check_use_cycles(root: ET.Element, name: str) -> None:
    """Refuse ``<use>`` elements that place themselves (directly or through other uses).

    Raises:
        InputError: a cycle, naming the ``<use>`` where it closes (SVG 1.1 §5.6: "an error").
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    uses = [e for e in root.iter() if local_name(e) == "use"]
    graph: dict[ET.Element, list[ET.Element]] = {}
    for use in uses:
        href = use.get(XLINK_HREF) or use.get("href") or ""
        target = ids.get(href[1:]) if href.startswith("#") else None
        graph[use] = [] if target is None else [e for e in target.iter() if local_name(e) == "use"]
    done: set[ET.Element] = set()
    for start in uses:
        if start in done:
            continue
        path: list[ET.Element] = [start]
        todo = [iter(graph[start])]
        while todo:
            nxt = next(todo[-1], None)
            if nxt is None:
                done.add(path.pop())
                todo.pop()
            elif nxt in path:
                label = nxt.get(SOURCE_ATTR, "use")
                raise InputError(f"{name}: {label}: <use> places itself; remove the loop")
            elif nxt not in done:
                path.append(nxt)
                todo.append(iter(graph[nxt]))


def _refers_to_symbol_viewbox(use: ET.Element, ids: dict[str | None, ET.Element]) -> bool:
    href = use.get(XLINK_HREF) or use.get("href") or ""
    target = ids.get(href[1:]) if href.startswith("#") else None
    return target is not None and local_name(target) == "symbol" and "viewBox" in target.attrib


def move(element: ET.Element, parents: dict[ET.Element, ET.Element], hold: ET.Element) -> None:
    """Move ``element`` from its parent into ``hold``, keeping ``parents`` up to date."""
    parent = parents.get(element)
    if parent is None or parent is hold:
        return
    parent.remove(element)
    hold.append(element)
    parents[element] = hold


def choose_switches(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    name: str,
    counts: Counter[str],
) -> None:
    """Keep of each ``<switch>`` only the child it shows; move the others into ``hold``.

    A ``<switch>`` renders its first direct child that is a rendered element (not an
    unknown one, nor ``<title>``) whose conditions hold (SVG 1.1 §5.8, SVG 2 §5.8.1):
    ``requiredExtensions`` names extensions camtool has none of (Illustrator's
    ``<foreignObject>`` beside its artwork), ``requiredFeatures`` holds (SVG 2 dropped
    it). svgelements draws every child, so alternatives would all be cut. Alternatives
    with shapes that were dropped are counted (``counts["switch"]``).

    Raises:
        InputError: a child with shapes chooses by ``systemLanguage``: which one the user
            sees depends on the viewer's language, which camtool cannot know.
    """
    for switch in elements(root, "switch"):
        children = [c for c in switch if isinstance(c.tag, str)]
        drawn = is_drawn(switch, parents, hold)  # else placed by a <use>, or not at all
        for child in children:
            if child.get("systemLanguage") is not None and has_shapes(child):
                where = child.get(SOURCE_ATTR) or local_name(child) or "an element"
                raise InputError(
                    f"{name}: a <switch> shows {where} or another child by the viewer's "
                    f'language (systemLanguage="{child.get("systemLanguage")}"), which camtool '
                    "cannot know; keep one of them in the drawing program"
                )
        shown = next(
            (
                c
                for c in children
                if local_name(c) in _SWITCHABLE and not (c.get("requiredExtensions") or "").strip()
            ),
            None,
        )
        for child in children:
            if child is not shown:
                if drawn and has_shapes(child):
                    counts["switch"] += 1
                move(child, parents, hold)


def check_conditions(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    name: str,
    counts: Counter[str],
) -> None:
    """Apply ``requiredExtensions`` and ``systemLanguage`` outside a ``<switch>`` too.

    Any element whose conditions fail is not rendered, with its children (SVG 1.1 §5.8.2,
    SVG 2 §5.8): one that requires extensions (camtool has none) goes into ``hold`` and is
    counted (``counts["extensions"]``). Run after :func:`choose_switches`.

    Raises:
        InputError: an element with shapes, or the ``<svg>`` itself, is shown by the
            viewer's language (``systemLanguage``), which camtool cannot know; or the
            ``<svg>`` requires extensions, so nothing is shown.
    """
    stack = [root]
    while stack:
        element = stack.pop()
        if element is hold or local_name(element) in NOT_DRAWN:  # clip paths are not cut
            continue
        where = element.get(SOURCE_ATTR) or local_name(element) or "an element"
        language = element.get("systemLanguage")
        if language is not None and has_shapes(element):
            raise InputError(
                f"{name}: {where} is shown only to viewers whose language is {language!r} "
                "(systemLanguage), which camtool cannot know; remove the attribute to cut "
                "it, or delete the element"
            )
        if (element.get("requiredExtensions") or "").strip():
            if element is root:
                raise InputError(
                    f"{name}: nothing to cut: the <svg> element requires extensions "
                    f"(requiredExtensions={element.get('requiredExtensions')!r}) that no "
                    "viewer without them shows"
                )
            if has_shapes(element):
                counts["extensions"] += 1
            move(element, parents, hold)
            continue
        stack.extend(element)


MAX_DEPTH = 256
"""Deepest element nesting read, ``<use>`` clones followed (drawing programs nest a few
dozen levels); deeper is refused before anything walks the tree recursively."""


def check_size(root: ET.Element, name: str, max_entities: int | None) -> None:
    """Refuse a document nested too deep or expanding to too many elements.

    Every element counts once per place it is drawn: a ``<use>`` counts itself plus
    what it places, so a "billion laughs" of ``<use>`` (a group cloning the previous
    one 10 times, 30 levels deep) is counted, without being expanded, as 10³⁰. Sizes
    and depths are computed once per element, bottom-up, without recursion. Call after
    :func:`check_use_cycles`.

    Raises:
        InputError: nesting deeper than :data:`MAX_DEPTH`, or too many elements once
            ``<use>`` clones are expanded (:func:`~camtool.importers.options.check_expansion`
            of ``max_entities``; the message names the ``--max-entities`` option).
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    cap = entity_limit(max_entities) + 1
    size: dict[ET.Element, int] = {}
    depth: dict[ET.Element, int] = {}

    def below(element: ET.Element) -> list[ET.Element]:
        kids = list(element)
        if local_name(element) == "use":
            href = element.get(XLINK_HREF) or element.get("href") or ""
            target = ids.get(href[1:]) if href.startswith("#") else None
            if target is not None:
                kids.append(target)
        return kids

    stack: list[tuple[ET.Element, list[ET.Element]]] = [(root, below(root))]
    size[root] = 0  # in progress
    while stack:
        element, kids = stack[-1]
        if kids:
            kid = kids.pop()
            if kid not in size:
                size[kid] = 0
                stack.append((kid, below(kid)))
            continue
        stack.pop()
        kids = below(element)
        size[element] = min(cap, 1 + sum(size[k] for k in kids))
        depth[element] = 1 + max((depth.get(k, 0) for k in kids), default=0)
        if depth[element] > MAX_DEPTH:
            label = element.get(SOURCE_ATTR, local_name(element) or "element")
            raise InputError(
                f"{name}: {label}: elements nested deeper than {MAX_DEPTH} levels "
                "(<use> clones followed); flatten the groups in the drawing program"
            )
    check_expansion(name, size[root], len(size), max_entities, "<use> clones")


_SIZES = frozenset({"width", "height", "r", "rx", "ry"})
_SKIP_REASONS = {
    "defs": "definitions are cut only where a <use> places them",
    "symbol": "no <use> places them, and a symbol is drawn and cut only where one does",
    "mask": "a mask is not cut: what it hides is checked where it is used",
    "text": "convert text to paths in the drawing program to cut it",
    "image": "raster images cannot be cut",
    "use": "a <use> of a <symbol> with a viewBox is not supported; unlink the clone",
    "marker": "a viewer draws the shapes of its markers at its vertices; camtool cuts the "
    "shape only: Inkscape's Path > Stroke to Path makes them paths",
    "pattern": "a viewer fills them with the pattern's lines or shapes; camtool cuts the "
    "outline only: Inkscape's Object > Pattern > Pattern to Objects makes them shapes",
}


@dataclass(frozen=True)
class Prepared:
    """An SVG document made ready for svgelements.

    Attributes:
        data: the document as XML bytes, root size attributes removed, labels added.
        matrix: user units to mm, Y up (the page's bottom-left corner at the origin).
        viewport: ``(width, height)`` in user units, for percentage lengths.
        warnings: messages for the user (assumed units, skipped elements, hidden layers).
        page: ``(width, height)`` of the page in mm, from the origin of ``matrix``'s
            output; ``None`` when the document has neither a size nor a viewBox.
    """

    data: bytes
    matrix: Affine
    viewport: tuple[float, float]
    warnings: tuple[str, ...]
    page: tuple[float, float] | None = None


def prepare(
    path: Path,
    layers: tuple[str, ...] | None,
    *,
    max_entities: int | None = None,
    units: str | None = None,
    shown: tuple[str, ...] = (),
) -> Prepared:
    """Read, check and prepare the SVG file at ``path`` (see the module docstring).

    Args:
        path: the SVG file.
        layers: Inkscape layer names (labels or ids) to keep; ``None`` keeps everything.
        max_entities: most elements the document may expand to, ``<use>`` clones
            included; ``None``: the defaults (:func:`check_size`).
        units: ``--units``: the user unit of a document without an absolute size.
        shown: layers read even if hidden (a job's operations name them).

    Raises:
        InputError: the file is missing, is not well-formed XML, is not an SVG document,
            has malformed path data, transforms, lengths, points, size or viewBox, a
            name in ``layers`` matches no layer (the message lists the layers there are),
            a ``<use>`` that places itself, nesting deeper than
            :data:`MAX_DEPTH` or too many elements (:func:`check_size`).
    """
    root = _parse(path)
    with path.open("rb") as file:
        head = file.read(4096)
    illustrator = illustrator_version(head)
    warnings: list[str] = []
    matrix, viewport, page = page_matrix(root, str(path), warnings, units, illustrator)
    parents = {child: parent for parent in root.iter() for child in parent}
    unapplied: set[str] = set()
    warnings += apply_style_sheets(root, parents, str(path), unapplied)
    resolve_variables(root, str(path), unapplied)
    normalize_styles(root)
    svgvalues.resolve_percentages(root, viewport)
    svgvalues.resolve_paint_references(root)
    svgvalues.resolve_context_paints(root, parents)
    svgvalues.normalize_colours(root)
    _label_and_check(root, str(path), viewport)
    _check_root_transform(root, str(path))
    check_use_cycles(root, str(path))
    check_size(root, str(path), max_entities)
    placed = frozenset(href(e)[1:] for e in root.iter() if local_name(e) == "use")
    try:
        replaced = symbols_as_viewports(root)
    except ValueError as exc:
        raise InputError(f"{path}: {exc}") from exc
    if replaced:
        svgvalues.resolve_percentages(root, viewport)  # the new viewports' sizes
        parents = {child: parent for parent in root.iter() for child in parent}
    hold = ET.SubElement(root, tag(root, "defs"))
    parents[hold] = root
    counts: Counter[str] = Counter()
    select_layers(
        root,
        layers,
        parents,
        hold,
        str(path),
        warnings,
        shown,
        top_level=top_level_layers(head, root),
    )
    choose_switches(root, parents, hold, str(path), counts)
    check_conditions(root, parents, hold, str(path), counts)
    fade_under_transparent(root)
    masks_as_clips(root, parents, hold, str(path), viewport)
    hold_undrawn(root, parents, hold, counts, placed)
    warnings += hold_unrendered(root, hold, str(path))
    count_skipped(root, hold, counts)
    if counts["use-file"]:
        warnings.append(
            f"{path}: skipped {counts['use-file']} <use> of another file's element (camtool "
            "reads one file): copy the element into this drawing to cut it"
        )
    if counts["switch"]:
        warnings.append(
            f"{path}: skipped {counts['switch']} child(ren) of <switch> elements with shapes "
            "(a <switch> shows only its first child that applies)"
        )
    if counts["extensions"]:
        warnings.append(
            f"{path}: skipped {counts['extensions']} element(s) with shapes that require "
            "extensions (requiredExtensions), which a viewer without them does not show"
        )
    clip_viewports(root, parents, hold, viewport, str(path))
    for kind in ("defs", "symbol", "mask", "text", "image", "use"):
        if counts[kind]:
            noun = "element" if counts[kind] == 1 else "elements"
            reason = _SKIP_REASONS[kind]
            warnings.append(f"{path}: skipped {counts[kind]} <{kind}> {noun} ({reason})")
    if counts["marker"]:
        noun = "shape" if counts["marker"] == 1 else "shapes"
        reason = _SKIP_REASONS["marker"]
        warnings.append(f"{path}: skipped the markers of {counts['marker']} {noun} ({reason})")
    if counts["pattern"]:
        noun = "shape" if counts["pattern"] == 1 else "shapes"
        reason = _SKIP_REASONS["pattern"]
        warnings.append(
            f"{path}: skipped the pattern fill of {counts['pattern']} {noun} ({reason})"
        )
    clip_paths_first(root)
    svgvalues.drop_gradients(root)
    return Prepared(ET.tostring(root), matrix, viewport, tuple(warnings), page)


def _parse(path: Path) -> ET.Element:
    if not path.is_file():
        raise not_a_file(path)
    try:
        if path.stat().st_size == 0:
            raise InputError(
                f"{path}: empty file; export the drawing again from the drawing program"
            )
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


# ---------------------------------------------------------------------------- labels, checks


def _label_and_check(root: ET.Element, name: str, viewport: tuple[float, float]) -> None:
    for element, kind, label in labelled(root):
        element.set(SOURCE_ATTR, label)
        if kind == "use":
            element.set(USE_ATTR, label)
        if kind in ("clipPath", "mask"):  # display does not apply to them (SVG 1.1 §14.3.5,
            _show(element)  # §14.4): a viewer clips by one even with display:none on it
        try:
            _check(element, kind, viewport)
        except ValueError as exc:
            raise InputError(f"{name}: {label}: {exc}") from exc


def _check_root_transform(root: ET.Element, name: str) -> None:
    """Refuse a ``transform`` on the ``<svg>`` element itself that moves anything.

    SVG 2 allows it, and viewers disagree on what it moves: a browser turns and moves the
    whole page with it (about the page's centre: the outermost ``<svg>`` has a CSS box,
    so its ``transform-origin`` is 50 % 50 %), svgelements the drawing on the page, other
    programs nothing. Checked after the CSS ``transform`` property became the attribute.

    Raises:
        InputError: such a transform, with where to put it instead.
    """
    text = (root.get("transform") or "").strip()
    if not text or se.Matrix(text).is_identity():
        return
    raise InputError(
        f"{name}: the <svg> element itself has transform={text!r}, which a browser applies "
        "to the whole page (turning it about its centre) and other programs to the drawing "
        "on the page or not at all, so camtool cannot tell where the drawing lies; move the "
        "attribute to a <g> around the drawing (a text editor, or Inkscape's Edit > XML "
        "Editor), or remove it"
    )


def _check(element: ET.Element, kind: str, viewport: tuple[float, float]) -> None:
    """Check ``element``'s syntax, then read what svgelements reads otherwise than SVG.

    Sizes SVG 2 gives a shape without them and ``transform-origin``
    (:mod:`camtool.importers.svgvalues`); ``viewport``: user units, for percentages.
    """
    transform = element.get("transform")
    if transform is not None:
        try:
            svgcheck.check_transform(transform)
        except ValueError as exc:
            raise ValueError(f"bad transform {transform!r}: {exc}") from exc
    if kind == "path" and element.get("d") is not None:
        try:
            element.set("d", svgcheck.check_path_data(element.get("d", "")))
        except ValueError as exc:
            raise ValueError(f"bad path data: {exc}") from exc
    if kind == "path" and element.get("d") is None:
        element.set("d", "")  # no path data: nothing drawn (svgelements fails on a missing d)
    svgvalues.default_sizes(element, kind)
    move_css_transform(element)
    svgvalues.fold_transform_origin(element, viewport)
    for attr in LENGTH_ATTRS.get(kind, ()):
        value = element.get(attr)
        if value is not None:
            try:
                svgcheck.check_length(value, negative=attr not in _SIZES)
            except ValueError as exc:
                raise ValueError(f"bad {attr} {value!r}: {exc}") from exc
    if kind == "rect":
        svgvalues.rect_radii(element)
    if kind in ("polyline", "polygon") and element.get("points") is not None:
        element.set("points", svgcheck.check_points(element.get("points", "")))


@dataclass
class Unseen:
    """Counts of the shapes a viewer shows nothing of, by why (:func:`unseen_warnings`)."""

    hidden: int = 0  # visibility:hidden or collapse
    faded: int = 0  # opacity 0
    invisible: int = 0  # neither fill nor stroke
    thin: int = 0  # a stroke of width 0, and no fill (or a <line>)
    bare: int = 0  # a <line> without a stroke
    background: int = 0  # the page's white background
    flat: int = 0  # a transform that is not invertible (scale(0), matrix(1 1 1 1 0 0))


def unseen_warnings(path: object, unseen: Unseen) -> list[str]:
    """What was skipped because a viewer shows nothing of it: one warning per kind."""
    said = []
    hidden, faded, invisible = unseen.hidden, unseen.faded, unseen.invisible
    thin, bare, background = unseen.thin, unseen.bare, unseen.background
    if hidden:
        said.append(f"{path}: skipped {hidden} {element_noun(hidden)} with visibility:hidden")
    if faded:
        said.append(f"{path}: skipped {faded} {element_noun(faded)} with opacity 0")
    if invisible:
        said.append(
            f"{path}: skipped {invisible} {element_noun(invisible)} with neither fill nor stroke"
        )
    if thin:
        said.append(
            f"{path}: skipped {thin} {element_noun(thin)} whose only paint is a stroke of "
            "stroke-width 0, which a viewer does not draw; give it a stroke width to cut it"
        )
    if bare:
        said.append(
            f"{path}: skipped {bare} <line> {element_noun(bare)} without a stroke (a line has no "
            "inside to fill, so a viewer shows nothing); give it a stroke to cut it"
        )
    if unseen.flat:
        said.append(
            f"{path}: skipped {unseen.flat} {element_noun(unseen.flat)} whose transform is not "
            "invertible (a scale of 0 on an axis, or a matrix that folds the plane onto a "
            "line), which a viewer does not draw"
        )
    if background:
        said.append(
            f"{path}: skipped the page's background: a white rectangle as large as the page, "
            "without a stroke (matplotlib, Figma and draw.io draw one), which a viewer does not "
            "show on the white page; give it a stroke to cut it"
        )
    return said


def element_noun(count: int) -> str:
    """``element`` or ``elements``, as ``count`` asks."""
    return "element" if count == 1 else "elements"
