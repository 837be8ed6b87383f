"""Tool compensation: closed contours offset to the tool's side, oriented for climb or conventional.

Design notes: docs/internals.md, ``camtool/toolpath/compensate.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from camtool.geometry.area import enclosed, inscribed_width
from camtool.model.errors import ToolpathError
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Arc, Contour, Line, Point, Segment
from camtool.toolpath.cuts import Cut, Finding, Stage, open_left_out, self_crossing, where
from camtool.toolpath.offset import (
    Answer,
    OffsetResult,
    offset_all,
    offset_checked,
    quad_segs,
    start_ahead,
    stop_ahead,
)
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting

__all__ = ["compensate", "makes_offsets", "offsets_ahead", "tight_corners", "tool_inside"]

CORNER_TURN_DEG = 1.0
"""A joint turning more than this toward the tool is a corner the tool cannot follow."""


@dataclass(frozen=True)
class _Side:
    """Where the tool runs relative to one closed contour."""

    inside: bool  # the tool runs inside the contour's enclosed area
    climb: bool


def tool_inside(depth: int, offset: str) -> bool:
    """True when the tool runs inside a closed contour at nesting ``depth``.

    Outer boundaries (even depth) have material inside, holes (odd depth) outside;
    ``outside`` (and ``on`` with a direction) puts the tool on the side without
    material, ``inside`` on the side with it.
    """
    hole = depth % 2 == 1
    return hole != (offset == "inside")


def compensate(
    contours: Sequence[Contour],
    nest: Nesting,
    options: PlanOptions,
    *,
    progress: Progress = no_progress,
) -> Stage:
    """Turn contours into cuts: compensated for the tool (``outside``/``inside``) or on the line.

    Cuts come in contour order; ``group`` is the contour's index. Compensated
    profiles have ``may_reverse=False``, ``may_rotate=True``, ``material_side``
    ``"right"`` for climb (``"left"`` conventional) and ``outside_profile`` for
    outer boundaries cut ``outside``. A contour whose offset splits gives one
    cut per piece. With ``offset="on"`` open contours give ``kind="open"`` cuts on the
    line, in their drawn direction (``may_reverse`` only with ``options.reverse_open``);
    under ``outside``/``inside`` they have no side and are not cut
    (:func:`~camtool.toolpath.cuts.open_left_out` says which).

    Args:
        contours: chained, closed-where-possible contours, mm.
        nest: their nesting (:func:`~camtool.toolpath.order.nesting`).
        options: ``offset`` (on/outside/inside), ``radius``, ``direction``,
            ``tolerance``.
        progress: told the ``offsetting`` stage (``done`` of ``total`` closed contours)
            as OpenCASCADE's offsets come in.

    Returns:
        The cuts and the findings (``open-left-out``, ``offset-fallback``,
        ``offset-vanished``, ``tight-corner``, ``gouge``).

    Raises:
        ToolpathError: every closed contour is offset away and nothing is left
            to cut (the message lists them), or every contour is open under
            ``outside``/``inside``; ``offset`` is ``pocket``.
    """
    if options.offset not in ("on", "outside", "inside"):
        raise ToolpathError(f"--offset {options.offset} is planned by the pocket stage")
    cuts: list[Cut] = []
    findings: list[Finding] = []
    vanished: list[Finding] = []
    jobs = _offset_jobs(contours, nest, options, progress)
    # the areas the checks below and a vanished contour's finding measure, made once
    polys = closed_polygons(contours, options.tolerance / 4) if options.offset != "on" else {}
    for i, contour in enumerate(contours):
        if not contour.closed:
            if options.offset == "on":
                # drawn direction unless --reverse-open: a drawn arc is a G02 or G03 as drawn
                cut = Cut(contour, i, "open", may_reverse=options.reverse_open, may_rotate=False)
                cuts.append(cut)
        elif options.offset == "on":
            cuts.append(_on_line(contour, i, nest, options))
        else:
            made, found = _compensated(contour, i, nest, options, jobs[i], polys[i])
            cuts.extend(made)
            findings.extend(found)
            vanished.extend(f for f in found if f.kind == "offset-vanished")
    if not cuts and vanished:
        raise ToolpathError(_nothing_left(vanished))
    if options.offset != "on":
        if not cuts:
            raise ToolpathError(_all_open(contours, options.offset))
        findings[:0] = open_left_out(contours, f"--offset {options.offset}")
    if options.offset != "on":
        findings.extend(crossings(contours, options.tolerance, polys))
        findings.extend(gouges(contours, nest, cuts, options, polys))
    return Stage(tuple(cuts), tuple(findings))


MAX_IN_ERROR = 3
"""Vanished contours named in the error when all of them vanish; the rest are counted."""


def _nothing_left(vanished: Sequence[Finding]) -> str:
    """The error when every closed contour is offset away: the first few, and a count."""
    named = "; ".join(f.message for f in vanished[:MAX_IN_ERROR])
    rest = len(vanished) - MAX_IN_ERROR
    if rest > 0:
        narrowest = min(f.value or 0.0 for f in vanished)
        named += (
            f"; and {rest} more closed contour(s) the tool does not fit in "
            f"({len(vanished)} in all, the narrowest about {narrowest:.3g} mm wide)"
        )
    return "nothing left to cut: " + named


def _on_line(contour: Contour, index: int, nest: Nesting, options: PlanOptions) -> Cut:
    """A closed contour cut on the line: drawn direction, or oriented when asked."""
    if options.direction is None:
        return Cut(contour, index, "profile", may_reverse=True, may_rotate=True)
    side = _Side(tool_inside(nest.depth(index), "on"), options.direction == "climb")
    return Cut(
        _oriented(contour, side),
        index,
        "profile",
        may_reverse=False,
        may_rotate=True,
        material_side="right" if side.climb else "left",
    )


@dataclass(frozen=True)
class _OffsetJob:
    """A closed contour's offset to the tool's side.

    The side, the contour oriented for it, the signed offset (mm) and the offsets' answer
    for it, mostly already checked (an item of :func:`~camtool.toolpath.offset.offset_all`;
    ``None`` for a zero radius: nothing to ask).
    """

    side: _Side
    drawn: Contour
    amount: float
    answer: Answer | None = None


def makes_offsets(options: PlanOptions) -> bool:
    """Whether :func:`compensate` offsets closed contours with ``options`` (OpenCASCADE).

    ``--offset`` other than ``on`` and a tool radius above 0 (:func:`_offset_jobs`).
    """
    return options.offset != "on" and options.radius > 0


@contextmanager
def offsets_ahead(options: PlanOptions) -> Iterator[None]:
    """Within it, the child that will make the offsets loads OpenCASCADE meanwhile.

    For a caller about to read a drawing and plan it with ``options``: when
    :func:`compensate` will offset (``--offset`` other than ``on``, a tool radius above
    0), :func:`camtool.toolpath.offset.start_ahead` starts the offsets' child now, so
    that it loads OpenCASCADE (~0.5 s) on another core while this process reads and
    plans; leaving stops it if no offsets used it. The plan is the same either way.
    """
    if makes_offsets(options):
        start_ahead()
    try:
        yield
    finally:
        stop_ahead()


def _offset_jobs(
    contours: Sequence[Contour], nest: Nesting, options: PlanOptions, progress: Progress
) -> dict[int, _OffsetJob]:
    """The offset of each closed contour to the tool's side, by contour index.

    OpenCASCADE's answers are all made at once by
    :func:`~camtool.toolpath.offset.offset_all` (in workers of a child process that a crash
    of OpenCASCADE cannot take this one down with), and checked there against shapely's
    buffer with the plan's tolerance; a zero radius needs none, and ``--offset on`` no
    job at all. A panel repeats its parts: each shape (:func:`shape_key`) and amount is
    offset once and its checked offset (OpenCASCADE's, or the fallback within the
    tolerance) :func:`moved` onto the copies; where the worker gave no checked offset
    (it died, or the check raised), the copies are offset each.
    """
    if options.offset == "on":
        return {}
    r = options.radius
    jobs: dict[int, _OffsetJob] = {}
    for i, contour in enumerate(contours):
        if contour.closed:
            depth = nest.depth(i)
            side = _Side(tool_inside(depth, options.offset), options.direction != "conventional")
            jobs[i] = _OffsetJob(side, _oriented(contour, side), -r if side.inside else r)
    if r == 0:
        return jobs
    first: dict[Any, int] = {}
    made_as = {
        i: first.setdefault((shape_key(job.drawn), job.amount), i) for i, job in jobs.items()
    }
    answers = _offsets(jobs, sorted(set(made_as.values())), options, progress)
    again = [
        i
        for i, j in made_as.items()
        if i not in answers and not isinstance(answers[j], OffsetResult)
    ]
    answers.update(_offsets(jobs, again, options, progress))
    for i, j in made_as.items():
        made = answers[j]
        if i not in answers and isinstance(made, OffsetResult):
            answers[i] = moved(made, jobs[j].drawn, jobs[i].drawn)
    return {i: dataclasses.replace(job, answer=answers[i]) for i, job in jobs.items()}


def _offsets(
    jobs: dict[int, _OffsetJob], chosen: list[int], options: PlanOptions, progress: Progress
) -> dict[int, Answer]:
    """:func:`~camtool.toolpath.offset.offset_all` of the ``chosen`` jobs, by index."""
    if not chosen:
        return {}
    total = len(chosen)
    progress(Step("offsetting", 0, total))
    made = offset_all(
        [(jobs[i].drawn, jobs[i].amount) for i in chosen],
        tolerance=options.tolerance,
        done=lambda n: progress(Step("offsetting", n, total)),
    )
    return dict(zip(chosen, made, strict=True))


SHAPE_DIGITS = 9
"""Decimals (mm) of a contour's points relative to its start that make its shape
(:func:`shape_key`): the copies of one part in a panel are one shape, offset once."""


def shape_key(contour: Contour) -> tuple[Any, ...]:
    """The contour's segments relative to its start, rounded to :data:`SHAPE_DIGITS`.

    Two contours of one key are translates of each other within ~1e-9 mm, far inside the
    plan's tolerance (micrometres): the checked offset of one, :func:`moved` onto the
    other, is the other's offset within that tolerance and those nanometres.
    """
    x0, y0 = contour.start

    def rel(p: Point) -> tuple[float, float]:
        return (round(p[0] - x0, SHAPE_DIGITS), round(p[1] - y0, SHAPE_DIGITS))

    return tuple(
        (rel(s.end), rel(s.centre), s.clockwise) if isinstance(s, Arc) else (rel(s.end),)
        for s in contour.segments
    )


def moved(answer: OffsetResult, made: Contour, copy: Contour) -> OffsetResult:
    """The offset ``answer`` of contour ``made`` translated onto ``copy`` of the same shape.

    The pieces move by the difference of the two contours' starts and take ``copy``'s
    layer, source, colour and linetype.
    """
    dx, dy = copy.start[0] - made.start[0], copy.start[1] - made.start[1]
    pieces = tuple(
        dataclasses.replace(
            p.transformed(1.0, dx, dy),
            layer=copy.layer,
            source=copy.source,
            colour=copy.colour,
            linetype=copy.linetype,
        )
        for p in answer.pieces
    )
    return OffsetResult(pieces, answer.fallback)


def _compensated(
    contour: Contour, index: int, nest: Nesting, options: PlanOptions, job: _OffsetJob, area: Any
) -> tuple[list[Cut], list[Finding]]:
    """The cuts of one closed contour offset to the tool's side (``job``), and what was found.

    ``area``: what the contour encloses (:func:`closed_polygons` at a quarter of the
    tolerance).
    """
    depth = nest.depth(index)
    side, drawn = job.side, job.drawn
    r = options.radius
    if isinstance(job.answer, OffsetResult):  # checked by the offsets' worker
        result = job.answer
    else:  # OpenCASCADE's own answer (its worker died, or the check raised there)
        result = offset_checked(drawn, job.amount, options.tolerance, occt=job.answer)
    findings: list[Finding] = []
    if not result.pieces:
        return [], [_vanished(contour, options, area)]
    if result.fallback is not None:
        findings.append(_fallback(contour, result.fallback, options.tolerance))
        # shapely's buffer keeps no loop
        where_cut = "inside" if side.inside else "outside"  # as the tool runs (a hole: inside)
        crossing = self_crossing(contour, options.tolerance, f"{where_cut} offset")
        if crossing is not None:
            findings.append(crossing)
    corners = tight_corners(drawn, side.inside, r, options.tolerance)
    if corners:
        findings.append(_tight(contour, corners, r))
    outside_profile = depth % 2 == 0 and options.offset == "outside"
    # an outward offset is one loop around the part and, where the tool cannot fill a bay
    # of the outline, loops inside it (the offset region's holes): only the loop around
    # frees the part, so only it gets the tabs and leads of an outside profile
    pieces = result.pieces
    around = max(range(len(pieces)), key=lambda i: abs(pieces[i].signed_area()))
    cuts = [
        Cut(
            piece,
            index,
            "profile",
            may_reverse=False,
            may_rotate=True,
            outside_profile=outside_profile and i == around,
            material_side="right" if side.climb else "left",
        )
        for i, piece in enumerate(pieces)
    ]
    return cuts, findings


def _oriented(contour: Contour, side: _Side) -> Contour:
    """The contour traversed so the tool is on the left (climb) or right (conventional).

    Climb keeps the material on the right, so the tool is on the left: a tool
    inside the contour means counter-clockwise travel.
    """
    want_ccw = side.inside == side.climb
    return contour if (contour.signed_area() > 0) == want_ccw else contour.reversed()


def tight_corners(contour: Contour, inside: bool, radius: float, tolerance: float) -> list[Point]:
    """Corners of a closed contour that a tool of ``radius`` on one side cannot follow.

    A joint is tight when the contour turns toward the tool by more than
    :data:`CORNER_TURN_DEG` (concave as seen from the tool: the corners of a
    rectangular hole with the tool inside it, the inner corner of an L cut
    outside); an arc is tight when it curves toward the tool with a radius
    below ``radius − tolerance``. The tool leaves a fillet of ``radius`` there.

    Args:
        contour: a closed contour as drawn, mm (either orientation).
        inside: the tool runs inside the enclosed area.
        radius: tool radius, mm.
        tolerance: radius slack, mm.

    Returns:
        The corner points (arc midpoints for tight arcs), mm, in contour order.
    """
    ccw = contour.signed_area() > 0
    tool_left = ccw == inside
    segs = contour.segments
    out: list[Point] = []
    for k, seg in enumerate(segs):
        prev = segs[k - 1]
        turn = _turn(_tangent(prev, at_end=True), _tangent(seg, at_end=False))
        if abs(turn) > math.radians(CORNER_TURN_DEG) and (turn > 0) == tool_left:
            out.append(seg.start)
        if (
            isinstance(seg, Arc)
            and seg.radius < radius - tolerance
            and (not seg.clockwise) == tool_left
        ):
            out.append(seg.point_at(0.5))
    return out


def _tangent(seg: Segment, *, at_end: bool) -> Point:
    """Unit direction of travel at the start or end of a segment."""
    if isinstance(seg, Line):
        dx, dy = seg.end[0] - seg.start[0], seg.end[1] - seg.start[1]
    else:
        p = seg.end if at_end else seg.start
        rx, ry = p[0] - seg.centre[0], p[1] - seg.centre[1]
        dx, dy = (ry, -rx) if seg.clockwise else (-ry, rx)
    n = math.hypot(dx, dy) or 1.0
    return (dx / n, dy / n)


def _turn(a: Point, b: Point) -> float:
    """Signed turn from direction ``a`` to ``b``, radians, > 0 to the left."""
    return math.atan2(a[0] * b[1] - a[1] * b[0], a[0] * b[0] + a[1] * b[1])


def _vanished(contour: Contour, options: PlanOptions, poly: Any) -> Finding:
    """An ``offset-vanished`` finding: where the contour is and how wide it is.

    ``poly``: the area the contour encloses (:func:`closed_polygons` at a quarter of the
    tolerance).
    """
    tol = options.tolerance / 4
    if poly.is_empty:  # no area (a closed contour that folds back on itself): no width
        (x, y), width = contour.start, 0.0
    else:
        centre = poly.centroid
        width = inscribed_width(poly, tol)
        x, y = float(centre.x), float(centre.y)
    d = options.tool_diameter
    return Finding(
        "offset-vanished",
        f"{where(contour)}: the region around ({x:.4f}, {y:.4f}) mm is about {width:.3g} mm "
        f"wide, narrower than the {d:g} mm tool: nothing can be cut there; use a smaller tool",
        (x, y),
        float(width),
    )


def _fallback(contour: Contour, reason: str, tolerance: float) -> Finding:
    return Finding(
        "offset-fallback",
        f"{where(contour)}: OpenCASCADE could not offset it ({reason}); used shapely's buffer "
        f"fitted with arcs within {tolerance:g} mm",
        contour.start,
    )


def _tight(contour: Contour, corners: list[Point], radius: float) -> Finding:
    x, y = corners[0]
    n = len(corners)
    return Finding(
        "tight-corner",
        f"{where(contour)}: {n} inside corner{'s' if n > 1 else ''} tighter than the "
        f"{radius:g} mm tool radius (first at ({x:.4f}, {y:.4f}) mm); the part keeps a "
        f"{radius:g} mm radius there",
        (x, y),
        float(n),
    )


def closed_polygons(contours: Sequence[Contour], tolerance: float) -> dict[int, Any]:
    """The area each closed contour encloses (:func:`~camtool.geometry.area.enclosed`), by index.

    ``tolerance``: chord tolerance of the polygons, mm (> 0).
    """
    return {i: enclosed(c.points(tolerance)) for i, c in enumerate(contours) if c.closed}


def material(
    contours: Sequence[Contour],
    nest: Nesting,
    offset: str,
    tolerance: float,
    polys: dict[int, Any] | None = None,
) -> list[Any]:
    """The material that must stay, as shapely polygons (mm), one per region.

    For ``outside``: each outer boundary (even depth) minus the holes directly
    inside it. For ``inside``: each hole minus the islands directly inside it,
    and the area around the outermost contours (a box 10 mm larger).

    Args:
        contours: contours, mm; open ones are ignored.
        nest: their nesting.
        offset: ``outside`` or ``inside``.
        tolerance: chord tolerance of the polygons, mm.
        polys: :func:`closed_polygons` of ``contours`` at ``tolerance``, when already made.
    """
    from shapely import box, union_all

    closed = [i for i, c in enumerate(contours) if c.closed]
    polys = closed_polygons(contours, tolerance) if polys is None else polys
    keep = 0 if offset == "outside" else 1
    regions = []
    for i in closed:
        if nest.depth(i) % 2 != keep:
            continue
        kids = [j for j in closed if i in nest.parents[j] and nest.depth(j) == nest.depth(i) + 1]
        regions.append(polys[i].difference(union_all([polys[j] for j in kids])))
    if offset == "inside" and closed:
        top = union_all([polys[i] for i in closed if nest.depth(i) == 0])
        x0, y0, x1, y1 = top.bounds
        regions.append(box(x0 - 10, y0 - 10, x1 + 10, y1 + 10).difference(top))
    return [r for r in regions if not r.is_empty]


MAX_CROSSINGS = 100
"""Most pairs of crossing contours :func:`crossings` reports (the warnings list fewer)."""


def crossings(
    contours: Sequence[Contour], tolerance: float, polys: dict[int, Any] | None = None
) -> list[Finding]:
    """``crossing`` findings: two closed contours whose insides overlap, neither inside the other.

    Such a pair has no outside or inside: each is offset on its own, and the tool cuts
    through the other (a tab marker drawn across a part's outline, two parts drawn over
    each other). Contours that only touch, or share an edge, are not reported; an overlap
    counts when it, and what each has outside the other, are wider than the tolerance
    (twice the area over the perimeter).

    Args:
        contours: the plan's contours, mm; open ones are ignored.
        tolerance: mm (> 0); the polygons' chords are within a quarter of it.
        polys: :func:`closed_polygons` of ``contours`` at a quarter of ``tolerance``, when
            already made.

    Returns:
        At most :data:`MAX_CROSSINGS` findings, ``at`` a point of the overlap, ``value`` its
        area in mm².
    """
    from shapely import STRtree, difference, intersection

    closed = [i for i, c in enumerate(contours) if c.closed]
    if len(closed) < 2:
        return []
    made = closed_polygons(contours, tolerance / 4) if polys is None else polys
    areas = [made[i] for i in closed]
    pairs = STRtree(areas).query(areas, predicate="overlaps")
    out: list[Finding] = []
    for a, b in zip(*pairs.tolist(), strict=True):
        if a >= b:
            continue
        shared = intersection(areas[a], areas[b])
        parts = (shared, difference(areas[a], areas[b]), difference(areas[b], areas[a]))
        if not all(2.0 * g.area > tolerance * g.length for g in parts):
            continue  # a sliver of chords: touching, or one inside the other
        p = shared.representative_point()
        first, second = contours[closed[a]], contours[closed[b]]
        out.append(
            Finding(
                "crossing",
                f"{where(first)} and {where(second)} cross each other around "
                f"({p.x:.4f}, {p.y:.4f}) mm: neither is inside the other, so each is offset "
                "on its own and the tool cuts through the other; fix the drawing, or cut "
                "them in separate operations (docs/jobs.md)",
                (float(p.x), float(p.y)),
                float(shared.area),
            )
        )
        if len(out) >= MAX_CROSSINGS:
            break
    return out


GEOS_PART = 32
"""Cuts or pairs :func:`gouges` gives a thread at a time (a few ms of GEOS work)."""
GOUGE_BATCH = 128
"""Cuts whose sweeps and overlaps :func:`gouges` holds at once: an outside cut's sweep
overlaps its own part by a sliver all along, so each overlap is as long as the cut."""


def gouges(
    contours: Sequence[Contour],
    nest: Nesting,
    cuts: Sequence[Cut],
    options: PlanOptions,
    polys: dict[int, Any] | None = None,
) -> list[Finding]:
    """``gouge`` findings where a compensated cut's swept area overlaps the material.

    Args:
        contours: the contours the cuts come from (``cut.group`` indexes them), mm.
        nest: their nesting.
        cuts: the cuts; only closed profiles are checked (open contours are cut
            on the line on purpose).
        options: ``offset`` (outside/inside), ``radius``, ``tolerance``.
        polys: :func:`closed_polygons` of ``contours`` at a quarter of the tolerance, when
            already made.

    Returns:
        One finding per overlapping region and cut: ``at`` its centroid, ``value``
        its area in mm².
    """
    from shapely import STRtree

    tol = options.tolerance / 4
    regions = material(contours, nest, options.offset, tol, polys)
    if not regions or options.radius <= 0:
        return []
    profiles = [cut for cut in cuts if cut.kind == "profile"]
    held = np.empty(len(regions), dtype=object)
    held[:] = regions
    tree = STRtree(regions)
    out: list[Finding] = []
    for lo in range(0, len(profiles), GOUGE_BATCH):  # the sweeps and overlaps of a batch held
        out += _batch_gouges(contours, profiles[lo : lo + GOUGE_BATCH], tree, held, options)
    return out


def _batch_gouges(
    contours: Sequence[Contour], batch: Sequence[Cut], tree: Any, held: Any, options: PlanOptions
) -> list[Finding]:
    """:func:`gouges` of the profile cuts ``batch`` against the material ``held`` (``tree``)."""
    from shapely import buffer, intersection, linestrings

    from camtool.accel.pool import parts_threaded

    tol = options.tolerance / 4
    segs = quad_segs(options.radius, tol)
    paths = np.empty(len(batch), dtype=object)
    paths[:] = [linestrings(cut.path.points(tol)) for cut in batch]
    swept = parts_threaded(
        lambda part: buffer(paths[part], options.radius, quad_segs=segs), len(paths), GEOS_PART
    )
    # each cut's regions in the order the tree gives them for that cut alone
    cut_of, region_of = tree.query(swept, predicate="intersects")
    overlaps = parts_threaded(
        lambda part: intersection(swept[cut_of[part]], held[region_of[part]]),
        len(cut_of),
        GEOS_PART,
    )
    out: list[Finding] = []
    for k, overlap in zip(cut_of.tolist(), overlaps, strict=True):
        for part in getattr(overlap, "geoms", [overlap]):
            if part.geom_type == "Polygon" and 2.0 * part.area > options.tolerance * part.length:
                out.append(_finding(contours[batch[k].group], part, options))
    return out


def _finding(contour: Contour, part: Any, options: PlanOptions) -> Finding:
    c = part.centroid
    x, y, area = float(c.x), float(c.y), float(part.area)
    return Finding(
        "gouge",
        f"{where(contour)}: the {options.tool_diameter:g} mm tool cuts into the part around "
        f"({x:.4f}, {y:.4f}) mm ({area:.3g} mm²): neighbouring contours are closer than the "
        "tool; use a smaller tool or move them apart",
        (x, y),
        area,
    )


def _all_open(contours: Sequence[Contour], side: str) -> str:
    """Why nothing is cut when every contour is open under ``--offset side``."""
    layers = sorted({c.layer for c in contours}, key=str.casefold)
    named = ", ".join(repr(name) for name in layers[:MAX_IN_ERROR])
    if len(layers) > MAX_IN_ERROR:
        named += f" and {len(layers) - MAX_IN_ERROR} more"
    on = f"layer {named}" if len(layers) == 1 else f"layers {named}"
    count = "the 1 contour is" if len(contours) == 1 else f"all {len(contours)} contours are"
    them, their = ("it", "its") if len(contours) == 1 else ("them", "their")
    return (
        f"nothing to cut: {count} open (on {on}), "
        f"and --offset {side} needs closed contours; cut {them} on {their} lines with --offset on "
        f"(or an engrave operation), or close {them} in the drawing (--close-gap closes small "
        "gaps)"
    )
