"""SVG element tree chores: Inkscape layers, what is not drawn, labels shared with svgelements.

Works on the standard library's ``xml.etree`` tree before svgelements reads it
(:mod:`camtool.importers.svgdoc` drives it):

- Inkscape layers (``<g inkscape:groupmode="layer">``) are named by ``inkscape:label``, else
  ``id``. With a selection, unselected drawn content is moved into a ``<defs>`` (the *hold*:
  not drawn, still usable by ``<use>``) and the selected layers (and their parents) are shown
  even if hidden.
- svgelements draws the children of elements it does not know (``<mask>``, ``<symbol>``,
  ``<marker>``, ``<flowRoot>``) as if they were a group, and a ``<symbol>`` placed by ``<use>``
  without its viewBox; these go into the hold too, and what is skipped is counted per kind.

Sources: SVG 1.1 §5.3 (defs), §5.5 (symbol), §14 (clipping and masking); Inkscape's SVG
extensions (``inkscape:groupmode``, ``inkscape:label``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter

from camtool.model.errors import InputError

SVG_NS = "http://www.w3.org/2000/svg"
INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
_CAMTOOL_NS = "urn:camtool:svg"
SOURCE_ATTR = f"{{{_CAMTOOL_NS}}}source"
"""Private attribute holding an element's source label (``path#id``, ``path[3]``)."""
LAYER_ATTR = f"{{{_CAMTOOL_NS}}}layer"
"""Private attribute holding a layer group's name; svgelements passes it down to shapes."""
USE_ATTR = f"{{{_CAMTOOL_NS}}}use"
"""Private attribute holding a ``<use>``'s label; svgelements passes it down to the clone."""

_GROUPMODE = f"{{{INKSCAPE_NS}}}groupmode"
_LABEL = f"{{{INKSCAPE_NS}}}label"
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
_NOT_DRAWN = frozenset(
    [
        "defs",
        "symbol",
        "marker",
        "clipPath",
        "mask",
        "pattern",
        "linearGradient",
        "radialGradient",
        "filter",
    ]
)
_HOLD_KINDS = frozenset({"symbol", "marker", "mask", "flowRoot"})


def local_name(element: ET.Element) -> str | None:
    """The tag without the SVG namespace; ``None`` for elements of other namespaces."""
    tag = element.tag
    if not isinstance(tag, str):
        return None  # comments, processing instructions
    if tag.startswith("{"):
        ns, _, name = tag[1:].partition("}")
        return name if ns == SVG_NS else None
    return tag


# ---------------------------------------------------------------------------- layers


def _layer_name(element: ET.Element) -> str:
    return element.get(_LABEL) or element.get("id") or str(element.get(SOURCE_ATTR, "g"))


def _is_layer(element: ET.Element) -> bool:
    return local_name(element) == "g" and element.get(_GROUPMODE) == "layer"


def select_layers(
    root: ET.Element,
    wanted: tuple[str, ...] | None,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    name: str,
    warnings: list[str],
) -> None:
    """Mark layers with :data:`LAYER_ATTR`; keep only ``wanted`` ones (``None``: all).

    Unselected drawn content moves into ``hold``; selected layers and their parents are
    shown. Without a selection, each hidden layer gets a warning.

    Raises:
        InputError: a name in ``wanted`` matches no layer label or id (the message lists
            the layers there are).
    """
    layers = [e for e in root.iter() if _is_layer(e)]
    for layer in layers:
        layer.set(LAYER_ATTR, _layer_name(layer))
    if wanted is None:
        for layer in layers:
            if _hidden(layer):
                warnings.append(
                    f"{name}: layer {_layer_name(layer)!r} is hidden and was skipped; "
                    "name it with --layers to cut it"
                )
        return
    names = {n: e for e in layers for n in (e.get("id"), e.get(_LABEL)) if n}
    unknown = [w for w in wanted if w not in names]
    if unknown:
        there = ", ".join(repr(_layer_name(e)) for e in layers)
        have = f"its layers are {there}" if layers else "it has no Inkscape layers"
        raise InputError(f"{name}: no layer named {', '.join(map(repr, unknown))}; {have}")
    selected = {names[w] for w in wanted}
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


