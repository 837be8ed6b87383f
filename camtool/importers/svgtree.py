"""The SVG document's tree: names camtool adds to it, and the questions every pass asks of it.

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from camtool.importers.svgcss import SVG_NS, local_name

INKSCAPE_NS = "http://www.inkscape.org/namespaces/inkscape"
LIBRECAD_NS = "https://librecad.org"
XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
CAMTOOL_NS = "urn:camtool:svg"
SOURCE_ATTR = f"{{{CAMTOOL_NS}}}source"
"""Private attribute holding an element's source label (``path#id``, ``path[3]``)."""
LAYER_ATTR = f"{{{CAMTOOL_NS}}}layer"
"""Private attribute holding a layer group's name; svgelements passes it down to shapes."""
USE_ATTR = f"{{{CAMTOOL_NS}}}use"
"""Private attribute holding a ``<use>``'s label; svgelements passes it down to the clone."""

NOT_DRAWN = frozenset(
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


def is_drawn(element: ET.Element, parents: dict[ET.Element, ET.Element], hold: ET.Element) -> bool:
    """Whether ``element`` is rendered where it is: under neither ``hold`` nor a not-drawn kind."""
    node = element
    while node in parents:
        node = parents[node]
        if node is hold or local_name(node) in NOT_DRAWN:
            return False
    return True


SHAPE_KINDS = frozenset({"path", "rect", "circle", "ellipse", "line", "polyline", "polygon", "use"})


def has_shapes(element: ET.Element) -> bool:
    """Whether ``element`` is a shape or a ``<use>``, or holds one."""
    return any(local_name(e) in SHAPE_KINDS for e in element.iter())


def href(element: ET.Element) -> str:
    """``element``'s ``xlink:href`` or ``href``, stripped (``""``: none)."""
    return (element.get(XLINK_HREF) or element.get("href") or "").strip()


def elements(root: ET.Element, name: str) -> list[ET.Element]:
    """The SVG elements ``name`` under ``root``, in document order (ElementTree's own search)."""
    return list(root.iter(tag(root, name)))


def tag(root: ET.Element, name: str) -> str:
    """The tag of SVG element ``name`` in ``root``'s document (with the namespace or not)."""
    return f"{{{SVG_NS}}}{name}" if root.tag.startswith("{") else name
