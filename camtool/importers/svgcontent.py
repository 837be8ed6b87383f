"""Shapes placed where SVG draws none: inside text, a title, a gradient, another shape.

svgelements reads the children of every element it does not render itself as if they
stood in the enclosing group, so a ``<path>`` inside a ``<title>``, a ``<text>``, a
``<linearGradient>``, a ``<filter>``, an element of another namespace or another shape
would be cut, while a viewer shows nothing of it: SVG renders shapes only as children of
``<svg>``, ``<g>``, ``<a>`` and ``<switch>`` (SVG 1.1 §5.1, and each element's content
model; SVG 2 §5.9 for unknown elements), or where a ``<use>`` places them. This pass moves
such shapes into the document's hold, where only a ``<use>`` reaches them.

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from camtool.importers.svgcss import local_name
from camtool.importers.svgtree import NOT_DRAWN, SHAPE_KINDS, SOURCE_ATTR, has_shapes

_RENDERS_CHILDREN = frozenset({"svg", "g", "a", "switch"})
"""Elements whose shape children a viewer draws where they stand."""
_PASSED = frozenset(NOT_DRAWN - {"linearGradient", "radialGradient", "filter"})
"""Containers whose shapes are drawn only where something places them (a ``<use>``, a
clip's reference), or not at all (``<defs>``, ``<symbol>``, ``<marker>``, clips, masks,
patterns), as the hold's: their shape children stand where SVG draws shapes, and what is
placed where it draws none inside them is moved without a warning (nothing of it shows
where it stands; a ``<use>`` of its host, or the clip, would have drawn it)."""


def hold_unrendered(root: ET.Element, hold: ET.Element, name: str) -> list[str]:
    """Move what is placed where SVG draws no shapes, and holds shapes, into ``hold``.

    A shape, ``<use>`` or element holding one, whose parent is neither ``<svg>``, ``<g>``,
    ``<a>`` nor ``<switch>`` (nor one of :data:`_PASSED`, nor ``hold``).

    Args:
        root: the ``<svg>`` element.
        hold: the document's hold (a ``<defs>`` under ``root``).
        name: the file, for the warning.

    Returns:
        The warning that counts the shapes moved from where they would have been drawn
        (outside :data:`_PASSED` and ``hold``) and names the first; ``[]`` for none.
    """
    found: list[tuple[ET.Element, ET.Element, bool]] = []  # (element, its parent, drawn)
    stack = [(root, True)]
    while stack:
        node, drawn = stack.pop()
        kind = local_name(node)
        renders = kind in _RENDERS_CHILDREN
        if node is hold or kind in _PASSED:
            renders, drawn = True, False  # its shapes are drawn where something places them
        for child in node:
            if renders:
                stack.append((child, drawn))
            elif has_shapes(child):
                found.append((child, node, drawn))  # with everything inside it
    if not found:
        return []
    order = {e: i for i, e in enumerate(root.iter())}
    shown = sorted(((e, p) for e, p, drawn in found if drawn), key=lambda pair: order[pair[0]])
    for element, parent, _ in found:
        parent.remove(element)
        hold.append(element)
    if not shown:
        return []
    shapes = [e for element, _ in shown for e in element.iter() if local_name(e) in SHAPE_KINDS]
    first = shapes[0]
    host = str(shown[0][1].tag).rpartition("}")[2]
    many = f"{len(shapes)} shapes" if len(shapes) > 1 else "1 shape"
    return [
        f"{name}: skipped {many} placed where SVG draws none (first: {first.get(SOURCE_ATTR)} "
        f"inside a <{host}>; shapes are drawn in <svg>, <g>, <a> and <switch> elements): a "
        "viewer shows nothing of them; move them into a group in the drawing program to cut them"
    ]
