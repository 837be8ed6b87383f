"""Plan a drawing into a Program: chain, close, fit, compensate or pocket, order, emit.

Offset modes (the ``--offset`` option):

Design notes: docs/internals.md, ``camtool/toolpath/plan.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from camtool.geometry.arcfit import FitStats, fit_polyline, fit_stats
from camtool.geometry.chain import chain_members, joint_distance
from camtool.model.construction import fit_extent
from camtool.model.errors import InputError
from camtool.model.program import Move, Program, Rapid
from camtool.model.progress import Progress, no_progress
from camtool.model.shapes import BBox, Contour, Drawing, Line, Point, Segment, fit_factor
from camtool.toolpath.chain import as_cut
from camtool.toolpath.copies import drop_copies, drop_near_copies
from camtool.toolpath.cuts import Cut, Finding, Stage, finding_warnings
from camtool.toolpath.gaps import open_gaps
from camtool.toolpath.leads import KeepOff
from camtool.toolpath.options import DEFAULT_CHAIN_TOLERANCE, OFFSET_MODES, PlanOptions
from camtool.toolpath.order import Ordering, nesting, order_cuts
from camtool.toolpath.placement import (
    Placing,
    check_extent,
    larger_than_travel,
    placement_shift,
    shift_moves,
    toolpath_extent,
)
from camtool.toolpath.split import MIN_PIECE

if TYPE_CHECKING:
    from camtool.model.machine import Machine

__all__ = [
    "OFFSET_MODES",
    "Plan",
    "PlanOptions",
    "PlanReport",
    "place",
    "place_program",
    "plan",
    "plan_drawing",
    "plan_unplaced",
]

MIN_FIT_RUN = 6
"""Shortest run of consecutive lines (edges) that arc fitting tries to replace."""


@dataclass(frozen=True)
class PlanReport:
    """What planning did and found (the ``plan`` key of the verify report).

    Attributes:
        contours: contours after chaining and closing.
        cuts: tool paths after compensation or pocketing (before passes).
        findings: everything the user must know, in stage order.
        ordering: the cutting order and its reversal and travel counts.
        fit: what arc fitting of dense polylines saved (``None`` when off).
        work_shift: ``(dx, dy)`` mm that ``--origin``/``--translate`` moved the program
            by. Findings locate features in the drawing's coordinates (after
            ``--scale``/``--fit``), as their messages say; :meth:`placed_findings`
            gives them in the program's work coordinates.
        joint_mm: the distance within which planning joined contour ends, mm
            (:func:`~camtool.geometry.chain.joint_distance` of ``--chain-tolerance``): a
            finding about a contour names every drawing contour of its chain, and the
            verification groups the drawing's contours at the same distance.
    """

    contours: int
    cuts: int
    findings: tuple[Finding, ...]
    ordering: Ordering
    fit: FitStats | None
    work_shift: Point = (0.0, 0.0)
    joint_mm: float = DEFAULT_CHAIN_TOLERANCE

    def placed_findings(self) -> tuple[Finding, ...]:
        """The findings with ``at`` in the program's work coordinates (mm)."""
        dx, dy = self.work_shift
        if dx == 0.0 and dy == 0.0:
            return self.findings
        return tuple(
            f if f.at is None else dataclasses.replace(f, at=(f.at[0] + dx, f.at[1] + dy))
            for f in self.findings
        )

    def notes(self) -> list[str]:
        """The ordering and arc-fit summaries, for stderr (the findings are warnings)."""
        lines = list(self.ordering.summary())
        if self.fit is not None and self.fit.replaced > self.fit.segments:
            lines.append(f"{self.fit.summary()}: {self.fit.saved} fewer moves")
        return lines

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict: counts per finding kind, the findings, order, fit."""
        fit = None
        if self.fit is not None:
            fit = {"replaced": self.fit.replaced, "arcs": self.fit.arcs, "lines": self.fit.lines}
        return {
            "contours": self.contours,
            "cuts": self.cuts,
            "counts": dict(Counter(f.kind for f in self.findings)),
            "findings": [
                {"kind": f.kind, "message": f.message, "at": f.at, "value": f.value}
                for f in self.findings
            ],
            "order": self.ordering.to_json(),
            "arc_fit": fit,
        }


@dataclass(frozen=True)
class Plan:
    """A planned program, its report, and the drawing as placed (mm).

    ``placed`` is the drawing after ``--scale``/``--fit`` and moved with the program
    by ``--origin``/``--translate``: it lies in the program's work coordinates.
    ``left_out`` are the indices in ``placed.contours`` of the contours the plan does not
    cut at all: the pieces of an open chain under ``--offset outside``, ``inside`` or
    ``pocket`` (a centre line, a construction line across the part; each is an
    ``open-left-out`` finding), and of a contour on the path of one an earlier operation
    of a job cuts (``cut_before``, a ``copy`` finding); ``placed.without(left_out)`` is
    what the program cuts.
    ``paths`` are the contours as chained that it plans (each path once, in the drawing's
    coordinates): what a later operation of a job that cuts alike need not cut again.
    """

    program: Program
    report: PlanReport
    placed: Drawing
    left_out: frozenset[int] = frozenset()
    paths: tuple[Contour, ...] = ()


def plan(drawing: Drawing, options: PlanOptions, machine: Machine | None = None) -> Program:
    """Turn a drawing into a program of rapids and cuts (see :func:`plan_drawing`)."""
    return plan_drawing(drawing, options, machine).program


def plan_drawing(
    drawing: Drawing,
    options: PlanOptions,
    machine: Machine | None = None,
    *,
    helix: bool = True,
    progress: Progress = no_progress,
) -> Plan:
    """Turn a drawing into a program and say what planning found.

    Contours are placed (scale/fit), chained and closed within the tolerances,
    dense polylines fitted with arcs, compensated for the tool or pocketed,
    ordered (inside before outside always) and emitted with depth passes, tabs
    and lead-ins; the program is then moved to its work zero (``--origin``, then
    ``--translate``: :func:`place_program`) and checked against the machine's
    travel. The findings also become the program's warnings.

    Args:
        drawing: the imported drawing, mm.
        options: the planning options.
        machine: the target's machine: its backlash weighs ``--order reversals``
            and a machine without Z refuses the depth options.
        helix: the target writes arcs that move Z; ``False`` ramps down arcs as
            chords within the tolerance.
        progress: told the ``offsetting`` stage (``total``: the closed contours offset
            for the tool) as the offsets come in, when there are any.

    Raises:
        UsageError: invalid options, no feed (``options.feed_mm_min`` is ``None``:
            :func:`camtool.jobs.pipeline.plan_options` fills in the target's), or depth
            options for a machine without Z.
        ToolpathError: a stage cannot plan the drawing (names the contour).
        DialectError: the toolpath does not fit the machine (:func:`place_program`).
    """
    unplaced = plan_unplaced(drawing, options, machine, helix=helix, progress=progress)
    program, placed, shift = place_program(unplaced.program, unplaced.placed, options, machine)
    report = dataclasses.replace(unplaced.report, work_shift=shift)
    return Plan(program, report, placed, unplaced.left_out)


def plan_unplaced(
    drawing: Drawing,
    options: PlanOptions,
    machine: Machine | None = None,
    *,
    helix: bool = True,
    progress: Progress = no_progress,
    cut_before: Sequence[tuple[str, Sequence[Contour]]] = (),
) -> Plan:
    """:func:`plan_drawing` without its placement stage: the program in drawing coordinates.

    The drawing is scaled (``--scale``/``--fit``) and planned as :func:`plan_drawing`
    plans it; ``options.placement``, ``translate`` and the travel check are not applied
    (:func:`place_program` does that, once for a whole job of several operations).
    ``cut_before`` are the :attr:`Plan.paths` of a job's earlier operations that cut as
    this one does, each with the operation's name (:func:`~camtool.toolpath.copies.drop_copies`):
    a contour on one of their paths is not cut again, and when every contour is, the
    program has no moves.

    Raises:
        As :func:`plan_drawing`, except the travel check.
    """
    from camtool.toolpath.passes import emit

    _ = options.feed  # no feed (the target's not filled in): refused before any work
    if machine is not None:
        options.check_machine(machine, machine.name)
    placed = place(drawing, options)
    contours, found, left_out, members = chained(placed.contours, options)
    contours, copied, earlier = drop_copies(contours, cut_before=cut_before)
    left_out |= {i for j in earlier for i in members[j]}  # cut by an earlier operation
    paths = tuple(contours)
    gaps = open_gaps(contours, options)
    stats = None
    if options.fit_arcs:
        contours, stats = fit_dense(contours, options.tolerance)
    contours, near, nest = drop_near_copies(contours, nesting(contours))
    findings = [*options.ineffective(), *found, *copied, *near, *gaps]
    stage = _stage(contours, nest, options, progress)
    findings.extend(stage.findings)
    backlash = (0.0, 0.0) if machine is None else _backlash_weights(machine)
    ordering = order_cuts(stage.cuts, nest, options, backlash)
    findings.extend(ordering.findings)
    z_axis = machine is not None and machine.has_z
    keep_off = _keep_off(contours, nest, options)
    on_line = _each_its_contour(stage.cuts, contours)
    moves, emitted = emit(
        ordering.cuts,
        options,
        helix=helix,
        z_axis=z_axis,
        keep_off=keep_off,
        nest=nest if on_line else None,
    )
    findings.extend(emitted)
    if (paths or not earlier) and not any(not isinstance(m, Rapid) for m in moves):
        raise InputError(
            f"{drawing.source or 'the drawing'}: nothing to cut: {len(contours)} contour(s), "
            f"none longer than {MIN_PIECE:g} mm after planning; check the drawing's units "
            "(or --scale it)"
        )
    warnings = tuple(dict.fromkeys((*drawing.warnings, *finding_warnings(findings))))
    program = Program(tuple(moves), options.origin, warnings)
    report = PlanReport(
        len(contours),
        len(stage.cuts),
        tuple(findings),
        ordering,
        stats,
        joint_mm=joint_distance(options.chain_tolerance),
    )
    return Plan(program, report, placed, left_out, paths)


def chained(
    contours: Sequence[Contour], options: PlanOptions
) -> tuple[list[Contour], list[Finding], frozenset[int], list[tuple[int, ...]]]:
    """``contours`` chained and their gaps closed as the planner cuts them.

    Ends within ``options.chain_tolerance`` are joined (:func:`chain_members`), then
    gaps up to ``options.close_gap`` closed (:func:`close_gaps`); a contour that comes
    back on its own path is cut one way (:func:`~camtool.toolpath.copies.one_way`): a
    circle drawn twice as one closed circle, a line drawn twice as one open line on the
    line (``offset`` ``on``; with a side it stays the region of no area it was drawn as).

    Returns:
        The planned contours, mm; the ``closed-gap`` and ``copy`` findings; the indices in
        ``contours`` of those the plan leaves out (:attr:`Plan.left_out`: the pieces
        of a chain still open, unless ``options.offset`` is ``on``); and each planned
        contour's pieces, as indices in ``contours``.
    """
    joint = joint_distance(options.chain_tolerance)
    joined, members = chain_members(contours, joint)
    joined, found = as_cut(joined, options.close_gap, joint, open_too=options.offset == "on")
    left_out = frozenset(
        i
        for contour, pieces in zip(joined, members, strict=True)
        if not contour.closed and options.offset != "on"
        for i in pieces
    )
    return joined, found, left_out, members


def _each_its_contour(cuts: Sequence[Cut], contours: Sequence[Contour]) -> bool:
    """Whether each contour is cut once, on its own path (``--offset on``, no ``--direction``)."""
    return len(cuts) == len(contours) and all(
        cut.group == i and cut.path is contours[i] for i, cut in enumerate(cuts)
    )


def _keep_off(contours: Sequence[Contour], nest: Any, options: PlanOptions) -> KeepOff | None:
    """The material lead arcs keep the tool off, for a profile with ``--lead-in``; else None."""
    if options.lead_in <= 0 or options.offset not in ("outside", "inside"):
        return None
    from camtool.toolpath.compensate import material

    regions = material(contours, nest, options.offset, options.tolerance / 4)
    distance = options.radius - options.tolerance
    return KeepOff(regions, distance, options.tolerance) if regions and distance > 0 else None


def _stage(
    contours: Sequence[Contour], nest: Any, options: PlanOptions, progress: Progress
) -> Stage:
    if not contours:  # each a copy of an earlier operation's (``cut_before``)
        return Stage(())
    if options.offset == "pocket":
        from camtool.toolpath.pocket import pocket

        return pocket(contours, nest, options, progress=progress)
    from camtool.toolpath.compensate import compensate

    return compensate(contours, nest, options, progress=progress)


def _backlash_weights(machine: Machine) -> tuple[float, float]:
    """Per-axis weight of a reversal: the larger of true backlash and compensation, µm."""
    b = machine.backlash
    return (max(b.true_um[0], b.compensation_um[0]), max(b.true_um[1], b.compensation_um[1]))


def place(drawing: Drawing, options: PlanOptions, sized: Drawing | None = None) -> Drawing:
    """The drawing scaled as ``options.scale`` or ``options.fit`` ask (mm).

    ``sized``: what ``--fit`` sizes (the drawing with the marks a job drills; ``None``:
    the drawing), :func:`scaling`.
    """
    k, dx, dy = scaling(sized if sized is not None else drawing, options)
    if (k, dx, dy) == (1.0, 0.0, 0.0):
        return drawing
    return drawing.transformed(k, dx, dy)


def scaling(drawing: Drawing, options: PlanOptions) -> tuple[float, float, float]:
    """``(k, dx, dy)``: :func:`place` maps a drawing point ``p`` to ``k·p + (dx, dy)``, mm.

    ``--scale`` scales about the drawing's origin; ``--fit`` about the lower-left corner
    of what is cut (:func:`~camtool.model.construction.fit_extent`).
    """
    if options.fit is None:
        return (options.scale, 0.0, 0.0)
    if not drawing.contours and not drawing.marks:  # nothing to size: refused as not cut
        return (1.0, 0.0, 0.0)
    x0, y0, _, _ = box = fit_extent(drawing)  # construction (centre lines, a border) aside
    k = fit_factor(box, options.fit)
    if math.isinf(k):
        return (1.0, 0.0, 0.0)
    return (k, x0 * (1 - k), y0 * (1 - k))


def is_end_move(move: Move, options: PlanOptions) -> bool:
    """Whether ``move`` is the ``--end-position`` rapid a plan ends with.

    A rapid of no contour to exactly ``options.end_position`` (in work coordinates: the
    placement leaves it where it was asked, :func:`place_program`).
    """
    end = options.end_position
    return (
        end is not None
        and isinstance(move, Rapid)
        and move.contour == 0
        and (move.x, move.y) == (float(end[0]), float(end[1]))
    )


def place_program(
    program: Program, placed: Drawing, options: PlanOptions, machine: Machine | None = None
) -> tuple[Program, Drawing, Point]:
    """The placement stage: move the program so that its work zero lies where asked.

    ``options.placement`` (``--origin``) then ``options.translate`` (``--translate``)
    shift the program's moves (:func:`~camtool.toolpath.placement.shift_moves`; the
    start position and the ``--end-position`` rapid, given in work coordinates, stay)
    and the placed drawing alike, so that ``verify --against``
    and previews still line up. With a machine, the program is then checked against
    its travel (:func:`~camtool.toolpath.placement.check_travel`); its warnings join
    the program's (the post-processor applies the same rule again as a backstop, but
    cannot know how work zero was chosen, so it only refuses).

    Returns:
        The program and the drawing, both in work coordinates (mm), and the shift
        ``(dx, dy)`` that placed them, mm.

    Raises:
        DialectError: the toolpath is larger than the machine's travel, or outside
            the work area of a machine in machine coordinates; the message names
            options that fix it as written.
    """
    moves = list(program.moves)
    # the end position is given in work coordinates: it stays where it was asked
    end = [moves.pop()] if moves and is_end_move(moves[-1], options) else []
    fields = {f.name: getattr(program, f.name) for f in dataclasses.fields(program)}
    del fields["moves"]
    dx, dy = placement_shift(Program(tuple(moves), **fields), options.placement, options.translate)
    # From here the list holds the moves (a caller that passed its program and kept no
    # reference lets each old move go as its shifted copy replaces it: shift_moves).
    del program
    fields["commands"], fields["lines"] = shift_moves(
        moves, fields["origin"], fields["commands"], fields["lines"], dx, dy
    )
    program = Program((*moves, *end), **fields)
    moves.clear()
    if dx or dy:
        placed = placed.transformed(1.0, dx, dy)
    if machine is not None:
        box = toolpath_extent(program)
        said = check_extent(box, machine, _placing(box, placed, options, machine))
        if said:
            program = dataclasses.replace(program, warnings=(*program.warnings, *said))
    return program, placed, (dx, dy)


def _placing(box: BBox | None, placed: Drawing, options: PlanOptions, machine: Machine) -> Placing:
    """How ``options`` placed a program of toolpath extent ``box``; its margin over the drawing.

    The margin is read only by the ``--fit`` remedy of a toolpath larger than the travel
    (:func:`~camtool.toolpath.placement.too_large`), so it is measured only then (the
    placed drawing's box walks every segment); otherwise it is left at ``(0, 0)``.
    """
    margin = (0.0, 0.0)
    if box is not None and placed.contours and larger_than_travel(box, machine):
        d = placed.bbox()
        margin = ((box[2] - box[0]) - (d[2] - d[0]), (box[3] - box[1]) - (d[3] - d[1]))
    return Placing(options.placement, options.translate, margin)


def fit_dense(contours: Sequence[Contour], tolerance: float) -> tuple[list[Contour], FitStats]:
    """Replace runs of :data:`MIN_FIT_RUN` or more lines by arcs and lines within ``tolerance``.

    A run's end points stay exact (they are corners or meet arcs); corners inside a
    run are kept by :func:`~camtool.geometry.arcfit.fit_polyline`. A run is replaced
    only when the fit has fewer segments.

    Returns:
        The contours (unchanged objects where nothing was saved) and the total
        :class:`FitStats` (``replaced`` counts the lines of the replaced runs).
    """
    total = FitStats(0, 0, 0)
    out: list[Contour] = []
    for contour in contours:
        segs: list[Segment] = []
        run: list[Line] = []
        for seg in (*contour.segments, None):
            if isinstance(seg, Line):
                run.append(seg)
                continue
            if len(run) >= MIN_FIT_RUN:
                total += _fit_run(run, tolerance, segs)
            else:  # too short to fit: most runs are
                segs.extend(run)
            run = []
            if seg is not None:
                segs.append(seg)
        same = len(segs) == len(contour.segments)
        # the same contour otherwise: its layer, source, colour and linetype kept
        out.append(contour if same else dataclasses.replace(contour, segments=tuple(segs)))
    return out, total


def _fit_run(run: list[Line], tolerance: float, out: list[Segment]) -> FitStats:
    """Append ``run``'s fit to ``out`` when it has fewer segments, else ``run``; its stats.

    ``run`` holds :data:`MIN_FIT_RUN` lines or more (:func:`fit_dense` keeps shorter ones).
    """
    points = [run[0].start, *(s.end for s in run)]
    fitted = fit_polyline(points, tolerance)
    if len(fitted) >= len(run):
        out.extend(run)
        return FitStats(0, 0, 0)
    out.extend(fitted)
    return fit_stats(len(run), fitted)
