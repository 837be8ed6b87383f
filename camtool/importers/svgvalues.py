"""SVG values svgelements reads otherwise than SVG does, rewritten before it reads them.

In each case a browser draws the file one way and svgelements another (resvg's test suite,
whose reference images Chrome agrees with, has a file for each); each pass rewrites the
attributes into the form svgelements reads as SVG means them:

- :func:`resolve_percentages`: a shape's percentage lengths as user units;
- :func:`default_sizes`: a shape without its size draws nothing; an ellipse's one radius
  is both (``auto``);
- :func:`rect_radii`: a rounded rect's corner radii in user units, each at most half its
  side;
- :func:`fold_transform_origin`: ``transform-origin`` into the ``transform``;
- :func:`resolve_paint_references`: a ``url(#id)`` paint that paints nothing as its
  fallback;
- :func:`normalize_colours`: ``rgb()``/``hsl()`` colours in the forms svgelements does
  not read (fractions, exponents, CSS Color 4's spaces and ``/ alpha``) as ``rgba()``,
  paints that are no colour dropped, and opacities clamped to [0, 1].

Sources: SVG 1.1 §7.10 (units), §13.2 (paint servers); SVG 2 §10 (shapes), §13.2
(paint); CSS Transforms 1 §6; CSS Color 4 §5.1 (``rgb()``), §7 (``hsl()``).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

import svgelements as se

from camtool.importers.svgcheck import NUMBER
from camtool.importers.svgcss import inline_style, local_name, style_text
from camtool.importers.svgtree import SHAPE_KINDS, href

LENGTH_ATTRS = {
    "rect": ("x", "y", "width", "height", "rx", "ry"),
    "circle": ("cx", "cy", "r"),
    "ellipse": ("cx", "cy", "rx", "ry"),
    "line": ("x1", "y1", "x2", "y2"),
    "use": ("x", "y", "width", "height"),
}
"""The length attributes of each shape, and of ``<use>`` (checked by the document pass,
resolved here)."""
_VIEWPORT_ATTRS = ("x", "y", "width", "height")
"""A nested ``<svg>``'s lengths :func:`resolve_percentages` resolves."""
_SIZE_NEEDS = {"rect": ("width", "height"), "circle": ("r",), "ellipse": ("rx", "ry")}
"""The size attributes a shape needs to be drawn (:func:`default_sizes`)."""


def default_sizes(element: ET.Element, kind: str) -> None:
    """Give a shape without its size the size SVG 2 gives it.

    A rect needs both sizes, an ellipse one radius (the other ``auto``: the same), a circle
    its radius: without them nothing is drawn (their value is 0 or ``auto``, SVG 2
    §10.2-10.4), where svgelements draws a size of 1 (a 1 px high rectangle). A size set in
    the ``style`` (SVG 2 geometry properties) counts. A rect's or a ``<use>``'s missing
    ``x`` and ``y`` are written as 0: svgelements passes attributes down, so inside a
    nested ``<svg>`` it would take that viewport's. Run after :func:`resolve_percentages`.
    """
    if kind in ("rect", "use"):
        style = inline_style(element)
        for attr in ("x", "y"):  # svgelements would take a nested <svg>'s x and y for them
            if element.get(attr) is None and attr not in style:
                element.set(attr, "0")
    needs = _SIZE_NEEDS.get(kind)
    if needs is None:
        return
    style = inline_style(element)
    given = {a for a in needs if element.get(a) is not None or a in style}
    if not given if kind == "ellipse" else given != set(needs):
        element.set(needs[0], "0")
    elif kind == "ellipse" and len(given) == 1:
        (have,) = given
        element.set("ry" if have == "rx" else "rx", element.get(have) or style[have])


