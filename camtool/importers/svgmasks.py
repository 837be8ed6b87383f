"""Clips, masks and nested viewports in the SVG document pass, made ready for svgclip.

A viewer shows a shape under a ``clip-path``, a ``mask`` or a nested ``<svg>`` viewport
only where these let it through; camtool cuts whole shapes. This pass turns each into a
``<clipPath>`` that :mod:`camtool.importers.svgclip` compares with the shapes it covers
(read, skipped, or refused), or refuses what it cannot turn into one:

- :func:`symbols_as_viewports`: a ``<use>`` of a ``<symbol>`` becomes the nested
  ``<svg>`` it stands for;
- :func:`clip_viewports`: a nested ``<svg>`` clips to its rectangle;
- :func:`masks_as_clips`: a mask whose every visible part is sure (white or coloured,
  opaque in part) lets through where its shapes are; any other mask is refused;
- :func:`clip_paths_first`: every ``<clipPath>`` moved to the document's start.

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py``.
"""

from __future__ import annotations

import copy
import math
import xml.etree.ElementTree as ET

import svgelements as se

from camtool.importers import svgcheck, svgvalues
from camtool.importers.svgcss import SVG_NS, inline_style, local_name
from camtool.importers.svgtree import (
    NOT_DRAWN,
    SOURCE_ATTR,
    XLINK_HREF,
    elements,
    has_shapes,
    href,
    is_drawn,
    tag,
)
from camtool.model.errors import InputError

MASK_CLIP = "camtool-mask-"
"""Prefix of the ids of the clips :func:`masks_as_clips` makes."""

_FILLED = frozenset({"path", "rect", "circle", "ellipse", "polyline", "polygon"})
_INHERITED = ("fill", "stroke", "visibility", "fill-opacity", "stroke-opacity")


def masks_as_clips(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    name: str,
    viewport: tuple[float, float],
) -> None:
    """Give each drawn element under a ``mask`` the clip that mask amounts to, or refuse it.

    A mask shows its element where its content is light and opaque (CSS Masking 1 §7). A
    mask amounts to a clip when each of its shapes is either sure to show through (a
    filled shape of a colour other than black, or of a gradient all of whose stops are,
    with an opacity above 0 in each; no stroke other than one of such a colour) or sure to
    hide (no fill and no stroke, a black fill, opacity 0, hidden), and no hiding shape lies
    over a showing one. The clip is the showing shapes, in the masked element's user space
    (``maskContentUnits="userSpaceOnUse"``, the default); a ``maskUnits="userSpaceOnUse"``
    rectangle (its ``x``, ``y``, ``width``, ``height``, -10 %, -10 %, 120 %, 120 % of the
    viewport when not given) is a second clip. The default ``objectBoundingBox``
    rectangle, 10 % around the element's box, lets its outline through whole. A sure
    shape's stroke, left out, only narrows the clip, so a shape is at worst refused for it.
    A ``mask`` naming no ``<mask>`` is ignored, as viewers ignore it (resvg's
    masking/mask/invalid-FuncIRI.svg).

    Raises:
        InputError: a drawn element with shapes under a mask that amounts to no clip:
            ``maskContentUnits="objectBoundingBox"``, a rectangle in ``objectBoundingBox``
            units, text, an image, a ``<use>``, a gradient with a black or transparent stop,
            a mask of the mask or a mask, clip or filter on what it holds (the message names
            the element, the mask and why).
    """
    masks = {e.get("id"): e for e in elements(root, "mask") if e.get("id")}
    if not masks:
        return
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    made: dict[str, tuple[str, ...]] = {}
    for element in list(root.iter()):
        text = inline_style(element).get("mask", element.get("mask")) or ""
        match = svgvalues.URL_REF.fullmatch(text)
        if match is None or match.group(1) not in masks:
            continue
        if local_name(element) in NOT_DRAWN or not has_shapes(element):
            continue
        if not is_drawn(element, parents, hold):
            continue
        mask = masks[match.group(1)]
        clips = made.get(match.group(1))
        if clips is None:
            try:
                shapes = _showing(mask, ids)
                box = _mask_box(mask, viewport)
            except ValueError as exc:
                where = element.get(SOURCE_ATTR) or local_name(element)
                raise InputError(
                    f"{name}: {where} is masked by <mask> #{match.group(1)}, which camtool "
                    f"cannot read as a clip ({exc}); release the mask in the drawing program "
                    "(Inkscape: Object > Mask > Release) and trim the shapes to it, or "
                    "remove the mask to cut them whole"
                ) from None
            clips = made[match.group(1)] = _mask_clips(root, ids, match.group(1), shapes, box)
        _unmask(element)
        for clip in reversed(clips):
            _wrap(element, parents, clip, root)


