"""Layers of a program and its drawing: cuts, rapids, tool width, starts, order, work area.

Design notes: docs/internals.md, ``camtool/preview/program_layers.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from camtool.model.program import Program, Rapid, ToolChange
from camtool.model.shapes import Arc, BBox, Drawing, Line, Point, Segment
from camtool.preview.scene import (
    Circle,
    Layer,
    Path,
    Polylines,
    Rect,
    Segments,
    Style,
    Text,
    kept_indices,
    moved_inside,
    place_labels,
    polyline,
    text_box,
)
from camtool.preview.thin import CELL_PX, DETAIL_MOVES, Strokes

CUT_COLOUR = "#1f4fd1"
"""Cutting moves (blue, S000-24)."""
RAPID_COLOUR = "#d4a900"
"""Rapids (dashed yellow, S000-24)."""
AREA_COLOUR = "#9a9a9a"
"""The machine's work area (dashed grey)."""
START_COLOUR = "#c0392b"
"""Start dots, direction arrows and order numbers."""
DRAWING_COLOUR = "#6b6b6b"
"""The drawing under the program."""
TOOL_COLOUR = "#1f4fd1"
"""Tool width (translucent)."""
TOOL_OPACITY = 0.18
TAB_COLOUR = "#2ca02c"
"""Moves that rise onto a holding tab (green)."""
ZERO_COLOUR = "#000000"
"""The work zero's cross."""
Z_EPS = 1e-6
"""Z difference, mm, below which two heights are the same."""
SECTION_COLOURS = ("#1f4fd1", "#d62728", "#9467bd", "#e07b00", "#17becf", "#8c564b", "#e377c2")
"""Cutting moves of a job's operations in turn (the first is :data:`CUT_COLOUR`)."""
CHANGE_COLOUR = "#000000"
"""Tool change marks."""

Section = tuple[str, int, int]
"""A part of a program drawn in its own colour: ``(label, first move, end move)``."""


@dataclass(frozen=True)
class Run:
    """Cutting moves in a row: ``segments``, from ``program.moves[first]``, of ``contour``."""

    first: int
    contour: int
    segments: list[Segment]


def runs_of(program: Program, breaks: Sequence[int] = ()) -> list[Run]:
    """The cutting moves as runs, in cutting order.

    A run ends at a rapid, a new contour or a move index in ``breaks`` (where a
    section of the picture starts).
    """
    runs: list[Run] = []
    contour, open_run = None, False
    cuts = set(breaks)
    for index, (move, seg) in enumerate(program.segments()):
        if isinstance(move, Rapid):
            open_run = False
            continue
        if not open_run or (move.contour and move.contour != contour) or index in cuts:
            runs.append(Run(index, move.contour, []))
            open_run = True
        contour = move.contour
        runs[-1].segments.append(seg)
    return runs


def cut_runs(program: Program) -> list[list[Segment]]:
    """The segments of each run of :func:`runs_of`."""
    return [run.segments for run in runs_of(program)]


def numbered(runs: Sequence[Run]) -> list[int]:
    """Indices of the runs that carry an order number: the first run of each contour.

    The depth passes, tab crossings and pocket levels of a contour are one number;
    moves of no contour (a re-read program without comments) number each run.
    """
    seen: set[int] = set()
    out = []
    for i, run in enumerate(runs):
        if run.contour and run.contour in seen:
            continue
        seen.add(run.contour)
        out.append(i)
    return out


def sections_of(program: Program) -> tuple[Section, ...]:
    """The program cut at its tool changes: one section per tool (none without changes)."""
    changes = [(i, c) for i, c in program.commands if isinstance(c, ToolChange)]
    if not changes:
        return ()
    ends = [i for i, _ in changes[1:]] + [len(program.moves)]
    sections = [
        (" ".join(f"T{c.tool} {c.description}".split()), i, end)
        for (i, c), end in zip(changes, ends, strict=True)
    ]
    if changes[0][0] > 0:
        sections.insert(0, ("before the first tool change", 0, changes[0][0]))
    return tuple(s for s in sections if s[2] > s[1])