def rect_radii(element: ET.Element) -> None:
    """Write a rounded ``<rect>``'s corner radii as user units, as SVG sizes them.

    A radius not given is the other one (``auto``), and each is then at most half its side:
    ``rx`` of the width, ``ry`` of the height (SVG 1.1 §9.2). svgelements applies the limit
    only when the sizes and radii are plain numbers: it would round ``rx="2mm"`` on a rect 5
    units wide, or ``rx="30"`` on one ``10mm`` wide, past the sides, a corner bulging out of
    the part. Sizes and radii in the ``style`` (SVG 2) count, and are
    written back as attributes; ``auto`` is a radius not given. A rect with a length
    camtool does not read here (``em``, ``ex``, a percentage left in a style) is left as
    it is. Run after the lengths are checked.
    """
    style = inline_style(element)
    sizes: dict[str, float] = {}
    for attr in ("width", "height", "rx", "ry"):
        text = style.get(attr, element.get(attr))
        if text is None or text.strip() == "auto":
            continue
        try:
            length = se.Length(text.strip()).value(ppi=96.0)
        except (ValueError, TypeError):
            return
        if isinstance(length, se.Length) or not math.isfinite(float(length)):
            return  # a percentage or a font-relative length: not resolved here
        sizes[attr] = float(length)
    rx, ry = sizes.get("rx"), sizes.get("ry")
    if rx is None and ry is None:
        return
    rx = ry if rx is None else rx
    ry = rx if ry is None else ry
    assert rx is not None and ry is not None
    limits = (sizes.get("width", 0.0) / 2.0, sizes.get("height", 0.0) / 2.0)
    for attr, value, limit in (("rx", rx, limits[0]), ("ry", ry, limits[1])):
        element.set(attr, repr(min(value, limit)))
        style.pop(attr, None)
    for attr in ("width", "height"):
        if attr in style:
            element.set(attr, repr(sizes[attr]))
            style.pop(attr)
    if element.get("style") is not None:
        element.set("style", style_text(style))


PERCENT = re.compile(rf"\s*({NUMBER.pattern})%\s*", re.ASCII)
_ACROSS = frozenset({"x", "cx", "width", "x1", "x2"})
_DOWN = frozenset({"y", "cy", "height", "y1", "y2"})


URL_REF = re.compile(r"\s*url\(\s*['\"]?#([^)'\"\s]+)['\"]?\s*\)\s*")
"""A reference to an element of the document, ``url(#id)``: its ``fullmatch`` gives the id."""
_PAINT_URL = re.compile(r"\s*url\(\s*['\"]?#([^)'\"\s]+)['\"]?\s*\)\s*(.*?)\s*")
_PAINT_SERVERS = frozenset(
    {"linearGradient", "radialGradient", "pattern", "meshgradient", "hatch", "solidcolor"}
)


def resolve_paint_references(root: ET.Element) -> None:
    """Write a ``fill`` or ``stroke`` of ``url(#id)`` that paints nothing as its fallback.

    A reference to no element, to one that is not a paint server (a ``<rect>``), or to a
    gradient without stops paints with its fallback colour (``url(#g) red``), else not at
    all (SVG 2 §13.2): a shape
    filled so and not stroked is invisible. svgelements paints every ``url(…)`` black, so
    such a shape would be cut. A ``<pattern>`` without children (its own or, through
    ``href``, another's: :func:`pattern_content`) is no paint server, as for Chromium; one
    whose children draw nothing (:func:`pattern_draws`) paints nothing, whatever the
    fallback. A reference to a gradient or a pattern that draws is kept (the shape is
    painted). Run after the style sheets are applied.
    """
    ids = {e.get("id"): e for e in root.iter() if e.get("id")}
    servers = {
        ident
        for ident, e in ids.items()
        if local_name(e) in _PAINT_SERVERS
        and (local_name(e) not in _GRADIENTS or gradient_stops(e, ids))
        and (local_name(e) != "pattern" or pattern_content(e, ids) is not None)
    }
    blank = {
        i for i in servers if local_name(ids[i]) == "pattern" and not pattern_draws(ids[i], ids)
    }
    painting = servers - blank
    for element in root.iter():
        style = element.get("style")
        declared = inline_style(element) if style and "url(" in style else {}
        for name in ("fill", "stroke"):
            for value, inline in ((element.get(name), False), (declared.get(name), True)):
                match = _PAINT_URL.fullmatch(value or "")
                if match is None or match.group(1) in painting:
                    continue
                paint = "none" if match.group(1) in blank else match.group(2) or "none"
                if inline:
                    declared[name] = paint
                    element.set("style", style_text(declared))
                else:
                    element.set(name, paint)