def _showing(mask: ET.Element, ids: dict[str | None, ET.Element]) -> list[ET.Element]:
    """Copies of the mask's shapes that show through, each with its whole transform.

    Raises:
        ValueError: the mask does not amount to a clip (why, for the message).
    """
    if mask.get("maskContentUnits", "").strip() == "objectBoundingBox":
        raise ValueError('maskContentUnits="objectBoundingBox"')
    if (inline_style(mask).get("mask") or mask.get("mask") or "none").strip() != "none":
        raise ValueError("the <mask> is masked itself")
    shown: list[ET.Element] = []
    stack = [(child, "", dict(_own(mask))) for child in reversed(list(mask))]
    while stack:
        element, transform, inherited = stack.pop()
        kind = local_name(element)
        style = {**inherited, **_own(element)}
        if kind is None or kind in NOT_DRAWN or kind in ("title", "desc", "metadata"):
            continue
        if _hidden(element) or style.get("visibility", "").lower() in ("hidden", "collapse"):
            continue
        own = inline_style(element)
        for key in ("mask", "clip-path", "filter"):
            if (own.get(key) or element.get(key) or "none").strip().lower() != "none":
                raise ValueError(f"{element.get(SOURCE_ATTR)} in it has a {key} of its own")
        here = f"{transform} {element.get('transform', '')}".strip()
        if kind in ("g", "a"):
            stack.extend((c, here, style) for c in reversed(list(element)))
            continue
        if kind not in _FILLED and kind != "line":
            raise ValueError(f"it holds <{kind}>, whose light camtool does not work out")
        fill = "none" if kind == "line" or _clear(style, "fill") else style.get("fill", "black")
        stroke = "none" if _clear(style, "stroke") else style.get("stroke", "none")
        shows, hides = _paint(fill, ids), _none(fill) or _black(fill)
        if not _none(stroke) and not _paint(stroke, ids):
            raise ValueError(f"{element.get(SOURCE_ATTR)}'s stroke {stroke!r} may hide")
        if shows:
            copy = ET.Element(element.tag, dict(element.attrib))
            copy.attrib.pop("style", None)
            if here:
                copy.set("transform", here)
            shown.append(copy)
        elif hides and _none(stroke):
            if shown:
                raise ValueError(f"{element.get(SOURCE_ATTR)} hides part of what lies under it")
        else:
            raise ValueError(f"{element.get(SOURCE_ATTR)}'s fill {fill!r} may hide in part")
    return shown


def _own(element: ET.Element) -> dict[str, str]:
    """The inherited paint properties ``element`` sets (its style over its attributes)."""
    style = inline_style(element)
    out = {}
    for key in _INHERITED:
        value = style.get(key, element.get(key))
        if value is not None:  # CSS-wide keywords are resolved by then (svgcss)
            out[key] = value.strip()
    return out


def _hidden(element: ET.Element) -> bool:
    """``display:none`` or ``opacity`` 0: nothing of the element, or what it holds, shows."""
    style = inline_style(element)
    if (style.get("display", element.get("display")) or "").strip().lower() == "none":
        return True
    value = style.get("opacity", element.get("opacity"))
    number = _number(value) if value is not None else None
    return number is not None and number <= 0


