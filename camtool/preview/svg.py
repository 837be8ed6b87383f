"""Write a preview scene as SVG: direct XML, exact arcs, deterministic bytes.

The SVG user unit is the page millimetre with +Y down, so a world point
``(x, y)`` is written ``(x, -y)``; a layer is a ``<g id="...">``, the zoom
inset a nested ``<svg>`` whose ``viewBox`` is its window. Numbers are written
with a fixed number of decimals for the panel's size (about 1/10 000 of it),
never ``-0``; nothing depends on the date or the machine, so the same scene
always gives the same bytes (CI can diff them).
"""

from __future__ import annotations

import math
from xml.sax.saxutils import escape, quoteattr

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Arc, BBox, Segment
from camtool.preview.scene import (
    Circle,
    Layer,
    Panel,
    Path,
    Polylines,
    Rect,
    Scene,
    Segments,
    Shape,
    Style,
    Text,
)


class _Numbers:
    """Formats numbers with ``digits`` decimals, trailing zeros dropped, never ``-0``."""

    def __init__(self, size: float) -> None:
        self.digits = max(1, min(9, 4 - math.floor(math.log10(max(size, 1e-12)))))

    def __call__(self, value: float) -> str:
        text = f"{value:.{self.digits}f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "", "-") else text

    def y(self, value: float) -> str:
        return self(-value)


def scene_svg(scene: Scene) -> str:
    """The SVG document of ``scene`` (text, Unix line ends, a final newline)."""
    x0, y0, x1, y1 = scene.page
    n = _Numbers(max(x1 - x0, y1 - y0))
    out = [
        '<svg xmlns="http://www.w3.org/2000/svg" '
        f'viewBox="{n(x0)} {n.y(y1)} {n(x1 - x0)} {n(y1 - y0)}" '
        f'width="{scene.width_px}" height="{scene.height_px}" font-family="sans-serif">',
        "<defs>",
        *(_clip(p, n) for p in scene.panels if p.clip),
        "</defs>",
    ]
    for panel in scene.panels:
        out.extend(_panel(panel, n))
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _clip(panel: Panel, n: _Numbers) -> str:
    return f'<clipPath id="clip-{panel.id}">{_rect(panel.frame, n)}</clipPath>'


def _rect(box: BBox, n: _Numbers, attrs: str = "") -> str:
    return (
        f'<rect x="{n(box[0])}" y="{n.y(box[3])}" width="{n(box[2] - box[0])}" '
        f'height="{n(box[3] - box[1])}"{attrs}/>'
    )


def _panel(panel: Panel, page: _Numbers) -> list[str]:
    if panel.frame == panel.window:
        clip = f' clip-path="url(#clip-{panel.id})"' if panel.clip else ""
        out = [f'<g id="{panel.id}"{clip}>']
        out.extend(_frame(panel, page))
        out.extend(line for layer in panel.layers for line in _layer(layer, page))
        out.append("</g>")
        return out
    n = _Numbers(panel.window[2] - panel.window[0])
    w, f = panel.window, panel.frame
    clip = f' clip-path="url(#clip-{panel.id})"' if panel.clip else ""
    out = [f'<g id="{panel.id}">', f"<g{clip}>"]
    out.extend(_frame(panel, page))
    out.append(
        f'<svg x="{page(f[0])}" y="{page.y(f[3])}" width="{page(f[2] - f[0])}" '
        f'height="{page(f[3] - f[1])}" viewBox="{n(w[0])} {n.y(w[3])} {n(w[2] - w[0])} '
        f'{n(w[3] - w[1])}">'
    )
    out.extend(line for layer in panel.layers for line in _layer(layer, n))
    out.extend(("</svg>", "</g>"))
    if panel.border is not None:
        border = Style(panel.border.stroke, panel.border.width)
        out.append(_rect(panel.frame, page, _style(border, page)))
    out.append("</g>")
    return out


def _frame(panel: Panel, n: _Numbers) -> list[str]:
    if panel.background is None:
        return []
    return [_rect(panel.frame, n, f' fill="{panel.background}"')]