_CONTEXT_HOSTS = frozenset({"defs", "symbol", "marker", "pattern", "clipPath", "mask"})
"""Elements whose content is drawn only where something places it (a ``<use>``, a marker's
path): there a context paint has a context element."""


def resolve_context_paints(root: ET.Element, parents: dict[ET.Element, ET.Element]) -> None:
    """Write ``context-fill`` and ``context-stroke`` as ``none`` where nothing gives them a paint.

    A context paint is the fill or stroke of the context element: the ``<use>`` that places
    the content, or the shape a marker is on; with no context element it is no paint (SVG 2
    §13.2: ``context-fill`` on a shape drawn where it stands shows nothing). svgelements read
    it as painted, so such a shape was cut. Kept where a context element may exist: inside
    ``<defs>``, ``<symbol>``, ``<marker>``, ``<pattern>``, a clip or a mask, and in (or under)
    an element a ``<use>`` places.
    """
    placed = {href(e)[1:] for e in root.iter() if local_name(e) == "use"}
    for element in root.iter():
        style = element.get("style")
        declared = inline_style(element) if style and "context-" in style.lower() else {}
        found = [
            (name, inline)
            for name in ("fill", "stroke")
            for inline, value in ((False, element.get(name)), (True, declared.get(name)))
            if value is not None and value.strip().lower() in ("context-fill", "context-stroke")
        ]
        if not found or _in_context(element, parents, placed):
            continue
        for name, inline in found:
            if inline:
                declared[name] = "none"
                element.set("style", style_text(declared))
            else:
                element.set(name, "none")


def _in_context(
    element: ET.Element, parents: dict[ET.Element, ET.Element], placed: set[str]
) -> bool:
    node: ET.Element | None = element
    while node is not None:
        if local_name(node) in _CONTEXT_HOSTS or node.get("id") in placed:
            return True
        node = parents.get(node)
    return False


_COLOUR_FUNCTION = re.compile(r"\s*(rgba?|hsla?)\(([^()]*)\)\s*", re.IGNORECASE)
_COLOUR_ARG = re.compile(rf"{NUMBER.pattern}(%|deg|grad|rad|turn)?$", re.ASCII)
_TURNS = {"": 1 / 360, "deg": 1 / 360, "grad": 1 / 400, "rad": 1 / (2 * math.pi), "turn": 1.0}


def normalize_colours(root: ET.Element) -> None:
    """Rewrite ``fill``, ``stroke`` and ``color`` values of ``rgb()``/``hsl()`` as ``rgba()``.

    svgelements reads only integer ``rgb()`` channels with commas: a fraction
    (``rgb(0.8, 127.5, 14.2)``, SVG 2) makes it drop the whole shape without a word,
    and CSS Color 4's space-separated form (``rgb(0 128 0 / 50%)``, ``hsl(120deg 100%
    25%)``) reads as black, which a job selecting by colour would take for another
    colour. Channels are clamped and rounded to 0–255 (CSS Color 4 §5.1); a value that
    is not a colour is left for svgelements.

    ``opacity``, ``fill-opacity`` and ``stroke-opacity`` are clamped to [0, 1] (a
    percentage is of 1), and one that is no number is dropped, its initial value 1 (CSS:
    an invalid declaration is ignored): svgelements raised on ``fill-opacity="1e400"``.
    A ``fill``, ``stroke`` or ``color`` that is no colour is dropped too (:func:`_paint`).
    Run after the style sheets are applied.
    """
    for element in root.iter():
        attrib = element.attrib
        if not attrib:
            continue
        _rewrite(attrib)
        style = attrib.get("style")
        if style and _rewritable(style):
            declared = inline_style(element)
            if _rewrite(declared):
                element.set("style", style_text(declared))