def _clear(style: dict[str, str], paint: str) -> bool:
    """Whether ``fill-opacity`` (or ``stroke-opacity``) of 0 makes ``paint`` paint nothing."""
    value = style.get(f"{paint}-opacity")
    number = _number(value) if value is not None else None
    return number is not None and number <= 0


def _number(text: str) -> float | None:
    text = text.strip()
    try:
        value = float(text[:-1]) / 100 if text.endswith("%") else float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _none(paint: str) -> bool:
    return paint.strip().lower() in ("none", "transparent")


def _black(paint: str) -> bool:
    """A solid paint of no light: black, or no alpha."""
    colour = _colour(paint)
    return colour is not None and (colour.alpha == 0 or colour.value & 0xFFFFFF00 == 0)


def _colour(paint: str) -> se.Color | None:
    """The solid colour ``paint`` names; ``None`` for a reference or a keyword of context."""
    if paint.strip().lower().startswith(("url(", "currentcolor", "context-")):
        return None
    try:
        colour = se.Color(paint)
    except (ValueError, TypeError):
        return None
    return colour if colour.value is not None else None


def _paint(paint: str, ids: dict[str | None, ET.Element]) -> bool:
    """Whether ``paint`` lets light through everywhere it paints (see :func:`masks_as_clips`)."""
    match = svgvalues.URL_REF.fullmatch(paint)
    if match is None:
        colour = _colour(paint)
        return colour is not None and colour.alpha > 0 and colour.value & 0xFFFFFF00 != 0
    stops = svgvalues.gradient_stops(ids.get(match.group(1)), ids)
    if not stops:
        return False
    for stop in stops:
        style = inline_style(stop)
        opacity = _number(style.get("stop-opacity", stop.get("stop-opacity", "1")))
        colour = _colour(style.get("stop-color", stop.get("stop-color", "black")))
        if opacity is None or opacity <= 0 or colour is None or not _paint(colour.hex, ids):
            return False
    return True


def _mask_box(mask: ET.Element, viewport: tuple[float, float]) -> tuple[str, str, str, str] | None:
    """The rectangle a ``maskUnits="userSpaceOnUse"`` mask clips to; ``None``: no clip.

    Raises:
        ValueError: a rectangle given in ``objectBoundingBox`` units (the default units).
    """
    given = [mask.get(a) for a in ("x", "y", "width", "height")]
    if mask.get("maskUnits", "").strip() != "userSpaceOnUse":
        if any(v is not None for v in given):
            raise ValueError("its rectangle is in objectBoundingBox units")
        return None
    out = []
    for value, default, base in zip(
        given, ("-10%", "-10%", "120%", "120%"), (*viewport, *viewport), strict=True
    ):
        text = value if value is not None else default
        try:
            svgcheck.check_length(text, negative=default == "-10%")
        except ValueError as exc:
            raise ValueError(f"its rectangle's {text!r}: {exc}") from None
        match = svgvalues.PERCENT.fullmatch(text)
        out.append(repr(float(match.group(1)) / 100.0 * base) if match else text)
    return (out[0], out[1], out[2], out[3])


def _mask_clips(
    root: ET.Element,
    ids: dict[str | None, ET.Element],
    mask_id: str,
    shapes: list[ET.Element],
    box: tuple[str, str, str, str] | None,
) -> tuple[str, ...]:
    """Write the clips a mask amounts to into ``root``: their ids, outermost first."""
    out = []
    contents: list[list[ET.Element]] = []
    if box is not None:
        rect = ET.Element(
            tag(root, "rect"), dict(zip(("x", "y", "width", "height"), box, strict=True))
        )
        contents.append([rect])
    contents.append(shapes)
    for k, content in enumerate(contents):
        name = f"{MASK_CLIP}{mask_id}-{k}"
        while name in ids:
            name += "-"
        clip = ET.SubElement(root, tag(root, "clipPath"), {"id": name})
        clip.set(SOURCE_ATTR, f"mask#{mask_id}")
        clip.extend(content)
        ids[name] = clip
        out.append(name)
    return tuple(out)