def section_colour(number: int) -> str:
    """The colour of section ``number`` (0-based), repeating after :data:`SECTION_COLOURS`."""
    return SECTION_COLOURS[number % len(SECTION_COLOURS)]


def program_layers(
    program: Program,
    u: float,
    *,
    edge_radius_mm: float = 0.0,
    sections: Sequence[Section] = (),
    pixel_mm: float | None = None,
    frame: BBox | None = None,
    clear: Sequence[BBox] = (),
) -> list[Layer]:
    """Tool width, rapids, cuts, starts, order and tool changes of ``program``.

    Every contour gets a start marker and its number up to :data:`MAX_LABELS`
    contours; past that only those whose number is kept do (every k-th,
    :func:`kept_indices`), so a job of thousands of contours is not buried under
    its markers. Empty layers are left out.

    Args:
        program: the moves, mm.
        u: the picture's size unit, mm (1/100 of the view).
        edge_radius_mm: tool radius of an offset cut; > 0 draws the swept tool.
        sections: parts of the program cut in their own colour (a job's operations);
            empty: every cut in :data:`CUT_COLOUR`.
        pixel_mm: the picture's pixel, mm; a program of more than
            :data:`~camtool.preview.thin.DETAIL_MOVES` moves is then drawn at that
            resolution (:mod:`camtool.preview.thin`: tool width, rapids, cuts and tabs as
            :class:`~camtool.preview.scene.Segments`). ``None``: always move by move.
        frame: the main panel's frame, mm: order numbers are kept inside it, clear of
            each other, of the tool numbers and of the work zero's label
            (:func:`order_labels`). ``None``: not bounded.
        clear: boxes (mm) the order numbers keep clear of too: the worst point's ring and
            its label, which say more.
    """
    if pixel_mm is not None and len(program.moves) > DETAIL_MOVES:
        return _dense_layers(program, u, pixel_mm, edge_radius_mm, sections, frame, clear)
    all_runs = runs_of(program, [first for _, first, _ in sections])
    runs = [run.segments for run in all_runs]
    first = numbered(all_runs)
    shown = [first[i] for i in kept_indices(len(first))]
    rapids = tuple((seg,) for move, seg in program.segments() if isinstance(move, Rapid))
    layers = [
        Layer("tool-width", tool_width(runs, edge_radius_mm, u)),
        Layer(
            "rapids",
            (Path(rapids, Style(RAPID_COLOUR, 0.25 * u, dash=(1.2 * u, 0.9 * u))),)
            if rapids
            else (),
        ),
        Layer("cuts", _cut_paths(all_runs, sections, u)),
        Layer("tabs", tab_shapes(tab_segments(program), u)),
        Layer("starts", tuple(s for i in shown for s in _start_marker(runs[i], u))),
        Layer("order", order_labels(program, runs, first, shown, u, frame, clear)),
        Layer("tool-changes", change_marks(program, u)),
    ]
    return [layer for layer in layers if layer.shapes]


def order_labels(
    program: Program,
    runs: list[list[Segment]],
    first: list[int],
    shown: list[int],
    u: float,
    frame: BBox | None,
    clear: Sequence[BBox] = (),
) -> tuple[Text, ...]:
    """The order numbers of the ``shown`` runs (:func:`~camtool.preview.scene.place_labels`).

    Inside ``frame`` (when given) and clear of each other, of the tool numbers
    (:func:`change_marks`), of the work zero's label (:func:`zero_label`) and of the
    boxes of ``clear`` (mm).
    """
    taken = [*clear, *(text_box(t) for t in change_marks(program, u) if isinstance(t, Text))]
    if frame is not None and (zero := zero_label(frame, u)) is not None:
        taken.append(text_box(zero))
    numbers = [_number(first.index(i) + 1, runs[i], u) for i in shown]
    return tuple(place_labels(numbers, taken=taken, inside=frame))