def _rewrite(values: dict[str, str]) -> bool:
    """:func:`normalize_colours` on one element's attributes or style declarations.

    Returns:
        Whether a value changed (``values`` is changed in place).
    """
    changed = False
    for names, read in ((_OPACITIES, _opacity), (_PAINTS, _paint)):
        for name in names:
            value = values.get(name)
            if value is None:
                continue
            written = read(value)
            if written != value:
                changed = True
                if written is None:
                    del values[name]
                else:
                    values[name] = written
    return changed


def _paint(value: str) -> str | None:
    """A ``fill``, ``stroke`` or ``color`` as svgelements reads it; ``None``: not a value.

    svgelements reads every value it does not know as black. A value that is no colour
    (``notacolour``, ``#12``, ``dark blue``) is an invalid declaration,
    which CSS ignores (the property then comes from the parent): ``None``. White space
    around a keyword, ``currentcolor`` in any case, CSS Color 4's ``rebeccapurple`` and
    ``aliceblue`` (which svgelements reads as another colour) and SVG 1.1's ``#f00
    icc-color(…)`` are written as it reads them; ``rgb()``/``hsl()`` as :func:`_rgba` writes
    them. A paint server (``url(…)``), a context paint, a system colour or a colour function
    camtool does not read (``lab()``) is kept: the shape is painted, whatever the colour.
    """
    text = value.strip()
    low = text.lower()
    if low == "none" or low.startswith(("url(", "context-")):
        return "none" if low == "none" else text
    if low == "currentcolor":
        return "currentColor"
    words = low.split(maxsplit=1)
    if len(words) == 2 and words[1].startswith("icc-color(") and "(" not in words[0]:
        text = low = words[0]  # SVG 1.1: an sRGB colour, then an ICC colour for a printer
    if "(" in text:
        if _COLOUR_CALL.match(text):
            return _rgba(text) or value  # one it does not read: as svgelements reads it
        return value  # another colour function: painted
    if low in _RENAMED:
        return _RENAMED[low]
    if _HEX.fullmatch(low) or low == "transparent" or low in _SYSTEM_COLOURS:
        return text
    if _IDENT.fullmatch(low) and _named(low):
        return text
    return None


_HEX = re.compile(r"#(?:[0-9a-f]{3,4}|[0-9a-f]{6}|[0-9a-f]{8})")
_IDENT = re.compile(r"[a-z]+")
_RENAMED = {"rebeccapurple": "#663399", "aliceblue": "#f0f8ff"}
"""CSS Color 4 names svgelements reads as another colour (black; ``#faf8ff``)."""
_SYSTEM_COLOURS = frozenset(
    {
        "canvas", "canvastext", "linktext", "visitedtext", "activetext", "buttonface",
        "buttontext", "buttonborder", "field", "fieldtext", "highlight", "highlighttext",
        "selecteditem", "selecteditemtext", "mark", "marktext", "graytext", "accentcolor",
        "accentcolortext", "activeborder", "activecaption", "appworkspace", "background",
        "buttonhighlight", "buttonshadow", "captiontext", "inactiveborder", "inactivecaption",
        "inactivecaptiontext", "infobackground", "infotext", "menu", "menutext", "scrollbar",
        "threeddarkshadow", "threedface", "threedhighlight", "threedlightshadow",
        "threedshadow", "window", "windowframe", "windowtext",
    }
)  # fmt: skip
"""CSS Color 4 §6.2 system colours (and the deprecated ones): painted, colour unknown."""


def _named(name: str) -> bool:
    """Whether svgelements knows ``name`` (lower case) as a colour (CSS Color 4 §6.1)."""
    return name == "black" or se.Color.parse_color_lookup(name) != _BLACK


_BLACK = se.Color.rgb_to_int(0, 0, 0)


_OPACITIES = ("opacity", "fill-opacity", "stroke-opacity")
_PAINTS = ("fill", "stroke", "color")
_COLOUR_CALL = re.compile(r"(?:rgb|hsl)a?\(", re.IGNORECASE)
_ODD_PAINT = re.compile(
    r"(?:^|;)\s*(?:fill|stroke|color)\s*:(?!\s*(?:#[0-9a-fA-F]{3,8}|none|url\([^;]*)\s*(?:;|$))"
)
"""A paint in a style that is not a hex colour, ``none`` or ``url(…)`` (Inkscape's forms)."""
_ODD_OPACITY = re.compile(
    r"opacity\s*:(?!\s*(?:[01]|0?\.\d+|1\.0*)\s*(?:!important\s*)?(?:;|$))", re.IGNORECASE
)


