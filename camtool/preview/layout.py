"""Page layout of a preview: title band, main panel, right column (inset, colour scale), legend.

Design notes: docs/internals.md, ``camtool/preview/layout.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, TypeAlias

from camtool.model.program import Program, Rapid
from camtool.model.shapes import BBox, Drawing, Line, bbox_union
from camtool.model.units import fmt_num
from camtool.preview import program_layers as pl
from camtool.preview import trace_layers as tl
from camtool.preview.scene import (
    Circle,
    Layer,
    Panel,
    Path,
    Polylines,
    Rect,
    Scene,
    Shape,
    Style,
    Text,
    expand,
    mark_box,
    nice_length,
    polyline,
    ramp_colour,
    text_width,
)
from camtool.verify.report import error_text

if TYPE_CHECKING:
    from camtool.model.machine import Machine
    from camtool.verify.motion import StepTrace
    from camtool.verify.verifier import Verification

TIMED_MOVES = 20_000
"""Most moves a preview times by a step simulation; a bigger program at programmed feeds
(simulating it is ``camtool verify``'s work: minutes and memory, not a picture's)."""
AREA_IN_VIEW = 4.0
"""Largest work-area / part extent ratio at which the whole work area is in view."""


@dataclass(frozen=True)
class Content:
    """What to draw (see :func:`camtool.preview.render_preview`)."""

    program: Program | None
    drawing: Drawing | None
    verification: Verification | None
    work_area: BBox | None
    target_name: str
    time: tuple[float, str] | None
    edge_radius_mm: float
    title: str | None
    width_px: int
    sections: tuple[pl.Section, ...] = ()
    resolution_mm: float | None = None
    """The machine's resolution (its step or the code's quantum, the coarser), mm: the
    program's extent in the title is rounded to it; ``None``: to 0.001 mm."""

    @cached_property
    def cut_box(self) -> BBox | None:
        """The program's cutting moves' box, mm (``None``: no program or no cut)."""
        return None if self.program is None else program_box(self.program, cutting_only=True)

    @cached_property
    def moves_box(self) -> BBox | None:
        """The box of all the program's moves, mm (``None``: no program or no move)."""
        return None if self.program is None else program_box(self.program)


def program_box(program: Program, *, cutting_only: bool = False) -> BBox | None:
    """:meth:`Program.bbox` in one pass and constant memory; ``None`` when it has no move.

    A picture asks for it several times: :class:`Content` keeps each.
    """
    x0 = y0 = math.inf
    x1 = y1 = -math.inf
    for move, seg in program.segments():
        if cutting_only and isinstance(move, Rapid):
            continue
        b = seg.bbox()
        x0, y0, x1, y1 = min(x0, b[0]), min(y0, b[1]), max(x1, b[2]), max(y1, b[3])
    return None if x0 > x1 else (x0, y0, x1, y1)


def part_box(c: Content) -> BBox:
    """What the title gives the size of: the cutting moves, else the drawing, else all moves."""
    if c.cut_box is not None:
        return c.cut_box
    if c.drawing is not None and c.drawing.contours:
        return c.drawing.bbox()
    if c.moves_box is not None:
        return c.moves_box
    raise ValueError("nothing to draw: no moves and no contours")


def view_box(c: Content) -> tuple[BBox, bool]:
    """The main view (mm) and whether the whole work area is in it."""
    boxes = [part_box(c)]
    if c.moves_box is not None:
        boxes.append(c.moves_box)
    if c.drawing is not None and c.drawing.contours:
        boxes.append(c.drawing.bbox())
    view = bbox_union(boxes)
    area = c.work_area
    if area is None:
        return view, False
    extent = max(view[2] - view[0], view[3] - view[1], 1e-6)
    if max(area[2] - area[0], area[3] - area[1]) <= AREA_IN_VIEW * extent:
        return bbox_union([view, area]), True
    return view, False