def _cut_paths(runs: list[Run], sections: Sequence[Section], u: float) -> tuple[Path, ...]:
    """The cuts, one path per section in its colour (one blue path without sections)."""
    if not sections:
        chains = tuple(tuple(r.segments) for r in runs)
        return (Path(chains, Style(CUT_COLOUR, 0.35 * u)),) if chains else ()
    paths = []
    for number, (_, start, end) in enumerate(sections):
        chains = tuple(tuple(r.segments) for r in runs if start <= r.first < end)
        if chains:
            paths.append(Path(chains, Style(section_colour(number), 0.35 * u)))
    return tuple(paths)


def change_marks(program: Program, u: float) -> tuple[Rect | Text, ...]:
    """A black square and ``T2`` where each tool change happens (none at the start)."""
    where = {}
    moves = program.moves
    for index, command in program.commands:
        if isinstance(command, ToolChange) and 0 < index <= len(moves):
            end = moves[index - 1]
            where[(end.x, end.y)] = f"T{command.tool}"
    shapes: list[Rect | Text] = []
    size = 1.4 * u
    for (x, y), label in where.items():
        shapes.append(Rect((x - size, y - size, x + size, y + size), Style(CHANGE_COLOUR, 0.4 * u)))
        shapes.append(Text((x + 2.2 * u, y + 1.6 * u), label, 3.0 * u, CHANGE_COLOUR, bold=True))
    return tuple(shapes)


def tab_segments(program: Program) -> list[Segment]:
    """The XY cutting moves that cross a holding tab, mm.

    A tab is crossed as :mod:`camtool.toolpath.passes` writes one: a straight rise
    (Z alone) from the pass depth onto the tab top, moves across it at that constant
    ``z``, then a straight descent (Z alone) below it again, within a run of cutting
    moves (between two rapids). A first, shallower pass of a multi-pass run is no tab
    (nothing rose onto it), nor is a stretch at a constant height between moves that
    change X or Y with Z (a V-carve's or a 3D finish's, as other CAM programs write them).
    Programs without Z have none.
    """
    out: list[Segment] = []
    run: list[tuple[Segment, float, float]] = []  # one run at a time: memory of a run
    z_here: float | None = None
    for move, seg in program.segments():
        z0 = z_here
        z_here = move.z if move.z is not None else z_here
        if isinstance(move, Rapid):
            out.extend(_tabs_of(run))
            run = []
            continue
        if z0 is None or z_here is None:
            continue
        run.append((seg, z0, z_here))
    out.extend(_tabs_of(run))
    return out


def _tabs_of(run: list[tuple[Segment, float, float]]) -> list[Segment]:
    """The tab crossings of one run of ``(segment, z before, z after)`` (:func:`tab_segments`).

    Each stretch of XY moves at one height is a tab when a rise of Z alone ends where
    it begins and a descent of Z alone starts where it ends; linear in the run.
    """
    out: list[Segment] = []
    i = 0
    while i < len(run):
        seg, z0, z1 = run[i]
        if not (_plunge(seg) and z1 > z0 + Z_EPS):
            i += 1
            continue
        j = i + 1  # the stretch across the tab: XY moves at z1
        while j < len(run) and abs(run[j][2] - z1) <= Z_EPS and abs(run[j][1] - z1) <= Z_EPS:
            j += 1
        across = [s for s, _, _ in run[i + 1 : j] if not _plunge(s)]
        if across and j < len(run) and _plunge(run[j][0]) and run[j][2] < z1 - Z_EPS:
            out.extend(across)
        i = j
    return out


def _plunge(seg: Segment) -> bool:
    """A move of Z alone (no XY travel)."""
    return seg.start == seg.end and not isinstance(seg, Arc)


def tab_shapes(segments: list[Segment], u: float) -> tuple[Path, ...]:
    """The tab crossings as thick green strokes over the cuts."""
    if not segments:
        return ()
    return (Path(tuple((s,) for s in segments), Style(TAB_COLOUR, 1.0 * u)),)