def _rewritable(style: str) -> bool:
    """Whether a ``style`` may hold a colour or an opacity :func:`normalize_colours` rewrites.

    A quick look (Inkscape writes ``opacity:1;fill-opacity:1`` on every element), so that
    only such styles are parsed.
    """
    return bool(
        ("(" in style and _COLOUR_CALL.search(style))
        or ("opacity" in style and _ODD_OPACITY.search(style))
        or _ODD_PAINT.search(style)
    )


_NUMBER = re.compile(rf"\s*({NUMBER.pattern})(%?)\s*", re.ASCII)


def _opacity(value: str) -> str | None:
    """An opacity clamped to [0, 1] as written (unchanged when already so); None: no number.

    CSS-wide keywords (``inherit``) are resolved before
    (:func:`~camtool.importers.svgcss.normalize_styles`).
    """
    match = _NUMBER.fullmatch(value)
    if match is None:
        return None
    number = float(match.group(1)) / (100.0 if match.group(2) else 1.0)
    if 0.0 <= number <= 1.0 and not match.group(2):
        return value
    return f"{min(max(number, 0.0), 1.0):g}"


def _rgba(value: str) -> str | None:
    """``value`` as ``rgba(r,g,b,a)`` with integer channels; None: not an rgb()/hsl() colour."""
    match = _COLOUR_FUNCTION.fullmatch(value)
    if match is None:
        return None
    kind = match.group(1).lower()[:3]
    body = match.group(2).strip()
    alpha_text = None
    if "/" in body:
        body, alpha_text = (part.strip() for part in body.split("/", 1))
    args = [a for a in re.split(r"\s*,\s*|\s+", body) if a]
    if alpha_text is None and len(args) == 4:
        alpha_text = args.pop()
    if len(args) != 3 or not all(_COLOUR_ARG.match(a) for a in args):
        return None
    alpha = _alpha(alpha_text)
    if alpha is None:
        return None
    channels = [_channel(a) for a in args] if kind == "rgb" else _hsl(args)
    if channels is None or any(c is None for c in channels):
        return None
    r, g, b = channels
    return f"rgba({r},{g},{b},{alpha:g})"


def _channel(arg: str) -> int | None:
    if arg.endswith(("deg", "grad", "rad", "turn")):
        return None
    number = float(arg.rstrip("%")) * (2.55 if arg.endswith("%") else 1.0)
    if not math.isfinite(number):
        return None
    return math.floor(min(max(number, 0.0), 255.0) + 0.5)


def _alpha(text: str | None) -> float | None:
    if text is None:
        return 1.0
    if not _COLOUR_ARG.match(text) or text.endswith(("deg", "grad", "rad", "turn")):
        return None
    number = float(text.rstrip("%")) / (100.0 if text.endswith("%") else 1.0)
    return min(max(number, 0.0), 1.0) if math.isfinite(number) else None


def _hsl(args: list[str]) -> list[int] | None:
    """CSS Color 4 §7.1: hue in degrees (or an angle unit), saturation and lightness."""
    hue, sat, light = args
    unit = _COLOUR_ARG.match(hue).group(1) or ""  # type: ignore[union-attr]
    if unit == "%":
        return None
    h = (float(hue[: len(hue) - len(unit)]) * _TURNS[unit]) % 1.0
    s = min(max(float(sat.rstrip("%")) / 100.0, 0.0), 1.0)
    lum = min(max(float(light.rstrip("%")) / 100.0, 0.0), 1.0)
    if not all(math.isfinite(v) for v in (h, s, lum)):
        return None

    def f(n: float) -> int:
        k = (n + h * 12.0) % 12.0
        a = s * min(lum, 1.0 - lum)
        v = lum - a * max(-1.0, min(k - 3.0, 9.0 - k, 1.0))
        return math.floor(v * 255.0 + 0.5)

    return [f(0.0), f(8.0), f(4.0)]