def _unmask(element: ET.Element) -> None:
    """Remove ``element``'s ``mask``, attribute and style property."""
    element.attrib.pop("mask", None)
    style = inline_style(element)
    if "mask" in style:
        del style["mask"]
        element.set("style", ";".join(f"{k}:{v}" for k, v in style.items()))


def _wrap(
    element: ET.Element, parents: dict[ET.Element, ET.Element], clip: str, root: ET.Element
) -> ET.Element:
    """Put ``element`` in a new ``<g clip-path="url(#clip)">`` in its place.

    The element's ``transform`` moves to the group: a clip is in the user space of the
    element that references it, its transform included (SVG 1.1 §14.3.5), and so is a
    mask's content and a nested viewport's rectangle. The ``<svg>`` itself (a mask on the
    whole drawing) keeps its place: its children move into the group.
    """
    wrapper = ET.Element(tag(root, "g"), {"clip-path": f"url(#{clip})"})
    wrapper.set(SOURCE_ATTR, str(element.get(SOURCE_ATTR, local_name(element) or "g")))
    if element is root:
        for child in list(root):
            root.remove(child)
            wrapper.append(child)
            parents[child] = wrapper
        root.append(wrapper)
        parents[wrapper] = root
        return wrapper
    parent = parents[element]
    if element.get("transform") is not None:
        wrapper.set("transform", element.attrib.pop("transform"))
    parent.insert(list(parent).index(element), wrapper)
    parent.remove(element)
    wrapper.append(element)
    parents[wrapper], parents[element] = parent, wrapper
    return wrapper


_USE_PLACES = frozenset({"x", "y", "width", "height", "href", XLINK_HREF})
"""A ``<use>``'s attributes that its generated ``<svg>`` takes (the others go to its ``<g>``)."""
_SIZES = frozenset({"width", "height"})
_SYMBOL_OWN = frozenset({"id", "x", "y", "width", "height", "refX", "refY"})
"""A ``<symbol>``'s attributes its generated ``<svg>`` does not take."""


def symbols_as_viewports(root: ET.Element) -> int:
    """Replace each ``<use>`` of a ``<symbol>``, or sizing an ``<svg>``, by what it stands for.

    SVG 2 §5.6: the use becomes a ``<g>`` with its attributes (its ``transform``, style,
    clip and mask), holding an ``<svg>`` viewport placed and sized as
    :func:`_symbol_viewport` says (the symbol's own ``x``, ``y``, ``width``, ``height``
    count), with the symbol's ``viewBox``,
    ``preserveAspectRatio`` and style, holding copies of the symbol's children. The viewport
    clips unless ``overflow`` is visible (resvg's structure/symbol tests), which
    :func:`clip_viewports` then checks. A use with a ``width`` or ``height`` of an
    ``<svg>`` gives that size to a copy of the ``<svg>`` (svgelements would scale a viewBox
    into the ``<svg>``'s own size, and clip to it), its ``x`` and ``y`` moved by the use's
    (resvg's structure/use/xlink-to-svg-element-with-viewBox.svg and
    xlink-to-svg-element-with-rect.svg). Only the uses the document holds are replaced, not
    those a copy brings (each is replaced once, whatever it nests).

    Returns:
        How many uses were replaced.

    Raises:
        ValueError: a symbol's ``x`` or ``y`` that cannot be added to its use's.
    """
    nested = any(e is not root for e in elements(root, "svg"))
    if not elements(root, "symbol") and not nested:
        return 0
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    parents = {child: parent for parent in root.iter() for child in parent}
    done = 0
    for use in [e for e in root.iter() if local_name(e) == "use"]:
        link = href(use)
        target = ids.get(link[1:]) if link.startswith("#") else None
        parent = parents.get(use)
        if target is None or parent is None:
            continue
        kind = local_name(target)
        sized = kind == "svg" and bool(_SIZES & set(use.attrib))
        if kind != "symbol" and not sized:
            continue
        group = ET.Element(tag(root, "g"), {k: v for k, v in use.attrib.items()
                                            if k not in _USE_PLACES})  # fmt: skip
        if kind == "symbol":
            viewport = ET.SubElement(group, tag(root, "svg"))
            viewport.attrib.update({k: v for k, v in target.attrib.items() if k not in _SYMBOL_OWN})
            viewport.attrib.update(_symbol_viewport(use, target))
            viewport.extend(copy.deepcopy(child) for child in target)
        else:  # a copy of the <svg>, of the use's size, moved by the use's x and y
            try:
                place = {k: _added(use.get(k), target.get(k)) for k in ("x", "y")}
            except ValueError:
                continue  # a bad x or y on the <svg>, refused where it is read
            sized_copy = copy.deepcopy(target)
            sized_copy.attrib.pop("id", None)
            sized_copy.attrib.update({k: v for k, v in use.attrib.items() if k in _SIZES})
            sized_copy.attrib.update(place)
            group.append(sized_copy)
        parent.insert(list(parent).index(use), group)
        parent.remove(use)
        done += 1
    return done


