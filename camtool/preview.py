"""Preview pictures: a program drawn over the target's work area, as SVG.

A first version for the docs: cutting moves in blue and rapids in dashed yellow
(the colours of the seed-000 GUI, S000-24), the start of each contour marked
and numbered in cutting order with an arrow for its direction, the work area,
a 1 mm scale bar and a title. Arcs are drawn as exact SVG arcs. The output is
deterministic: the same program gives the same bytes.

Coordinates: the SVG user unit is 1 mm; the drawing's +Y is up on the page.
"""

from __future__ import annotations

import math
from xml.sax.saxutils import escape

from camtool.geometry import Arc, BBox, Segment, bbox_union
from camtool.program import Program, Rapid

CUT_COLOUR = "#1f4fd1"
RAPID_COLOUR = "#d4a900"
AREA_COLOUR = "#9a9a9a"


def _n(value: float) -> str:
    """A coordinate written with 4 decimals, never ``-0``."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def program_svg(program: Program, *, work_area: BBox | None = None, title: str = "") -> str:
    """Draw ``program`` as an SVG document (1 user unit = 1 mm, +Y up).

    Args:
        program: the program to draw.
        work_area: the machine's ``(xmin, ymin, xmax, ymax)`` in mm, drawn as a
            dashed frame; ``None`` draws none.
        title: a line of text above the picture.

    Returns:
        The SVG document as text.

    Raises:
        ValueError: the program has no moves.
    """
    box = program.bbox() if work_area is None else bbox_union([program.bbox(), work_area])
    size = max(box[2] - box[0], box[3] - box[1], 1e-3)
    pad, stroke = 0.08 * size, size / 400
    x0 = box[0] - pad
    width, height = box[2] - box[0] + 2 * pad, box[3] - box[1] + 3 * pad
    top = box[3] + 2 * pad  # room for the title
    out = [
        '<svg xmlns="http://www.w3.org/2000/svg" '
        f'viewBox="{_n(x0)} {_n(-top)} {_n(width)} {_n(height)}" '
        f'width="{_n(width * 60)}" height="{_n(height * 60)}">',
        f'<rect x="{_n(x0)}" y="{_n(-top)}" width="{_n(width)}" height="{_n(height)}" '
        'fill="white"/>',
    ]
    if work_area is not None:
        ax0, ay0, ax1, ay1 = work_area
        out.append(
            f'<rect id="work-area" x="{_n(ax0)}" y="{_n(-ay1)}" width="{_n(ax1 - ax0)}" '
            f'height="{_n(ay1 - ay0)}" fill="none" stroke="{AREA_COLOUR}" '
            f'stroke-width="{_n(stroke)}" stroke-dasharray="{_n(stroke * 4)}"/>'
        )
    out.extend(_moves(program, stroke))
    out.extend(_starts(program, stroke, size))
    out.extend(_scale_bar(x0 + pad, -(box[1] - pad / 2), stroke, size))
    if title:
        out.append(
            f'<text x="{_n(x0 + pad)}" y="{_n(-(top - pad * 0.7))}" font-family="sans-serif" '
            f'font-size="{_n(size / 22)}">{escape(title)}</text>'
        )
    out.append("</svg>")
    return "\n".join(out) + "\n"


def _moves(program: Program, stroke: float) -> list[str]:
    cuts: list[str] = []
    rapids: list[str] = []
    for move, seg in program.segments():
        sx, sy = seg.start
        if isinstance(move, Rapid):
            rapids.append(_straight(seg))
        elif isinstance(seg, Arc):
            pieces = seg.split(2) if seg.is_full_circle else [seg]
            d = f"M{_n(sx)} {_n(-sy)}"
            for a in pieces:
                large = 1 if abs(a.sweep) > math.pi else 0
                # On the page Y points down, so a clockwise arc (seen from +Z)
                # turns in SVG's positive-angle direction: sweep-flag 1.
                sweep = 1 if a.clockwise else 0
                r = _n(a.radius)
                d += f"A{r} {r} 0 {large} {sweep} {_n(a.end[0])} {_n(-a.end[1])}"
            cuts.append(d)
        else:
            cuts.append(_straight(seg))
    return [
        f'<path id="rapids" d="{"".join(rapids)}" fill="none" stroke="{RAPID_COLOUR}" '
        f'stroke-width="{_n(stroke)}" stroke-dasharray="{_n(stroke * 3)}"/>',
        f'<path id="cuts" d="{"".join(cuts)}" fill="none" stroke="{CUT_COLOUR}" '
        f'stroke-width="{_n(stroke * 1.5)}" stroke-linejoin="round"/>',
    ]


def _straight(seg: Segment) -> str:
    """SVG path data of a straight segment (page Y = −drawing Y)."""
    return f"M{_n(seg.start[0])} {_n(-seg.start[1])}L{_n(seg.end[0])} {_n(-seg.end[1])}"


def _starts(program: Program, stroke: float, size: float) -> list[str]:
    """A dot, the contour number and a direction arrow at each contour's start."""
    out = ['<g id="starts" font-family="sans-serif">']
    seen: set[int] = set()
    for move, seg in program.segments():
        if isinstance(move, Rapid) or move.contour in seen:
            continue
        seen.add(move.contour)
        sx, sy = seg.start
        tx, ty = _tangent(seg)
        arrow = size / 60
        tip = (sx + tx * arrow * 1.6, sy + ty * arrow * 1.6)
        left = (sx + tx * arrow * 0.4 - ty * arrow * 0.5, sy + ty * arrow * 0.4 + tx * arrow * 0.5)
        right = (sx + tx * arrow * 0.4 + ty * arrow * 0.5, sy + ty * arrow * 0.4 - tx * arrow * 0.5)
        out.append(f'<circle cx="{_n(sx)}" cy="{_n(-sy)}" r="{_n(stroke * 3)}" fill="#c0392b"/>')
        out.append(
            f'<path d="M{_n(tip[0])} {_n(-tip[1])}L{_n(left[0])} {_n(-left[1])}'
            f'L{_n(right[0])} {_n(-right[1])}Z" fill="#c0392b"/>'
        )
        out.append(
            f'<text x="{_n(sx - arrow)}" y="{_n(-sy - arrow)}" font-size="{_n(size / 30)}" '
            f'fill="#c0392b">{move.contour}</text>'
        )
    out.append("</g>")
    return out


def _tangent(seg: Segment) -> tuple[float, float]:
    """Unit direction of travel at a segment's start."""
    if isinstance(seg, Arc):
        rx, ry = seg.start[0] - seg.centre[0], seg.start[1] - seg.centre[1]
        tx, ty = (ry, -rx) if seg.clockwise else (-ry, rx)
    else:
        (x0, y0), (x1, y1) = seg.start, seg.end
        tx, ty = x1 - x0, y1 - y0
    length = math.hypot(tx, ty) or 1.0
    return tx / length, ty / length


def _scale_bar(x: float, y: float, stroke: float, size: float) -> list[str]:
    """A 1 mm bar (or 0.1 mm / 10 mm for small or large pictures) with its label."""
    length = 10.0 ** math.floor(math.log10(size / 3)) if size > 0 else 1.0
    label = f"{length:g} mm"
    return [
        f'<g id="scale-bar"><path d="M{_n(x)} {_n(y)}h{_n(length)}" stroke="black" '
        f'stroke-width="{_n(stroke * 2)}"/>'
        f'<text x="{_n(x + length + stroke * 6)}" y="{_n(y + size / 100)}" '
        f'font-family="sans-serif" font-size="{_n(size / 35)}">{label}</text></g>'
    ]