def zero_layer(view: BBox, u: float) -> Layer:
    """A cross on the work zero (0, 0) when it is in ``view``, labelled ``0, 0``."""
    if not (view[0] <= 0.0 <= view[2] and view[1] <= 0.0 <= view[3]):
        return Layer("zero", ())
    a = 2.5 * u
    cross = Path(
        ((Line((-a, 0.0), (a, 0.0)),), (Line((0.0, -a), (0.0, a)),)),
        Style(ZERO_COLOUR, 0.3 * u),
    )
    label = zero_label(view, u)
    return Layer("zero", (cross, label) if label is not None else (cross,))


def zero_label(view: BBox, u: float) -> Text | None:
    """The ``0, 0`` label of the work zero's cross, inside ``view``; None when 0, 0 is not."""
    if not (view[0] <= 0.0 <= view[2] and view[1] <= 0.0 <= view[3]):
        return None
    label = Text((0.6 * u, -2.6 * u), "0, 0", 2.2 * u, ZERO_COLOUR, halo=True)
    return moved_inside(label, view) or label


def drawing_layer(drawing: Drawing, u: float) -> Layer:
    """The drawing's contours as thin grey strokes."""
    chains = tuple(c.segments for c in drawing.contours)
    return Layer("drawing", (Path(chains, Style(DRAWING_COLOUR, 0.25 * u)),))


def work_area_layer(area: BBox, u: float) -> Layer:
    """The machine's work area as a dashed grey frame."""
    return Layer("work-area", (Rect(area, Style(AREA_COLOUR, 0.25 * u, dash=(1.5 * u, u))),))


def tool_width(runs: list[list[Segment]], radius: float, u: float) -> tuple[Polylines, ...]:
    """The area the tool sweeps along the cuts (shapely buffer by ``radius``), translucent.

    Returns no shape when ``radius`` <= 0 or nothing is cut. Rings are
    oriented (outer counter-clockwise, holes clockwise), so any fill rule works.
    """
    if radius <= 0 or not runs:
        return ()
    import shapely
    from shapely.geometry import LineString, Polygon
    from shapely.geometry import Point as ShapelyPoint
    from shapely.geometry.polygon import orient

    tolerance = min(radius / 20.0, u / 10.0)
    pieces = []
    for run in runs:
        pts = [run[0].start]
        for seg in run:
            pts.extend(seg.points(tolerance)[1:])
        line = LineString(pts) if len(pts) > 1 else ShapelyPoint(pts[0])
        pieces.append(line.buffer(radius, quad_segs=16))
    area = shapely.unary_union(pieces)
    polygons = [g for g in getattr(area, "geoms", [area]) if isinstance(g, Polygon)]
    rings = []
    for polygon in polygons:
        oriented = orient(polygon, 1.0)
        rings.append(polyline(oriented.exterior.coords))
        rings.extend(polyline(hole.coords) for hole in oriented.interiors)
    style = Style(fill=TOOL_COLOUR, opacity=TOOL_OPACITY)
    return (Polylines(tuple(rings), style, closed=True),)


def _start_marker(run: list[Segment], u: float) -> tuple[Circle, Polylines]:
    """A dot at the run's start and an arrow along its direction of travel."""
    sx, sy = run[0].start
    tx, ty = start_tangent(run)
    a = 3.2 * u
    tip = (sx + tx * a, sy + ty * a)
    base = (sx + tx * a * 0.45, sy + ty * a * 0.45)
    w = 0.55 * u
    left = (base[0] - ty * w, base[1] + tx * w)
    right = (base[0] + ty * w, base[1] - tx * w)
    style = Style(fill=START_COLOUR)
    return (
        Circle((sx, sy), 0.8 * u, style),
        Polylines((polyline([(sx, sy), left, tip, right]),), style, closed=True),
    )


def _number(number: int, run: list[Segment], u: float) -> Text:
    """The run's number beside its start, on the left of the direction of travel."""
    sx, sy = run[0].start
    tx, ty = start_tangent(run)
    # left normal (-ty, tx), a little behind the start; baseline lowered by a third of the size
    size = 3.0 * u
    x = sx - ty * 2.6 * u - tx * 1.2 * u
    y = sy + tx * 2.6 * u - ty * 1.2 * u - size / 3.0
    return Text((x, y), str(number), size, START_COLOUR, anchor="middle", bold=True)