def compose(c: Content) -> Scene:
    """The whole preview scene of ``c``.

    Raises:
        ValueError: there is nothing to draw.
    """
    view = view_box(c)[0]
    u = max(view[2] - view[0], view[3] - view[1], 1e-3) / 100.0
    frame = expand(view, 6.0 * u)
    frame = _at_least(frame, 30.0 * u)  # a flat part still gets a readable strip
    v = c.verification
    worst = v is not None and v.deviation.block >= 0
    column = 56.0 * u if worst else 0.0
    lines = _title_lines(c)
    title_h = 3.0 * u + 5.5 * u * len(lines)
    right = frame[2] + column
    scale_bar, legend, legend_h = _legend(c, frame, u, right - frame[0])
    column_h = 90.0 * u if worst else 0.0
    bottom = min(frame[1] - legend_h, frame[3] - column_h)
    page = (frame[0] - 2 * u, bottom - 2 * u, right + 2 * u, frame[3] + title_h + 2 * u)
    furniture = [
        Layer("background", (Rect(page, Style(fill="#ffffff")),)),
        _title(lines, page, frame[3] + 3.0 * u, u),
        scale_bar,
        legend,
    ]
    pixel_mm = (page[2] - page[0]) / c.width_px
    main = tuple(_main_layers(c, u, frame, pixel_mm))
    panels = [Panel("main", frame, frame, main, border=None)]
    if worst and v is not None:
        inset, labels = _column(v, frame, u)
        furniture.extend(labels)
        panels.append(inset)
    page_panel = Panel("page", page, page, tuple(furniture), clip=False)
    return Scene(page, c.width_px, (page_panel, *panels))


def _at_least(box: BBox, size: float) -> BBox:
    """``box`` widened and heightened about its centre to at least ``size``."""
    x0, y0, x1, y1 = box
    dx, dy = max(0.0, size - (x1 - x0)) / 2, max(0.0, size - (y1 - y0)) / 2
    return (x0 - dx, y0 - dy, x1 + dx, y1 + dy)


def _main_layers(c: Content, u: float, frame: BBox, pixel_mm: float) -> list[Layer]:
    layers: list[Layer] = []
    if c.work_area is not None:
        layers.append(pl.work_area_layer(c.work_area, u))
    if c.drawing is not None and c.drawing.contours:
        layers.append(pl.drawing_layer(c.drawing, u))
    v = c.verification
    worst = None
    if v is not None and v.deviation.block >= 0:
        worst = tl.worst_layer("worst", v, u, view=frame)
    marks = [mark_box(s) for s in worst.shapes if isinstance(s, Text | Circle)] if worst else []
    program = []
    if c.program is not None:
        program = pl.program_layers(
            c.program,
            u,
            edge_radius_mm=c.edge_radius_mm,
            sections=c.sections,
            pixel_mm=pixel_mm,
            frame=frame,
            clear=marks,
        )
    layers.extend(layer for layer in program if layer.id == "tool-width")
    if v is not None:
        points, run, dev_um = tl.cutting_trace(v)
        pieces = tl.binned_polylines(points, run, dev_um, tolerance=u / 5.0, top_um=tl.top_um(v))
        layers.append(tl.trace_layer("trace", pieces, 1.1 * u))
    layers.extend(layer for layer in program if layer.id != "tool-width")
    layers.append(pl.zero_layer(frame, u))
    if v is not None and v.against is not None and v.against.not_cut:
        numbers = [mark_box(s) for layer in program for s in layer.shapes if isinstance(s, Text)]
        layers.append(tl.not_cut_layer("not-cut", v.against.not_cut, u, clear=marks + numbers))
    if worst is not None:
        layers.append(worst)
    return [layer for layer in layers if layer.shapes]