def _style(element: ET.Element) -> dict[str, str]:
    pairs = (item.split(":", 1) for item in element.get("style", "").split(";") if ":" in item)
    return {k.strip(): v.strip() for k, v in pairs}


def _hidden(element: ET.Element) -> bool:
    display = _style(element).get("display", element.get("display", ""))
    return display.strip().lower() == "none"


def _show(element: ET.Element) -> None:
    if _hidden(element):
        style = {k: v for k, v in _style(element).items() if k != "display"}
        element.set(
            "style", ";".join(f"{k}:{v}" for k, v in [*style.items(), ("display", "inline")])
        )
        element.set("display", "inline")


# ---------------------------------------------------------------------------- skipped


def hold_undrawn(
    root: ET.Element, parents: dict[ET.Element, ET.Element], hold: ET.Element, counts: Counter[str]
) -> None:
    """Move what svgelements would draw by mistake into ``hold`` and count it.

    svgelements draws the children of elements it does not know (``<mask>``, ``<symbol>``,
    ``<marker>``, ``<flowRoot>``) as if they were in a group, and draws a ``<symbol>``
    placed by ``<use>`` without the symbol's viewBox.
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    for element in list(root.iter()):
        kind = local_name(element)
        bad_use = kind == "use" and _refers_to_symbol_viewbox(element, ids)
        if kind not in _HOLD_KINDS and not bad_use:
            continue
        drawn = _is_drawn(element, parents, hold)
        if kind == "mask":
            counts["mask"] += 1
        elif drawn and kind in ("flowRoot", "use"):
            counts["text" if kind == "flowRoot" else "use"] += 1
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


def _is_drawn(element: ET.Element, parents: dict[ET.Element, ET.Element], hold: ET.Element) -> bool:
    node = element
    while node in parents:
        node = parents[node]
        if node is hold or local_name(node) in _NOT_DRAWN:
            return False
    return True


def move(element: ET.Element, parents: dict[ET.Element, ET.Element], hold: ET.Element) -> None:
    """Move ``element`` from its parent into ``hold``, keeping ``parents`` up to date."""
    parent = parents.get(element)
    if parent is None or parent is hold:
        return
    parent.remove(element)
    hold.append(element)
    parents[element] = hold


def count_skipped(root: ET.Element, hold: ET.Element, counts: Counter[str]) -> None:
    """Add to ``counts`` the skipped kinds: clipPath, non-empty defs, drawn text and image."""

    def walk(node: ET.Element, drawn: bool) -> None:
        for child in node:
            kind = local_name(child)
            if child is hold or kind is None:
                continue
            if kind == "clipPath":
                counts["clipPath"] += 1
            elif kind == "defs" and any(local_name(c) not in (None, "style") for c in child):
                counts["defs"] += 1
            elif kind in ("text", "image") and drawn:
                counts[kind] += 1
                continue
            walk(child, drawn and kind not in _NOT_DRAWN)

    walk(root, True)


MAX_DEPTH = 256
"""Deepest element nesting read, ``<use>`` clones followed (drawing programs nest a few
dozen levels); deeper is refused before anything walks the tree recursively."""


def check_size(root: ET.Element, name: str, max_entities: int) -> None:
    """Refuse a document nested too deep or expanding to too many elements.

    Every element counts once per place it is drawn: a ``<use>`` counts itself plus
    what it places, so a "billion laughs" of ``<use>`` (a group cloning the previous
    one 10 times, 30 levels deep) is counted, without being expanded, as 10³⁰. Sizes
    and depths are computed once per element, bottom-up, without recursion. Call after
    :func:`check_use_cycles`.

    Raises:
        InputError: nesting deeper than :data:`MAX_DEPTH`, or more than
            ``max_entities`` elements once ``<use>`` clones are expanded (the message
            names the ``--max-entities`` option).
    """
    from camtool.importers import too_many_entities

    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    cap = max_entities + 1
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
    if size[root] > max_entities:
        raise too_many_entities(name, max_entities)