def _layer(layer: Layer, n: _Numbers) -> list[str]:
    if not layer.shapes:
        return [f'<g id="{layer.id}"/>']
    return [f'<g id="{layer.id}">', *(_shape(s, n) for s in layer.shapes), "</g>"]


def _shape(shape: Shape, n: _Numbers) -> str:
    if isinstance(shape, Path):
        d = "".join(_chain(chain, n) for chain in shape.chains)
        return f'<path d="{d}"{_style(shape.style, n)}/>'
    if isinstance(shape, Polylines):
        d = "".join(_points(line, n, shape.closed) for line in shape.lines)
        rule = ' fill-rule="evenodd"' if shape.closed else ""
        return f'<path d="{d}"{_style(shape.style, n)}{rule}/>'
    if isinstance(shape, Segments):
        d = "".join(
            f"M{n(float(x0))} {n.y(float(y0))}L{n(float(x1))} {n.y(float(y1))}"
            for (x0, y0), (x1, y1) in shape.xy.tolist()
        )
        return f'<path d="{d}"{_style(shape.style, n)}/>'
    if isinstance(shape, Circle):
        cx, cy = shape.centre
        return (
            f'<circle cx="{n(cx)}" cy="{n.y(cy)}" r="{n(shape.radius)}"{_style(shape.style, n)}/>'
        )
    if isinstance(shape, Rect):
        return _rect(shape.box, n, _style(shape.style, n))
    return _text(shape, n)


def _text(t: Text, n: _Numbers) -> str:
    anchor = f' text-anchor="{t.anchor}"' if t.anchor != "start" else ""
    weight = ' font-weight="bold"' if t.bold else ""
    if t.halo:
        weight += (
            f' stroke="#ffffff" stroke-width="{n(t.size * 0.2)}" stroke-linejoin="round"'
            ' paint-order="stroke"'
        )
    return (
        f'<text x="{n(t.at[0])}" y="{n.y(t.at[1])}" font-size="{n(t.size)}" '
        f'fill="{t.colour}"{anchor}{weight}>{escape(t.text)}</text>'
    )


def _style(style: Style, n: _Numbers) -> str:
    parts = [f' fill="{style.fill}"' if style.fill else ' fill="none"']
    if style.stroke:
        cap = "" if style.dash else ' stroke-linecap="round"'
        parts.append(
            f' stroke="{style.stroke}" stroke-width="{n(style.width)}" stroke-linejoin="round"{cap}'
        )
        if style.dash:
            parts.append(f" stroke-dasharray={quoteattr(' '.join(n(d) for d in style.dash))}")
    if style.opacity < 1.0:
        parts.append(f' opacity="{style.opacity:g}"')
    return "".join(parts)


def _chain(chain: tuple[Segment, ...], n: _Numbers) -> str:
    """Path data of a chain: one M, then L for lines and A for arcs (full circles in two)."""
    if not chain:
        return ""
    x, y = chain[0].start
    d = [f"M{n(x)} {n.y(y)}"]
    here = chain[0].start
    for seg in chain:
        if seg.start != here:
            d.append(f"M{n(seg.start[0])} {n.y(seg.start[1])}")
        here = seg.end
        if isinstance(seg, Arc):
            for a in seg.split(2) if seg.is_full_circle else [seg]:
                large = 1 if abs(a.sweep) > math.pi else 0
                # The page's Y points down, so a clockwise arc (seen from +Z)
                # turns in SVG's positive-angle direction: sweep-flag 1.
                sweep = 1 if a.clockwise else 0
                r = n(a.radius)
                d.append(f"A{r} {r} 0 {large} {sweep} {n(a.end[0])} {n.y(a.end[1])}")
        else:
            d.append(f"L{n(seg.end[0])} {n.y(seg.end[1])}")
    return "".join(d)


def _points(line: npt.NDArray[np.float64], n: _Numbers, closed: bool) -> str:
    pts = [(n(float(x)), n.y(float(y))) for x, y in line]
    if not pts:
        return ""
    d = f"M{pts[0][0]} {pts[0][1]}" + "".join(f"L{x} {y}" for x, y in pts[1:])
    return d + ("Z" if closed else "")