_ORIGIN_KEYWORDS = {"left": 0.0, "top": 0.0, "center": 50.0, "right": 100.0, "bottom": 100.0}
_CSS_UNIT_PX = {"": 1.0, "px": 1.0, "mm": 96.0 / 25.4, "cm": 96.0 / 2.54, "in": 96.0,
                "pt": 96.0 / 72.0, "pc": 16.0}  # fmt: skip
_ORIGIN_TOKEN = re.compile(rf"({NUMBER.pattern})(%|px|mm|cm|in|pt|pc)?", re.ASCII)


def fold_transform_origin(element: ET.Element, viewport: tuple[float, float]) -> None:
    """Fold ``element``'s ``transform-origin`` into its ``transform``.

    ``transform="T" transform-origin="ox oy"`` is ``translate(ox oy) T translate(-ox -oy)``
    (CSS Transforms 1 §6; SVG 2 takes it as a presentation attribute or a style
    property). Keywords (``left``, ``center``, ``right``, ``top``, ``bottom``) and
    percentages are of the document's viewport (``transform-box: view-box``, the initial
    value); one value leaves the other axis at ``center``. svgelements ignores it, so a
    shape turned about its centre would be cut turned about the origin, elsewhere.

    Raises:
        ValueError: a ``transform-origin`` that is not one or two such values (a third,
            Z, of 0 is allowed).
    """
    style = inline_style(element)
    text = style.get("transform-origin", element.get("transform-origin"))
    if text is None:
        return
    if "transform-origin" in style:
        del style["transform-origin"]
        element.set("style", style_text(style))
    element.attrib.pop("transform-origin", None)
    transform = element.get("transform")
    if not transform or not transform.strip():
        return  # no transform: the origin moves nothing
    origin = _origin(text, viewport)
    if origin is None:
        raise ValueError(
            f"transform-origin {text!r} is not one or two keywords, lengths or percentages; "
            "apply the transform in the drawing program"
        )
    ox, oy = origin
    element.set("transform", f"translate({ox!r} {oy!r}) {transform} translate({-ox!r} {-oy!r})")


def _origin(text: str, viewport: tuple[float, float]) -> tuple[float, float] | None:
    """``transform-origin`` as user units ``(x, y)``, or ``None`` if it cannot be read."""
    tokens = text.replace(",", " ").split()
    z = _ORIGIN_TOKEN.fullmatch(tokens[2]) if len(tokens) == 3 else None
    if z is not None and float(z.group(1)) == 0.0:  # a Z of 0 moves nothing in the plane
        tokens = tokens[:2]
    if not 1 <= len(tokens) <= 2:
        return None
    if len(tokens) == 1:
        tokens = ["center", tokens[0]] if tokens[0] in ("top", "bottom") else [tokens[0], "center"]
    elif tokens[0] in ("top", "bottom") or tokens[1] in ("left", "right"):
        tokens = [tokens[1], tokens[0]]  # "top left": the vertical keyword first
    out: list[float] = []
    for token, size in zip(tokens, viewport, strict=True):
        if token in _ORIGIN_KEYWORDS:
            out.append(_ORIGIN_KEYWORDS[token] / 100.0 * size)
            continue
        match = _ORIGIN_TOKEN.fullmatch(token)
        if match is None:
            return None
        value, unit = float(match.group(1)), match.group(2) or ""
        out.append(value / 100.0 * size if unit == "%" else value * _CSS_UNIT_PX[unit])
    return out[0], out[1]


_GRADIENTS = frozenset({"linearGradient", "radialGradient"})