def _symbol_viewport(use: ET.Element, symbol: ET.Element) -> dict[str, str]:
    """``x``, ``y``, ``width``, ``height`` of the viewport a ``<use>`` of ``symbol`` makes.

    SVG 2 §5.6 and §5.5: the size is the use's (``auto`` is none), else the symbol's own
    ``width``/``height``, else 100 %; the symbol's own ``x``/``y`` place the viewport in the
    use's coordinates, moved by the use's ``x``/``y`` (Chromium draws a symbol at x 10 used
    at x 20 from 30; ``refX``/``refY`` it ignores, as here).

    Raises:
        ValueError: a symbol's ``x`` or ``y`` that cannot be added to the use's (a
            percentage left unresolved on one of them).
    """
    out: dict[str, str] = {}
    for key in ("width", "height"):
        given = [e.get(key) for e in (use, symbol)]
        out[key] = next((v for v in given if v and v.strip().lower() != "auto"), "100%")
    for key in ("x", "y"):
        mine, its = use.get(key), symbol.get(key)
        if not its:
            if mine:
                out[key] = mine
            continue
        try:
            out[key] = _added(mine, its)
        except ValueError:
            raise ValueError(
                f"cannot place <symbol> {symbol.get('id')!r}: its {key} {its!r} and the "
                f"<use>'s {mine!r} do not add up (a percentage); give the symbol's {key} in "
                "user units"
            ) from None
    return out


def _added(first: str | None, second: str | None) -> str:
    """The sum, px as text, of two lengths without percentages (a missing one is 0).

    Raises:
        ValueError: one is not a length.
    """
    total = 0.0
    for text in (first, second):
        if text:
            try:
                total += float(se.Length(text).value(ppi=96.0))
            except TypeError as exc:  # a percentage svgelements cannot resolve
                raise ValueError(text) from exc
    if not math.isfinite(total):
        raise ValueError(f"{first} + {second}")
    return repr(total)


VIEWPORT_CLIP = "camtool-viewport-"
"""Prefix of the ids of the clips :func:`clip_viewports` makes (svgclip names them as
viewports)."""


