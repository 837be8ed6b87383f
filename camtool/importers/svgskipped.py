"""What an SVG holds that camtool does not cut, counted for the reader's warnings.

``<defs>`` holding what no ``<use>`` places, text and images drawn, markers drawn on
shapes, shapes filled with a pattern, and ``<use>`` of another file's element.

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Iterable

from camtool.importers.svgcss import inline_style, local_name
from camtool.importers.svgtree import NOT_DRAWN, SHAPE_KINDS, has_shapes, href
from camtool.importers.svgvalues import URL_REF, pattern_draws


def count_skipped(root: ET.Element, hold: ET.Element, counts: Counter[str]) -> None:
    """Add to ``counts`` the skipped kinds: defs, drawn text and image, markers, patterns.

    A ``<defs>`` counts when it holds an element a ``<use>`` could place and none does
    (:data:`_PLACEABLE`): a viewer draws nothing of it, and a user may have drawn it
    there. Gradients, markers, clips, masks, patterns, filters and symbols (counted
    apart) are what a ``<defs>`` is for: the drawing is the same with or without them.

    A drawn shape filled with a ``<pattern>`` that draws something, or with an SVG 2
    ``<hatch>``, counts as ``pattern``: camtool cuts the shape's outline, not the lines or
    dots the pattern paints inside it (matplotlib's hatched bars).

    And a drawn ``<use>`` of another file's element (``use-file``). Text, images, markers
    and pattern-filled shapes a ``<use>`` places (from a ``<symbol>`` or a group in
    ``<defs>``) count once per ``<use>``; each element placed is walked once
    (:func:`~camtool.importers.svgdoc.check_use_cycles` has run).
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    placed_ids = {
        link[1:] for e in root.iter() if local_name(e) == "use" and (link := href(e))[:1] == "#"
    }
    placed: dict[ET.Element, Counter[str]] = {}
    patterns = _drawing_patterns(ids)

    def placed_by_use(target: ET.Element) -> Counter[str]:
        """The text, images, markers and pattern fills a ``<use>`` of ``target`` draws."""
        found = placed.get(target)
        if found is None:
            found = Counter()
            walk(target if local_name(target) == "symbol" else [target], True, found)
            kinds = ("text", "image", "marker", "pattern")
            found = placed[target] = Counter({k: found[k] for k in kinds if found[k]})
        return found

    def walk(
        node: Iterable[ET.Element],
        drawn: bool,
        into: Counter[str],
        marked: frozenset[str] = _NO,
        patterned: bool = False,
    ) -> None:
        for child in node:
            kind = local_name(child)
            if child is hold or kind is None:
                continue
            inner = _markers(child, marked, ids)
            if inner and drawn and kind in _MARKED:
                into["marker"] += 1
            filled = _pattern_filled(child, patterned, patterns)
            if filled and drawn and kind in _FILLED:
                into["pattern"] += 1
            if kind == "defs" and any(
                local_name(c) in _PLACEABLE and c.get("id") not in placed_ids for c in child
            ):
                into["defs"] += 1
            elif kind in ("text", "image") and drawn:
                into[kind] += 1
                continue
            elif kind == "use" and drawn:
                link = href(child)
                if link[:1] not in ("", "#"):
                    into["use-file"] += 1  # another file's element: svgelements places nothing
                elif link[:1] == "#" and (target := ids.get(link[1:])) is not None:
                    into.update(placed_by_use(target))
            walk(child, drawn and kind not in NOT_DRAWN, into, inner, filled)

    walk(root, True, counts)


_NO: frozenset[str] = frozenset()
_PLACEABLE = SHAPE_KINDS | {"g", "a", "switch", "svg", "text", "image"}
"""Elements a ``<defs>`` holds that a ``<use>`` of them draws (SVG 1.1 §5.6)."""
_MARKED = frozenset({"path", "line", "polyline", "polygon"})
"""The shapes a viewer draws markers on (SVG 1.1 §11.6.1)."""
_FILLED = frozenset({"path", "rect", "circle", "ellipse", "polyline", "polygon"})
"""The shapes a fill paints (SVG 1.1 §11.3: a ``<line>`` has no inside)."""
_MARKER_PROPERTIES = {
    "marker": ("start", "mid", "end"),
    "marker-start": ("start",),
    "marker-mid": ("mid",),
    "marker-end": ("end",),
}


def _markers(
    element: ET.Element, inherited: frozenset[str], ids: dict[str | None, ET.Element]
) -> frozenset[str]:
    """Which of ``start``, ``mid``, ``end`` get a drawing marker on ``element`` and inherit.

    The marker properties inherit; ``marker`` sets all three, the others one; ``none`` or a
    reference to no ``<marker>`` with shapes sets none (SVG 1.1 §11.6.2). A ``style``
    declaration outranks the attribute.
    """
    text = element.get("style") or ""
    if "marker" not in text and _MARKER_PROPERTIES.keys().isdisjoint(element.attrib):
        return inherited  # sets none: the style is not parsed (most elements)
    style = inline_style(element)
    out = set(inherited)
    for prop, places in _MARKER_PROPERTIES.items():
        value = style.get(prop, element.get(prop))
        if value is None:
            continue
        ref = URL_REF.fullmatch(value)
        target = ids.get(ref.group(1)) if ref is not None else None
        draws = target is not None and local_name(target) == "marker" and has_shapes(target)
        out = out | set(places) if draws else out - set(places)
    return frozenset(out)


def _drawing_patterns(ids: dict[str | None, ET.Element]) -> frozenset[str]:
    """The ids of the paint servers that draw shapes, text or images inside what they fill."""
    return frozenset(i for i, e in ids.items() if i is not None and pattern_draws(e, ids))


def _pattern_filled(element: ET.Element, inherited: bool, patterns: frozenset[str]) -> bool:
    """Whether ``element``'s fill, its own or inherited, is one of ``patterns``.

    ``fill`` inherits; a ``style`` declaration outranks the attribute.
    """
    value = element.get("fill")
    if "fill" in (element.get("style") or ""):
        value = inline_style(element).get("fill", value)
    if value is None or value.strip() == "inherit":
        return inherited
    ref = URL_REF.match(value)
    return ref is not None and ref.group(1) in patterns