def extent_text(c: Content) -> str:
    """The part's size and the toolpath's extent, apart.

    ``"part 100 × 60 mm, toolpath X −1.5…101.5 Y −1.5…61.5 mm"`` with a drawing;
    ``"toolpath 103 × 63 mm, X −1.5…101.5 Y −1.5…61.5 mm"`` without one (an
    offset toolpath is not the part); ``"part 100 × 60 mm"`` for a drawing alone.
    """
    parts = []
    has_drawing = c.drawing is not None and bool(c.drawing.contours)
    if c.drawing is not None and has_drawing:
        parts.append(f"part {size_text(c.drawing.bbox())}")
    step = c.resolution_mm
    if c.cut_box is not None:
        box = c.cut_box
        small = _is_small(box)
        x0, y0, x1, y1 = (length(v, um=small, step_mm=step).replace("-", "−") for v in box)
        span = f"X {x0}…{x1} Y {y0}…{y1} {'µm' if small else 'mm'}"
        size = size_text(box, step_mm=step)
        parts.append(f"toolpath {span}" if has_drawing else f"toolpath {size}, {span}")
    return ", ".join(parts) or size_text(part_box(c))


def _title_lines(c: Content) -> list[str]:
    facts = [c.target_name] if c.target_name else []
    facts.append(extent_text(c))
    if c.time is not None:
        facts.append(f"≈ {duration(c.time[0])} {c.time[1]}")
    lines = [c.title] if c.title else []
    lines.append(" · ".join(facts))
    v = c.verification
    if v is not None:
        text = f"verified: max deviation {fmt_num(v.deviation.max_um, 2)} µm"
        if v.deviation.block >= 0:
            text += f" ({tl.worst_label(v).split(', ', 1)[1]})"
        text += f", rms {fmt_num(v.deviation.rms_um, 2)} µm"
        if v.along is not None:
            text += f"; shortfall along the path {fmt_num(v.along.shortfall_um, 2)} µm"
        lines.append(text)
        against = _against_line(v)
        if against:
            lines.append(against)
        lines.append(budget_text(v))
    return lines


def _against_line(v: Verification) -> str:
    """The title line of the drawing comparison ("" when no drawing was given)."""
    a = v.against
    if a is None:
        return "" if v.against_skipped is None else "the drawing: not compared (see the warnings)"
    text = f"against the drawing: max {fmt_num(a.max_um, 2)} µm"
    if a.not_cut:
        n = len(a.not_cut)
        worst = max(f.error_um for f in a.not_cut)
        text += (
            f" where cut as drawn; {n} feature{'s' if n > 1 else ''} not cut as drawn "
            f"with this tool (max {error_text(worst)})"
        )
    return text


def _title(lines: list[str], page: BBox, base: float, u: float) -> Layer:
    """Title lines, the first bold, shrunk to fit the page width."""
    width = page[2] - page[0] - 4 * u
    shapes = []
    y = base + 5.5 * u * (len(lines) - 1) + u
    for i, line in enumerate(lines):
        size = 3.6 * u if i == 0 else 3.0 * u
        size = min(size, size * width / max(text_width(line, size, bold=i == 0), 1e-9))
        shapes.append(Text((page[0] + 2 * u, y), line, size, bold=i == 0))
        y -= 5.5 * u
    return Layer("title", tuple(shapes))


def _legend(c: Content, frame: BBox, u: float, width: float) -> tuple[Layer, Layer, float]:
    """The scale bar, then the legend entries flowing in rows under the main panel.

    Returns:
        The ``scale-bar`` and ``legend`` layers and the height they take below the frame.
    """
    bar = nice_length(20.0 * u)
    x0, y = frame[0] + u, frame[1] - 5.0 * u
    label = f"{bar:g} mm" if bar >= 1.0 else f"{bar * 1000.0:.4g} µm"
    scale = Layer(
        "scale-bar",
        (
            Path(((_line((x0, y), (x0 + bar, y)),),), Style("#000000", 0.5 * u)),
            Path(
                (
                    (_line((x0, y - u), (x0, y + u)),),
                    (_line((x0 + bar, y - u), (x0 + bar, y + u)),),
                ),
                Style("#000000", 0.3 * u),
            ),
            Text((x0 + bar + 1.5 * u, y - u), label, 2.8 * u),
        ),
    )
    shapes: list[Shape] = []
    x = x0 + bar + 4.5 * u + text_width(label, 2.8 * u)
    for glyph, text in _entries(c, u):
        need = 6.0 * u + text_width(text, 2.6 * u) + 3.0 * u
        if x + need > frame[0] + width:
            x, y = x0, y - 5.0 * u
        shapes.extend(glyph(x, y))
        shapes.append(Text((x + 6.0 * u, y - 0.9 * u), text, 2.6 * u, "#333333"))
        x += need
    return scale, Layer("legend", tuple(shapes)), frame[1] - y + 3.0 * u