def gradient_stops(
    gradient: ET.Element | None, ids: dict[str | None, ET.Element]
) -> list[ET.Element]:
    """The ``<stop>``s ``gradient`` paints with, its own or those of one it refers to (``href``).

    A gradient without stops paints as ``none`` (SVG 1.1 §13.2.4). Inkscape writes a
    gradient with coordinates that takes its stops from another; the chain is followed
    (at most 32 links: a cycle ends it, without stops). ``[]`` for no gradient.
    """
    current = gradient if gradient is not None and local_name(gradient) in _GRADIENTS else None
    for _ in range(32):
        if current is None:
            return []
        stops = [c for c in current if local_name(c) == "stop"]
        if stops:
            return stops
        # any attribute named href: openclipart has files whose xlink namespace is mangled
        href = next((v for k, v in current.attrib.items() if k.rpartition("}")[2] == "href"), "")
        href = href.strip()
        target = ids.get(href[1:]) if href.startswith("#") else None
        current = target if target is not None and local_name(target) in _GRADIENTS else None
    return []


def pattern_draws(server: ET.Element, ids: dict[str | None, ET.Element]) -> bool:
    """Whether the paint server ``server`` draws something inside what it fills.

    An SVG 2 ``<hatch>`` always draws lines; a ``<pattern>`` draws when its content
    (:func:`pattern_content`) holds a shape, text or image.
    """
    if local_name(server) == "hatch":
        return True
    content = pattern_content(server, ids)
    return content is not None and any(local_name(e) in _PATTERN_CONTENT for e in content.iter())


def pattern_content(server: ET.Element, ids: dict[str | None, ET.Element]) -> ET.Element | None:
    """The ``<pattern>`` whose children ``server`` draws; ``None``: none in its chain has any.

    A pattern without children takes those of the pattern its ``href`` names, and so on
    (SVG 1.1 §13.3; a cycle ends it). ``None`` for an element that is not a pattern.
    """
    seen: set[ET.Element] = set()
    node: ET.Element | None = server
    while node is not None and local_name(node) == "pattern" and node not in seen:
        seen.add(node)
        if len(node):
            return node
        link = href(node)
        node = ids.get(link[1:]) if link[:1] == "#" else None
    return None


_PATTERN_CONTENT = SHAPE_KINDS | {"text", "image"}
"""What a pattern draws when it holds it: shapes, ``<use>``, text and images."""

_GRADIENT_CONTENT = frozenset({*_GRADIENTS, "stop", "animate", "set"})
"""What a gradient holds that svgelements reads into plain elements and draws nothing of."""


def drop_gradients(root: ET.Element) -> int:
    """Take the gradients out of the prepared document: svgelements need not read them.

    Run last, once every pass that reads a gradient has (:func:`resolve_paint_references`,
    the masks). svgelements paints a ``url(…)`` fill or stroke black whether its gradient
    is there or not, and reads a gradient and its stops into elements that are neither
    drawn shapes nor clips (a ``clip-path`` naming one is ignored either way), so the
    shapes it gives are the same without them; Inkscape drawings hold many (the Tango
    icons: 8 000 of 19 000 elements, 47 % of the bytes), each read and copied by
    svgelements. Kept: a gradient holding anything else (a shape inside it would be read
    as drawn), and one holding an element a ``<use>`` places.

    Returns:
        How many gradients were taken out (with their content).
    """
    placed: set[str] = set()
    found: list[tuple[ET.Element, ET.Element]] = []
    for parent in root.iter():
        for child in parent:
            kind = local_name(child)
            if kind == "use":  # any href: svgelements' or a mangled namespace's
                placed.update(v.strip()[1:] for k, v in child.attrib.items() if k.endswith("href"))
            elif kind in _GRADIENTS:
                found.append((parent, child))
    dropped = 0
    for parent, gradient in found:
        content = list(gradient.iter())
        if all(local_name(e) in _GRADIENT_CONTENT for e in content) and not any(
            e.get("id") in placed for e in content
        ):
            parent.remove(gradient)
            dropped += 1
    return dropped


