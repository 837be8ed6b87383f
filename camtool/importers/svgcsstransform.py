"""The CSS ``transform`` property of an SVG element, made its ``transform`` attribute.

SVG 2 lets a transform come as a CSS property (a ``style`` attribute or a style sheet,
``transform: rotate(30deg) translate(5mm, 0)``), which wins over the ``transform``
attribute (CSS Transforms 1 §7, "The SVG transform attribute"; Chromium draws it so).
svgelements reads such a property its own way: a unitless ``rotate(30)``, which CSS
makes invalid and a viewer ignores, it applies; and ``transform-origin`` then folded
into the attribute (:func:`camtool.importers.svgvalues.fold_transform_origin`) would not
apply to it. So the property is read here, to CSS's grammar, and written as the
attribute svgelements reads; what cannot be written so is refused with what to do.

Design notes: docs/internals.md, ``camtool/importers/svgcsstransform.py``.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET

from camtool.importers.svgcheck import NUMBER
from camtool.importers.svgcss import inline_style, style_text

_PX = {"px": 1.0, "mm": 96.0 / 25.4, "cm": 96.0 / 2.54, "q": 96.0 / 101.6, "in": 96.0,
       "pt": 96.0 / 72.0, "pc": 16.0}  # fmt: skip
"""CSS absolute length units in px: one px is one user unit of the element's coordinates."""
_DEG = {"deg": 1.0, "grad": 0.9, "rad": 180.0 / math.pi, "turn": 360.0}
_ARGUMENT = re.compile(rf"\s*({NUMBER.pattern})([a-zA-Z%]*)\s*", re.ASCII)
_FUNCTION = re.compile(r"\s*([a-zA-Z0-9]+)\(([^()]*)\)\s*", re.ASCII)
_THREE_D = frozenset(
    {"matrix3d", "translate3d", "translatez", "scale3d", "scalez", "rotate3d", "rotatex",
     "rotatey", "rotatez", "perspective"}
)  # fmt: skip
_ALONE = ("translate", "rotate", "scale")
"""CSS Transforms 2's properties of one transform each, which svgelements does not read."""
_WORDS = ("transform", *_ALONE)
"""Words a ``style`` holds when :func:`move_css_transform` has anything to do."""
_DO = "apply the transform in the drawing program (Inkscape: Object > Transform)"


def move_css_transform(element: ET.Element) -> None:
    """Make ``element``'s CSS ``transform`` (of its ``style``) its ``transform`` attribute.

    ``none`` leaves no transform (the attribute's too: the property wins). Lengths in
    ``px``, ``mm``, ``cm``, ``Q``, ``in``, ``pt``, ``pc`` (a px is a user unit), angles in
    ``deg``, ``grad``, ``rad``, ``turn``; a bare 0 for either; ``scale`` by numbers or
    percentages. A ``transform-box`` other than ``view-box`` (turning about the shape's
    own box) is refused with any transform, as are 3D functions, percentages of a length,
    font-relative units and the properties ``translate``, ``rotate`` and ``scale``.

    Raises:
        ValueError: what cannot be read so, named, with what to do.
    """
    written = element.get("style", "")
    if not any(word in written for word in _WORDS) and element.get("transform-box") is None:
        return  # no transform, translate, rotate or scale property, no transform-box
    style = inline_style(element)
    for name in _ALONE:
        if name in style:
            raise ValueError(f"the CSS property {name!r} ({style[name]!r}) is not read; {_DO}")
    box = style.get("transform-box", element.get("transform-box", "view-box")).strip().lower()
    text = style.pop("transform", None)
    if text is not None:
        element.set("style", style_text(style))
        svg = svg_transform(text)
        if svg:
            element.set("transform", svg)
        else:
            element.attrib.pop("transform", None)
    if box != "view-box" and (element.get("transform") or "").strip():
        raise ValueError(
            f"transform-box {box!r} turns the shape about its own box, which camtool does "
            f"not measure; {_DO}"
        )