def _line(a: tuple[float, float], b: tuple[float, float]) -> Line:
    return Line(a, b)


Glyph: TypeAlias = Callable[[float, float], tuple[Shape, ...]]


def _entries(c: Content, u: float) -> list[tuple[Glyph, str]]:
    """Legend entries for what the picture holds: ``(glyph at (x, y), label)``."""

    def stroke(style: Style) -> Glyph:
        return lambda x, y: (Path(((_line((x, y), (x + 4.5 * u, y)),),), style),)

    def start(x: float, y: float) -> tuple[Shape, ...]:
        fill = Style(fill=pl.START_COLOUR)
        arrow = polyline([(x + 1.5 * u, y + 0.5 * u), (x + 4.5 * u, y), (x + 1.5 * u, y - 0.5 * u)])
        return (Circle((x + 0.8 * u, y), 0.8 * u, fill), Polylines((arrow,), fill, closed=True))

    def band(x: float, y: float) -> tuple[Shape, ...]:
        style = Style(fill=pl.TOOL_COLOUR, opacity=pl.TOOL_OPACITY)
        return (Rect((x, y - 1.2 * u, x + 4.5 * u, y + 1.2 * u), style),)

    def change(x: float, y: float) -> tuple[Shape, ...]:
        box = (x + 1.0 * u, y - 1.2 * u, x + 3.4 * u, y + 1.2 * u)
        return (Rect(box, Style(pl.CHANGE_COLOUR, 0.4 * u)),)

    def marker(x: float, y: float) -> tuple[Shape, ...]:
        return tl.not_cut_marker((x + 2.2 * u, y), u)

    def ramp(x: float, y: float) -> tuple[Shape, ...]:
        return tuple(
            Path(
                ((_line((x + i * 1.5 * u, y), (x + (i + 1) * 1.5 * u, y)),),),
                Style(ramp_colour(i / 2), 1.1 * u),
            )
            for i in range(3)
        )

    out: list[tuple[Glyph, str]] = []
    p = c.program
    if c.sections:
        for number, (label, _, _) in enumerate(c.sections):
            out.append((stroke(Style(pl.section_colour(number), 0.5 * u)), label))
    elif p is not None and any(not isinstance(m, Rapid) for m in p.moves):
        out.append((stroke(Style(pl.CUT_COLOUR, 0.5 * u)), "cut"))
    if p is not None and any(isinstance(m, Rapid) for m in p.moves):
        out.append((stroke(Style(pl.RAPID_COLOUR, 0.4 * u, dash=(1.2 * u, 0.9 * u))), "rapid"))
    if p is not None and any(not isinstance(m, Rapid) for m in p.moves):
        out.append((start, "start, direction, order"))
    if c.edge_radius_mm > 0 and p is not None:
        out.append((band, f"tool width (r = {c.edge_radius_mm:g} mm)"))
    if c.drawing is not None:
        out.append((stroke(Style(pl.DRAWING_COLOUR, 0.4 * u)), "drawing"))
    if c.work_area is not None:
        label = (
            "work area" if view_box(c)[1] else f"work area {size_text(c.work_area)}, partly shown"
        )
        out.append((stroke(Style(pl.AREA_COLOUR, 0.4 * u, dash=(1.5 * u, u))), label))
    if p is not None and pl.change_marks(p, u):
        out.append((change, "tool change"))
    if p is not None and pl.tab_segments(p):
        out.append((stroke(Style(pl.TAB_COLOUR, 1.0 * u)), "tab"))
    if c.verification is not None:
        out.append((ramp, "simulated tool centre"))
    v = c.verification
    if v is not None and v.against is not None and v.against.not_cut:
        out.append((marker, "not cut as drawn with this tool"))
    return out