def resolve_percentages(root: ET.Element, viewport: tuple[float, float]) -> None:
    """Write every percentage length of a shape as user units, as SVG resolves it.

    A percentage is of the nearest viewport's width (``x``, ``cx``, ``width``, ``x1``,
    ``x2``, a rect's ``rx``), height (``y``, ...; a rect's ``ry``) or normalised diagonal
    ``sqrt((w² + h²) / 2)`` (``r``; an ellipse's ``rx`` and ``ry`` are of the width and the
    height) (SVG 1.1 §7.10). The viewport is the document's, or a nested ``<svg>``'s
    (:func:`viewport_size`), whose own ``x``, ``y``, ``width`` and ``height`` are
    resolved too. svgelements resolves them against other sizes: a rect at ``x="10%"
    width="50%"`` in a 200 × 100 viewBox would be cut from x 10 to 60 instead of 20 to 120.

    Args:
        root: the ``<svg>`` element.
        viewport: its viewport's width and height, user units.
    """
    stack: list[tuple[ET.Element, tuple[float, float]]] = [(root, viewport)]
    while stack:
        element, (w, h) = stack.pop()
        kind = local_name(element)
        nested = kind == "svg" and element is not root
        for attr in _VIEWPORT_ATTRS if nested else LENGTH_ATTRS.get(kind or "", ()):
            match = PERCENT.fullmatch(element.get(attr) or "")
            if match is None:
                continue
            if attr in _ACROSS or (attr == "rx" and kind in ("rect", "ellipse")):
                base = w
            elif attr in _DOWN or (attr == "ry" and kind in ("rect", "ellipse")):
                base = h
            else:
                base = math.sqrt((w * w + h * h) / 2.0)
            element.set(attr, repr(float(match.group(1)) / 100.0 * base))
        inner = (w, h)
        if nested:
            inner = viewport_size(element, inner)
        stack.extend((child, inner) for child in element)


def viewport_size(element: ET.Element, outer: tuple[float, float]) -> tuple[float, float]:
    """The size, user units, a nested ``<svg>`` gives its content's percentages.

    Its ``viewBox``'s, else its own ``width`` and ``height`` (a percentage of ``outer``,
    the nearest viewport's size; 100 % when not given) (SVG 1.1 §7.10; resvg's
    structure/svg/nested-svg-with-relative-width-and-height.svg).
    """
    box = viewbox_size(element)
    return box if box is not None else viewport_extent(element, outer)


def viewport_extent(element: ET.Element, outer: tuple[float, float]) -> tuple[float, float]:
    """A nested ``<svg>``'s own ``width`` and ``height``, user units (100 % when not given).

    ``outer``: the nearest viewport's size, for percentages. What its viewBox, if any,
    is scaled into; a 0 shows nothing (SVG 1.1 §7.10: "disables rendering").
    """
    return (
        _viewport_length(element.get("width"), outer[0]),
        _viewport_length(element.get("height"), outer[1]),
    )


def _viewport_length(text: str | None, outer: float) -> float:
    """A nested ``<svg>``'s ``width`` or ``height`` in user units (px: 96 per inch)."""
    if text is None:
        return outer
    match = PERCENT.fullmatch(text)
    if match is not None:
        return float(match.group(1)) / 100.0 * outer
    try:
        value = float(se.Length(text).value(ppi=96.0))
    except (ValueError, TypeError):
        return outer  # a bad length is refused where it is read
    return value if math.isfinite(value) else outer


def viewbox_empty(element: ET.Element) -> bool:
    """Whether ``element``'s ``viewBox`` has a width or height of 0, which shows nothing.

    SVG 1.1 §7.7: "A value of zero disables rendering of the element" (a negative one, or
    a malformed ``viewBox``, only invalidates the attribute).
    """
    box = (element.get("viewBox") or "").replace(",", " ").split()
    try:
        return len(box) == 4 and 0.0 in (float(box[2]), float(box[3]))
    except ValueError:
        return False


def viewbox_size(element: ET.Element) -> tuple[float, float] | None:
    """``(width, height)`` of ``element``'s ``viewBox``, or ``None`` without a good one."""
    box = (element.get("viewBox") or "").replace(",", " ").split()
    try:
        if len(box) == 4 and float(box[2]) > 0 and float(box[3]) > 0:
            return (float(box[2]), float(box[3]))
    except ValueError:
        pass  # a bad viewBox is refused where it is read
    return None