def start_tangent(run: list[Segment]) -> Point:
    """Unit direction of travel at the start of the first segment of ``run`` that has one."""
    for seg in run:
        if isinstance(seg, Arc):
            rx, ry = seg.start[0] - seg.centre[0], seg.start[1] - seg.centre[1]
            tx, ty = (ry, -rx) if seg.clockwise else (-ry, rx)
        else:
            tx, ty = seg.end[0] - seg.start[0], seg.end[1] - seg.start[1]
        length = math.hypot(tx, ty)
        if length > 0:
            return tx / length, ty / length
    return 1.0, 0.0


def _dense_layers(
    program: Program,
    u: float,
    pixel_mm: float,
    edge_radius_mm: float,
    sections: Sequence[Section],
    frame: BBox | None,
    clear: Sequence[BBox],
) -> list[Layer]:
    """:func:`program_layers` of a big program, drawn at the picture's resolution.

    One pass over the moves, keeping points in :class:`~camtool.preview.thin.Strokes`
    and of each run only its first moves (for its start marker): the memory is the
    points', not an object per move. Tool width, rapids, cuts and tabs are
    :class:`~camtool.preview.scene.Segments` thinned to cells of
    :data:`~camtool.preview.thin.CELL_PX` pixel; starts and order numbers as
    :func:`program_layers` draws them.
    """
    from bisect import bisect_right

    cell = CELL_PX * pixel_mm
    firsts = [first for _, first, _ in sections]
    cuts = [Strokes(cell) for _ in range(max(len(sections), 1))]
    rapids = Strokes(cell)
    runs: list[Run] = []
    contour, open_run = None, False
    for index, (move, seg) in enumerate(program.segments()):
        if isinstance(move, Rapid):
            open_run = False
            rapids.start(seg.start)
            rapids.extend([seg.end])
            continue
        if not open_run or (move.contour and move.contour != contour) or index in firsts:
            runs.append(Run(index, move.contour, []))
            cuts[max(bisect_right(firsts, index) - 1, 0)].start(seg.start)
            open_run = True
        contour = move.contour
        if len(runs[-1].segments) < 4:  # enough for its start tangent
            runs[-1].segments.append(seg)
        cuts[max(bisect_right(firsts, index) - 1, 0)].extend(seg.points(cell)[1:])
    first = numbered(runs)
    shown = [first[i] for i in kept_indices(len(first))]
    segments = [run.segments for run in runs]
    colours = [section_colour(k) for k in range(len(sections))] or [CUT_COLOUR]
    cut_strokes = [(c.thinned(), colour) for c, colour in zip(cuts, colours, strict=True)]
    tabs = Strokes(cell)
    for seg in tab_segments(program):
        tabs.start(seg.start)
        tabs.extend(seg.points(cell)[1:])
    width: tuple[Segments, ...] = ()
    if edge_radius_mm > 0:  # the swept band: the cuts stroked as wide as the tool
        band = Style(TOOL_COLOUR, 2.0 * edge_radius_mm, opacity=TOOL_OPACITY)
        width = tuple(Segments(xy, band) for xy, _ in cut_strokes if len(xy))
    rapid_style = Style(RAPID_COLOUR, 0.25 * u, dash=(1.2 * u, 0.9 * u))
    layers = [
        Layer("tool-width", width),
        Layer("rapids", (Segments(rapids.thinned(), rapid_style),) if rapids else ()),
        Layer(
            "cuts",
            tuple(Segments(xy, Style(c, 0.35 * u)) for xy, c in cut_strokes if len(xy)),
        ),
        Layer("tabs", (Segments(tabs.thinned(), Style(TAB_COLOUR, 1.0 * u)),) if tabs else ()),
        Layer("starts", tuple(s for i in shown for s in _start_marker(segments[i], u))),
        Layer("order", order_labels(program, segments, first, shown, u, frame, clear)),
        Layer("tool-changes", change_marks(program, u)),
    ]
    return [layer for layer in layers if layer.shapes]