def budget_text(v: Verification) -> str:
    """The title's error-budget line: the dominant source of the largest figure, or why none."""
    budget = v.error_budget
    if budget.skipped is not None:
        return f"error budget skipped: {budget.skipped.split(':')[0]}"
    verdict = budget.dominant_text()
    if not budget.without:
        return "error budget: this machine models no error source that can be switched off"
    if verdict is None:
        return "error budget: no source changes any figure"
    return f"error budget: {verdict}, one source off at a time"


def _column(v: Verification, frame: BBox, u: float) -> tuple[Panel, list[Layer]]:
    """The zoom inset on the worst point, its scale bar and the deviation colour scale."""
    side = 48.0 * u
    x0 = frame[2] + 5.0 * u
    top = frame[3] - 6.0 * u
    box = (x0, top - side, x0 + side, top)
    window = tl.inset_window(v)
    inset = Panel(
        "inset",
        box,
        window,
        tl.inset_layers(v, window),
        background="#ffffff",
        border=Style("#555555", 0.3 * u),
    )
    zoom = side / (window[2] - window[0])
    window_um = (window[2] - window[0]) * 1000.0
    bar_um = nice_length(window_um / 4.0)
    bar = bar_um / 1000.0 * zoom
    y = box[1] - 5.0 * u
    labels = Layer(
        "inset-labels",
        (
            Text(
                (x0, top + 2.0 * u),
                f"zoom × {zoom_text(zoom)} on the worst point",
                2.8 * u,
                bold=True,
            ),
            Path(((_line((x0, y), (x0 + bar, y)),),), Style("#000000", 0.5 * u)),
            Text((x0 + bar + 1.5 * u, y - u), f"{bar_um:.4g} µm", 2.8 * u),
            Text((x0, y - 5.0 * u), "blue: programmed path", 2.4 * u, "#333333"),
            Text((x0, y - 8.5 * u), "colour: simulated tool centre", 2.4 * u, "#333333"),
        ),
    )
    return inset, [labels, _colour_scale(v, x0, y - 16.0 * u, side, u)]


def _colour_scale(v: Verification, x0: float, y: float, width: float, u: float) -> Layer:
    """The deviation scale: one box per colour class, ticks in µm, a caption."""
    top = tl.top_um(v)
    w = width / tl.BINS
    shapes: list[Shape] = [
        Rect(
            (x0 + i * w, y - 3.0 * u, x0 + (i + 1) * w + 1e-9, y),
            Style(fill=ramp_colour((i + 0.5) / tl.BINS)),
        )
        for i in range(tl.BINS)
    ]
    for f, anchor in ((0.0, "start"), (0.5, "middle"), (1.0, "end")):
        shapes.append(Text((x0 + f * width, y - 6.5 * u), f"{f * top:.3g}", 2.6 * u, anchor=anchor))
    shapes.append(Text((x0, y + 1.5 * u), "deviation from the path (µm)", 2.4 * u))
    return Layer("colour-scale", tuple(shapes))


def time_basis(machine: Machine, trace: StepTrace) -> str:
    """How :func:`camtool.verify.clock.block_times_s` timed a trace, in words."""
    if trace.block_time_s is not None:
        return "by the servo simulation"
    model = machine.timing.get("model") if machine.timing else None
    return f"by the {model} timing model" if model else "at programmed feeds"