def clip_viewports(
    root: ET.Element,
    parents: dict[ET.Element, ET.Element],
    hold: ET.Element,
    viewport: tuple[float, float],
    name: str,
) -> None:
    """Give each drawn nested ``<svg>`` that clips (``overflow`` hidden, the default) a clip.

    A nested viewport clips its content to its ``x``, ``y``, ``width``, ``height`` (SVG 1.1
    §7.2, §14.3.3; resvg's structure/svg/nested-svg-with-rect.svg: a circle shown as a
    square); svgelements does not. Each such ``<svg>`` is wrapped in a ``<g>`` with a
    ``clip-path`` to a ``<clipPath>`` of that rectangle (a percentage of the nearest
    viewport, ``width`` and ``height`` 100 % when not given), which
    :mod:`camtool.importers.svgclip` checks as any clip; an SVG 2 ``transform`` on the
    ``<svg>`` moves to the ``<g>``, as it applies to the viewport too.

    A ``<use>`` that places the ``<svg>`` (run after :func:`symbols_as_viewports`, so one
    without a size of its own) or a group holding it copies the clip too: the ``<svg>``'s
    id moves to the ``<g>``, and an ``<svg>`` in ``<defs>`` is given its clip as well.

    Raises:
        InputError: a nested ``<svg>`` whose ``x``, ``y``, ``width`` or ``height`` is not a
            length (or a negative size), naming it.
    """
    svg_tag = f"{{{SVG_NS}}}svg" if root.tag.startswith("{") else "svg"
    if not any(e is not root for e in root.iter(svg_tag)):
        return
    sizes: dict[ET.Element, tuple[float, float]] = {}
    stack = [(root, viewport)]
    while stack:  # each nested <svg>'s nearest viewport, as percentages resolve against
        element, size = stack.pop()
        if local_name(element) == "svg" and element is not root:
            sizes[element] = size
            size = svgvalues.viewport_size(element, size)
        stack.extend((child, size) for child in element)
    ids = {e.get("id") for e in root.iter() if e.get("id")}
    used = {href(e)[1:] for e in root.iter(tag(root, "use")) if href(e).startswith("#")}
    made = 0
    for element in [e for e in root.iter(svg_tag) if e is not root]:
        outer = sizes.get(element, viewport)
        empty = 0.0 in svgvalues.viewport_extent(element, outer) or svgvalues.viewbox_empty(element)
        _own_viewbox(element, outer)
        if empty:  # shows nothing, whatever its overflow: clipped to no width, and without
            _check_size(element, name)  # a viewBox scaled into nothing, which makes
            element.attrib.pop("viewBox", None)  # svgelements read no document
            element.set("width", "0")
        overflow = inline_style(element).get("overflow", element.get("overflow", "hidden"))
        visible = overflow.strip().lower() in ("visible", "auto")
        if (visible and not empty) or not has_shapes(element):
            continue
        own_id = element.get("id")
        placed = own_id in used or _in_placed(element, parents, used)
        if not placed and not is_drawn(element, parents, hold):
            continue
        made += 1
        clip_id = f"{VIEWPORT_CLIP}{made}"
        while clip_id in ids:
            clip_id += "-"
        width, height = sizes.get(element, viewport)
        rect = ET.Element(tag(root, "rect"))
        for attr, default, base in (
            ("x", "0", width),
            ("y", "0", height),
            ("width", "100%", width),
            ("height", "100%", height),
        ):
            value = element.get(attr) or default
            _check_length(element, attr, value, name)
            match = svgvalues.PERCENT.fullmatch(value)
            rect.set(attr, repr(float(match.group(1)) / 100.0 * base) if match else value)
        clip = ET.SubElement(root, tag(root, "clipPath"), {"id": clip_id})
        clip.append(rect)
        wrapper = _wrap(element, parents, clip_id, root)
        if own_id in used:  # a <use> of the <svg> copies the group, clip and all
            wrapper.set("id", element.attrib.pop("id"))
        parents[clip] = root


def _in_placed(element: ET.Element, parents: dict[ET.Element, ET.Element], used: set[str]) -> bool:
    """Whether an element that holds ``element`` is one a ``<use>`` places (its id in ``used``).

    A ``<use>`` of a group in ``<defs>`` draws the nested ``<svg>`` inside it, clip and all
    (a ``<use>`` of a ``<use>`` of a ``<symbol>``: resvg's
    structure/symbol/indirect-symbol-reference.svg).
    """
    node = element
    while node in parents:
        node = parents[node]
        if node.get("id") in used:
            return True
    return False