def svg_transform(text: str) -> str:
    """The CSS transform list ``text`` as an SVG ``transform`` attribute (``""``: none).

    Raises:
        ValueError: not a CSS transform list camtool reads (see :func:`move_css_transform`).
    """
    if text.strip().lower() == "none":
        return ""
    out: list[str] = []
    pos = 0
    while pos < len(text):
        match = _FUNCTION.match(text, pos)
        if match is None:
            if text[pos:].strip():
                raise ValueError(f"cannot read the CSS transform {text!r} at character {pos}")
            break
        out.append(_function(match[1].lower(), match[2], text))
        pos = match.end()
    if not out:
        raise ValueError(f"cannot read the CSS transform {text!r}")
    return " ".join(out)


def _function(name: str, body: str, text: str) -> str:
    """One CSS transform function as SVG's, or ValueError naming it."""
    if name in _THREE_D:
        raise ValueError(f"the CSS transform {text!r} is 3D ({name}); {_DO}")
    args = body.split(",") if body.strip() else []
    counts = {"matrix": (6,), "translate": (1, 2), "scale": (1, 2), "skew": (1, 2)}
    if len(args) not in counts.get(name, (1,)):
        raise ValueError(
            f"cannot read the CSS transform {text!r}: {name}() with {len(args)} argument(s) "
            "(CSS separates them with commas)"
        )
    if name == "matrix":
        return f"matrix({' '.join(repr(_number(a, text)) for a in args)})"
    if name in ("translate", "translatex", "translatey"):
        x, y = (_length(a, text) for a in [*args, "0"][:2])
        return {"translatex": f"translate({x!r} 0)", "translatey": f"translate(0 {x!r})"}.get(
            name, f"translate({x!r} {y!r})"
        )
    if name in ("scale", "scalex", "scaley"):
        sx = _scale(args[0], text)
        sy = _scale(args[1], text) if len(args) == 2 else sx
        return {"scalex": f"scale({sx!r} 1)", "scaley": f"scale(1 {sx!r})"}.get(
            name, f"scale({sx!r} {sy!r})"
        )
    if name == "rotate":
        return f"rotate({_angle(args[0], text)!r})"
    if name in ("skewx", "skewy"):
        return f"skew{name[-1].upper()}({_angle(args[0], text)!r})"
    if name == "skew":
        ax = _angle(args[0], text)
        ay = _angle(args[1], text) if len(args) == 2 else 0.0
        # x' = x + tan(ax)·y, y' = tan(ay)·x + y (CSS Transforms 1 §13.1): not skewX then skewY
        return f"matrix(1 {math.tan(math.radians(ay))!r} {math.tan(math.radians(ax))!r} 1 0 0)"
    raise ValueError(f"cannot read the CSS transform {text!r}: unknown function {name}()")


def _parts(arg: str, text: str) -> tuple[float, str]:
    match = _ARGUMENT.fullmatch(arg)
    if match is None:
        raise ValueError(f"cannot read {arg.strip()!r} in the CSS transform {text!r}")
    value = float(match[1])
    if not math.isfinite(value):
        raise ValueError(f"{arg.strip()!r} in the CSS transform {text!r} is not a finite number")
    return value, match[2].lower()


def _number(arg: str, text: str) -> float:
    value, unit = _parts(arg, text)
    if unit:
        raise ValueError(f"{arg.strip()!r} in the CSS transform {text!r} takes no unit")
    return value


def _scale(arg: str, text: str) -> float:
    value, unit = _parts(arg, text)
    if unit == "%":
        return value / 100.0
    return _number(arg, text)


def _length(arg: str, text: str) -> float:
    """A CSS length in px (user units)."""
    return _measured(arg, text, _PX, "10px, 5mm", "a length in px, mm, cm, Q, in, pt or pc")


def _angle(arg: str, text: str) -> float:
    """A CSS angle in degrees."""
    return _measured(arg, text, _DEG, "30deg", "an angle in deg, grad, rad or turn")


def _measured(arg: str, text: str, units: dict[str, float], example: str, what: str) -> float:
    """``arg`` in the unit of ``units`` whose factor is 1; a bare 0 is 0 (CSS Values 4)."""
    value, unit = _parts(arg, text)
    if unit in units:
        return value * units[unit]
    if not unit and value == 0.0:
        return 0.0
    if not unit:
        raise ValueError(
            f"{arg.strip()!r} in the CSS transform {text!r} has no unit, which CSS requires "
            f"({example}) and a viewer ignores the transform without; write it"
        )
    raise ValueError(
        f"{arg.strip()!r} in the CSS transform {text!r} is not {what} (camtool reads no "
        f"{unit}); {_DO}"
    )