def machine_time(program: Program, machine: Machine) -> tuple[float, str]:
    """Seconds ``program`` takes on ``machine`` by its timing model, and the basis in words.

    Simulates the steps (no measurement); see :mod:`camtool.verify.clock`.

    Raises:
        CamtoolError: the machine profile is invalid for the simulator.
    """
    from camtool.verify.report import block_times
    from camtool.verify.trace_sources import simulate

    trace = simulate(program, machine)
    return float(block_times(trace, program, machine).sum()), time_basis(machine, trace)


def estimated_time(
    program: Program | None, machine: Machine | None, verification: Verification | None
) -> tuple[float, str] | None:
    """The best time estimate (see the module docstring): ``(seconds, basis)`` or ``None``."""
    if verification is not None:
        return verification.time_s, time_basis(verification.machine, verification.trace)
    if program is None or not any(not isinstance(m, Rapid) for m in program.moves):
        return None
    if machine is not None and len(program.moves) <= TIMED_MOVES:
        return machine_time(program, machine)
    if machine is not None:
        return program.cutting_time_s(), (
            f"at programmed feeds, cuts only ({len(program.moves)} moves: not simulated)"
        )
    return program.cutting_time_s(), "at programmed feeds, cuts only"


def duration(seconds: float) -> str:
    """``"0.0735 s"``, ``"0.8 s"``, ``"42 s"``, ``"3 min 12 s"``, ``"2 h 05 min"``."""
    if 0 < seconds < 0.1:
        return f"{seconds:.3g} s"
    if seconds < 10:
        return f"{seconds:.1f} s"
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    if whole < 3600:
        return f"{whole // 60} min {whole % 60} s"
    minutes = round(seconds / 60)
    return f"{minutes // 60} h {minutes % 60:02d} min"


def zoom_text(zoom: float) -> str:
    """A zoom factor: whole from 10 on, 2 significant digits below (``"0.42"``, never ``"0"``)."""
    return f"{zoom:.0f}" if zoom >= 10 else f"{zoom:.2g}"


def length(mm: float, *, um: bool = False, step_mm: float | None = None) -> str:
    """A length for titles: mm to at most 3 decimals (``"4.5"``); ``um``: in µm to 0.01 µm.

    ``step_mm``: the machine's resolution. The length is then written as the shortest
    decimal within half a step of it (at most :data:`MOST_DECIMALS` in mm): the machine
    cannot tell the two apart, so ``34.999`` and ``-0.001`` on a 0.004 mm machine are
    ``"35"`` and ``"0"``, and ``12.345`` stays ``"12.345"``. Never ``"-0"``.
    """
    value = mm * 1000.0 if um else mm
    if step_mm is None:
        text = f"{value:.{2 if um else 3}f}"
    else:
        half = step_mm * (1000.0 if um else 1.0) / 2.0
        most = MOST_DECIMALS - 3 if um else MOST_DECIMALS
        text = f"{value:.{most}f}"
        for places in range(-6, most + 1):  # tens of µm first for a part in µm
            if abs(round(value, places) - value) <= half:
                text = f"{value:.{places}f}" if places >= 0 else f"{round(value, places):.0f}"
                break
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text.strip("-0.") == "" else text


MOST_DECIMALS = 5
"""Most decimals of a title's mm (0.01 µm)."""


SMALL_MM = 1.0
"""Parts under this size (both sides) are labelled in µm."""


def _is_small(box: BBox) -> bool:
    return max(box[2] - box[0], box[3] - box[1]) < SMALL_MM


def size_text(box: BBox, *, step_mm: float | None = None) -> str:
    """``"5 × 4.5 mm"``: width × height of ``box``; ``"980 × 120 µm"`` for a part under 1 mm.

    ``step_mm``: round to the machine's resolution (:func:`length`).
    """
    small = _is_small(box)
    w = length(box[2] - box[0], um=small, step_mm=step_mm)
    h = length(box[3] - box[1], um=small, step_mm=step_mm)
    return f"{w} × {h} {'µm' if small else 'mm'}"