def _check_size(element: ET.Element, name: str) -> None:
    """Refuse a nested ``<svg>`` whose ``width`` or ``height`` is not a length (or < 0)."""
    for attr in ("width", "height"):
        value = element.get(attr)
        if value is not None:
            _check_length(element, attr, value, name)


def _check_length(element: ET.Element, attr: str, value: str, name: str) -> None:
    """Refuse ``value`` of a nested ``<svg>``'s ``attr`` if it is not a length (or a size < 0).

    Raises:
        InputError: naming the file, the ``<svg>`` and the attribute.
    """
    try:
        svgcheck.check_length(value, negative=attr in ("x", "y"))
    except ValueError as exc:
        where = element.get(SOURCE_ATTR) or "svg"
        raise InputError(f"{name}: {where}: bad {attr} {value!r}: {exc}") from None


def _own_viewbox(element: ET.Element, outer: tuple[float, float]) -> None:
    """Give a nested ``<svg>`` without a viewBox the viewBox ``0 0 width height``.

    The same viewport (its content unscaled, SVG 1.1 §7.7), which svgelements places at the
    ``<svg>``'s ``x``, ``y``: without a viewBox it left the content at the parent's origin
    (resvg's structure/svg/nested-svg-with-rect.svg). A size of 0 shows nothing and is
    left as it is. A missing ``x`` or ``y`` is written as 0.
    """
    for attr in ("x", "y"):  # else svgelements takes an outer viewport's
        if element.get(attr) is None:
            element.set(attr, "0")
    if svgvalues.viewbox_size(element) is not None:
        return
    width, height = svgvalues.viewport_size(element, outer)
    if width > 0 and height > 0:
        element.set("viewBox", f"0 0 {width!r} {height!r}")


_CLIP_CONTENT = frozenset(
    ["path", "rect", "circle", "ellipse", "line", "polyline", "polygon", "text", "use"]
)
"""What a ``<clipPath>``'s region is made of (SVG 1.1 §14.3.5: shapes, text, and ``<use>``
of a shape or text); any other child (a group, an image, a ``<switch>``) adds nothing."""


def clip_paths_first(root: ET.Element) -> None:
    """Move every ``<clipPath>`` into a ``<defs>`` that is the document's first child.

    A clip's children are in the user space of the element that references it, whatever
    lies around the ``<clipPath>`` (SVG 1.1 §14.3.5); svgelements composes the transforms
    of its ancestors into them, and looks a reference up when it meets it. At the start,
    under no transform, each clip is known before any reference to it and carries only its
    own ``transform`` (:mod:`camtool.importers.svgclip`). Children that add nothing to the
    region (not in :data:`_CLIP_CONTENT`, or a ``<use>`` of anything but a shape or text)
    are taken out, so that svgelements does not read them into it; one that holds an
    element a ``<use>`` places goes to a ``<defs>`` of its own after the clips, where the
    use still finds it (resvg's structure/use/xlink-to-a-child-of-an-invalid-element.svg:
    a ``<g>`` in a clip, ignored by the clip, holds the rectangle the use draws).
    """
    clips = elements(root, "clipPath")
    if not clips:
        return
    parents = {child: parent for parent in root.iter() for child in parent}
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    placed = {href(e)[1:] for e in elements(root, "use") if href(e).startswith("#")}
    front = ET.Element(tag(root, "defs"))
    kept = ET.Element(tag(root, "defs"))
    for clip in clips:
        parents[clip].remove(clip)
        front.append(clip)
        for child in list(clip):
            kind = local_name(child)
            if kind == "use":
                link = href(child)
                target = ids.get(link[1:]) if link.startswith("#") else None
                kind = local_name(target) if target is not None else None
                kind = None if kind == "use" else kind
            if kind not in _CLIP_CONTENT:
                clip.remove(child)
                if any(e.get("id") in placed for e in child.iter()):
                    kept.append(child)
    root.insert(0, front)
    if len(kept):
        root.insert(1, kept)
