"""Run a job: every operation planned in turn, joined into one program for one target.

:func:`run_job` is the one path from a drawing to code: ``post``, ``batch`` and the API
(:func:`camtool.jobs.pipeline.post_drawing`, whose options are the one-operation
shorthand :meth:`~camtool.jobs.job.Job.single`) all come through it. In turn, for each
operation of :meth:`~camtool.jobs.job.Job.sequenced`:

Design notes: docs/internals.md, ``camtool/jobs/run.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from camtool.geometry.chain import chain_members, joint_distance
from camtool.jobs.by_hand import ToolProgram, loaded_by_hand, per_tool
from camtool.jobs.drill import drill_moves
from camtool.jobs.heights import check_heights
from camtool.jobs.job import Job, Operation, Tool, check_spindle
from camtool.jobs.job_warnings import holes_cut_outside, overlaps, undrilled, unselected
from camtool.jobs.jobfile import as_keys
from camtool.jobs.selection import (
    Chaining,
    Selected,
    Shape,
    as_chained,
    construction_notes,
    nothing_selected,
    select,
    with_drilled_marks,
)
from camtool.jobs.travel import refuse_too_large, refuse_too_small
from camtool.model.errors import InputError, ToolpathError, UsageError
from camtool.model.program import (
    ArcMove,
    Command,
    Dwell,
    Move,
    Program,
    Rapid,
    Spindle,
    ToolChange,
    spindle_start,
)
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Arc, Contour, Drawing, Point, arc_length, circle_of
from camtool.toolpath.chain import as_cut
from camtool.toolpath.options import PlanOptions

if TYPE_CHECKING:
    from camtool.post.base import PostResult, Target
    from camtool.toolpath.plan import PlanReport


@dataclass(frozen=True)
class PostJob:
    """Everything one ``post`` produced.

    Attributes:
        drawing: what was imported (``None`` when the input was already a program).
        program: the planned, machine-neutral program.
        target: the target it was written for.
        result: the emitted code and its warnings.
        placed: the drawing as placed on the machine (after ``scale``/``fit``),
            in the program's coordinates.
        edge_radius_mm: how far the cut edge lies from the tool path: half the tool
            diameter for ``outside``/``inside``/``pocket``, 0 for paths on the line.
        plan: what planning did and found (``None`` for a re-posted program, and for a
            job of several operations: each has its own, in ``operations``).
        operations: what each operation of the job made, in the order they ran (one for
            ``post``'s options; none for a re-posted program).
        pieces: for a target that cannot change tools (:attr:`PostProcessor.tool_changes
            <camtool.post.base.PostProcessor.tool_changes>` ``"none"``), the job as one
            program per tool, in the order they run; ``result`` is then the first's.
            Empty otherwise: ``result`` is the whole program.
    """

    drawing: Drawing | None
    program: Program
    target: Target
    result: PostResult
    placed: Drawing | None
    edge_radius_mm: float = 0.0
    plan: PlanReport | None = None
    operations: tuple[OperationRun, ...] = ()
    pieces: tuple[ToolProgram, ...] = ()

    @property
    def cut(self) -> Drawing | None:
        """What the job cuts: ``placed`` without the contours its operations' plans left out.

        ``placed`` is the operations' drawings one after the other (:attr:`OperationRun.cut`
        is each one's); ``None`` for a re-posted program.
        """
        if self.placed is None:
            return None
        left_out: set[int] = set()
        first = 0
        for run in self.operations:
            left_out.update(first + i for i in run.left_out)
            first += len(run.placed.contours)
        return self.placed.without(frozenset(left_out))

    @property
    def warnings(self) -> tuple[str, ...]:
        """Warnings of every stage, in pipeline order, without repeats."""
        pieces = [w for p in self.pieces for w in (*p.program.warnings, *p.result.warnings)]
        written = pieces or self.result.warnings
        return tuple(dict.fromkeys((*self.program.warnings, *written)))


@dataclass(frozen=True, kw_only=True)
class OutputOptions:
    """How the planned program is written: the options that are not planning options.

    They apply to a re-posted program too (:func:`post_program`).

    Attributes:
        fmt: the dialect's output format (``None``: its first, see ``camtool targets``).
        spindle_rpm: spindle speed, rev/min; ``None`` takes the target's
            ``spindle_rpm`` for a planned drawing (which may be none), 0 programs no
            spindle; a re-posted program gets spindle commands only when > 0 and it
            has none of its own.
        spindle_dwell_s: wait this long after the spindle starts, s (``--spindle-dwell``).

    Raises:
        UsageError: a speed or wait no machine runs (:func:`~camtool.jobs.job.check_spindle`).
    """

    fmt: str | None = None
    spindle_rpm: float | None = None
    spindle_dwell_s: float = 0.0

    def __post_init__(self) -> None:
        check_spindle(self.spindle_rpm, self.spindle_dwell_s)


def plan_options(target: Target, plan: PlanOptions | None = None) -> PlanOptions:
    """``plan`` for ``target``: its default feed filled in, checked against what it can do.

    Args:
        target: the target the plan is for.
        plan: the planning options (``None``: the defaults); ``feed_mm_min`` ``None``
            takes the target's default feed.

    Raises:
        UsageError: options the target cannot carry out: depth options for a machine
            without Z, lead-in arcs on a target that writes arcs as chords, a ramp on
            a target that moves Z in its own block (the options themselves are
            checked when the :class:`PlanOptions` is made).
    """
    plan = plan if plan is not None else PlanOptions()
    if plan.feed_mm_min is None:
        plan = dataclasses.replace(plan, feed_mm_min=target.default_feed_mm_min)
    plan.check_machine(target.machine, target.name)
    if plan.lead_in > 0 and not target.post.arcs:
        raise UsageError(
            f"--lead-in: {target.name} writes arcs as chords; lead-in arcs are for targets "
            "with arcs (leave --lead-in out)"
        )
    if plan.ramp_deg is not None and not target.post.z_with_xy:
        raise UsageError(
            f"--ramp: {target.name} moves Z in a block of its own, so it cannot descend "
            "along the path; leave --ramp out (the tool plunges straight down)"
        )
    check_heights(target, plan)
    return plan


@dataclass(frozen=True)
class OperationRun:
    """What one operation of a job made.

    Attributes:
        number: its place in the run, 1-based.
        operation: the operation.
        tool: its tool.
        moves: ``(first, end)``: its moves are ``program.moves[first:end]``.
        contours: ``(first, last)`` contour numbers of its cuts in the program (``(0, -1)``
            when it has none).
        placed: what it selects, in the program's work coordinates.
        edge_radius_mm: how far the cut edge lies from the tool path (half the tool for
            a compensated profile, a pocket and a drill; 0 on the line).
        report: what planning found (``None`` for drilling).
        holes: the holes a drill operation drills.
        time_s: its moves' time at their programmed feeds (rapids at the machine's rate
            where its profile gives one), s.
        left_out: indices in ``placed.contours`` of the contours its plan does not cut
            (:attr:`camtool.toolpath.plan.Plan.left_out`).
    """

    number: int
    operation: Operation
    tool: Tool
    moves: tuple[int, int]
    contours: tuple[int, int]
    placed: Drawing
    edge_radius_mm: float
    report: PlanReport | None
    holes: int = 0
    time_s: float = 0.0
    left_out: frozenset[int] = frozenset()

    @property
    def cut(self) -> Drawing:
        """What it cuts: ``placed`` without the contours its plan left out."""
        return self.placed.without(self.left_out)

    @property
    def label(self) -> str:
        """``"operation 2 (pocket 'floor')"``: how messages name it."""
        name = f" {self.operation.name!r}" if self.operation.name else ""
        return f"operation {self.number} ({self.operation.kind}{name})"


@dataclass(frozen=True)
class _Planned:
    moves: list[Move]
    commands: list[tuple[int, Command]]
    warnings: list[str]
    report: PlanReport | None
    placed: Drawing
    holes: int = 0
    left_out: frozenset[int] = frozenset()
    paths: tuple[Contour, ...] = ()


def run_job(
    drawing: Drawing,
    target: Target,
    job: Job,
    output: OutputOptions | None = None,
    *,
    progress: Progress = no_progress,
) -> PostJob:
    """Plan every operation of ``job`` on ``drawing`` and write the program for ``target``.

    Args:
        drawing: the imported drawing, mm.
        target: the target.
        job: the job (:func:`~camtool.jobs.jobfile.load_job`, or :meth:`Job.single` of
            ``post``'s options).
        output: the output format and spindle (``None``: the defaults).
        progress: told the ``planning`` stage (and ``offsetting`` within it) and the
            ``writing`` stage.

    Returns:
        The job's :class:`~camtool.jobs.pipeline.PostJob`, with one
        :class:`OperationRun` per operation in ``operations``.

    Raises:
        InputError: an operation selects nothing, a drill operation selects what is not
            a hole or a hole of another size than its drill, or an operation leaves nothing
            to cut (names the operation).
        UsageError: options the target cannot carry out (depth for a machine without Z...).
        CamtoolError: from any stage, with its exit code.
    """
    from camtool.jobs.header import job_notes, surface_warnings
    from camtool.toolpath.plan import place, place_program

    output = output if output is not None else OutputOptions()
    setup = plan_options(target, job.setup.plan)
    sized = with_drilled_marks(drawing, [op.select for op in job.operations])
    scaled = place(drawing, setup, sized)
    progress(Step("planning", 0, len(drawing.contours)))
    moves: list[Move] = []
    commands: list[tuple[int, Command]] = []
    warnings: list[str] = list(drawing.warnings)
    runs: list[OperationRun] = []
    construction: dict[int, Contour] = {}  # by id: a contour two operations leave, once
    drilled: set[int] = set()  # the drawing's marks an operation selected, by id
    joint = joint_distance(setup.chain_tolerance)  # how the planner chains contours
    chaining = _chaining(drawing, scaled, joint, setup.close_gap)
    here: tuple[float, float, float | None] = (*setup.origin, None)
    loaded: int | None = None
    sequence = job.sequenced()
    cut: list[tuple[Operation, str, tuple[Contour, ...]]] = []  # each operation's paths
    selections = [select(drawing, op.select, chaining) for op in sequence]
    selections_scaled = [(s, _as_scaled(s, drawing, scaled)) for s in selections]
    refuse_too_large(job, sequence, selections_scaled, chaining, setup, target)
    refuse_too_small(selections_scaled, setup, drawing.source)
    for number, (op, (selected, chosen)) in enumerate(
        zip(sequence, selections_scaled, strict=True), start=1
    ):
        tool = job.tool(op.tool)
        where = _where(job, op, number)
        drilled.update(id(m) for m in selected.drawing.marks)
        construction.update((id(c), c) for c in chosen.construction)
        if not chosen.drawing.contours and not chosen.drawing.marks:
            if job.shorthand and chosen.construction:
                raise InputError(
                    f"{drawing.source or 'the drawing'}: nothing to cut: every contour is "
                    "construction (" + "; ".join(construction_notes(chosen.construction)) + ")"
                )
            about = drawing.source if job.shorthand else job.source  # the options: the drawing
            raise InputError(f"{about or 'the job'}: {nothing_selected(scaled, op, where)}")
        last = number == len(sequence)
        try:
            options = _operation_options(target, op, setup, here, last)
        except UsageError as exc:
            if job.shorthand:
                raise
            raise InputError(f"{job.source or 'the job'}: {where}: {as_keys(str(exc))}") from None
        first = len(moves)
        alike = [(w, paths) for o, w, paths in cut if _cuts_alike(o, op)]
        try:
            planned = _plan_operation(
                as_chained(chosen).drawing, op, tool, options, target, here, where, progress, alike
            )
        except (InputError, ToolpathError, UsageError) as exc:
            if job.shorthand or not job.source:
                raise
            # its message starts with ``where``: said of the job file's operation, by the file
            raise type(exc)(f"{job.source}: {exc}") from None
        cut.append((op, where, planned.paths))
        if not job.shorthand and tool.id != loaded and planned.moves:  # none: nothing to cut
            at = spindle_start(planned.moves, 0, _position(moves, here)[:2])
            commands.extend(_tool_change(len(moves), at, tool, loaded, output, target))
            loaded = tool.id
        offset = _last_contour(moves)
        _join(moves, commands, planned, offset)
        warnings.extend(planned.warnings)
        here = _position(moves, here)
        runs.append(
            OperationRun(
                number=number,
                operation=op,
                tool=tool,
                moves=(first, len(moves)),
                contours=_numbers(offset, moves),
                placed=planned.placed,
                edge_radius_mm=_edge(op, tool, options),
                report=planned.report,
                holes=planned.holes,
                left_out=planned.left_out,
                time_s=feed_time_s(moves[first:], target, start=_start(moves, first, setup)),
            )
        )
        del planned  # its moves are in ``moves``: not kept past the placement's shifted copy
    _end_at(moves, options)
    notes = construction_notes(list(construction.values()))
    if not job.shorthand:
        notes.extend(
            unselected(
                scaled,
                [c for _, chosen in selections_scaled for c in chosen.drawing.contours],
                list(construction.values()),
                joint,
                [p for *_, ps in cut for p in ps],
                setup.close_gap,
            )
        )
        notes.extend(undrilled(drawing, drilled))
    warnings[len(drawing.warnings) : len(drawing.warnings)] = notes
    warnings.extend(overlaps(runs, job))
    warnings.extend(holes_cut_outside(runs, job, [ps for *_, ps in cut]))
    placed_all = Drawing(
        tuple(c for r in runs for c in r.placed.contours),
        drawing.source,
        (),
        tuple(m for r in runs for m in r.placed.marks),
    )
    # the program built in the call, and ``moves`` emptied: placing it may shift every
    # move, and each old one goes as its shifted copy is made (no second set at the peak)
    program, placed_all, shift = place_program(
        _unplaced(moves, setup.origin, tuple(dict.fromkeys(warnings)), tuple(commands)),
        placed_all,
        setup,
        target.machine,
    )
    runs = _shifted(runs, placed_all, shift)
    program = dataclasses.replace(
        program,
        notes=job_notes(
            drawing.source,
            target,
            setup if job.shorthand else None,
            job,
            runs,
            placement=_placement(sized, setup, shift),
        ),
        tolerance_mm=setup.tolerance,
        warnings=(*program.warnings, *surface_warnings(runs, target)),
    )
    if job.shorthand:
        program = _spindle_around(program, output, target)
    elif any(isinstance(c, Spindle) for _, c in commands):
        program = dataclasses.replace(
            program, commands=(*program.commands, (len(program.moves), Spindle("off")))
        )
    progress(Step("writing", 0, len(program.moves), target.name))
    pieces: tuple[ToolProgram, ...] = ()
    if target.post.tool_changes == "none" and len({r.tool.id for r in runs}) > 1:
        pieces = per_tool(program, target, output.fmt)
        result = pieces[0].result
    else:
        program = loaded_by_hand(program, target)
        result = target.emit(program, fmt=output.fmt)
    only = runs[0]
    report = only.report if len(runs) == 1 else None
    if report is not None:
        report = dataclasses.replace(report, work_shift=shift)
    return PostJob(
        drawing,
        program,
        target,
        result,
        placed_all,
        only.edge_radius_mm if len(runs) == 1 else 0.0,
        report,
        operations=tuple(runs),
        pieces=pieces,
    )


def _unplaced(
    moves: list[Move],
    origin: Point,
    warnings: tuple[str, ...],
    commands: tuple[tuple[int, Command], ...],
) -> Program:
    """The job's program before its placement, ``moves`` emptied (the program holds them)."""
    program = Program(tuple(moves), origin, warnings, commands=commands)
    moves.clear()
    return program


def _edge(op: Operation, tool: Tool, options: PlanOptions) -> float:
    """How far the cut edge lies from the tool path, mm (a drill's: its radius)."""
    if op.type == "drill":
        return tool.diameter / 2.0
    return options.radius if options.offset != "on" else 0.0


def _chaining(drawing: Drawing, scaled: Drawing, joint_mm: float, close_gap: float) -> Chaining:
    """What contours of ``drawing`` are once chained as the planner chains them.

    They are chained as scaled (``scaled``: ``drawing`` after ``scale``/``fit``, the same
    contours in order), ``joint_mm`` apart at most (:func:`~camtool.geometry.chain.chain_members`),
    and a chain whose own ends lie within ``close_gap`` (mm) is closed, as the planner
    closes it (:func:`~camtool.toolpath.chain.close_gaps`: ``closed = true`` selects it);
    a chain that is a whole circle gives the circle of its first piece as drawn.
    """
    as_scaled = {id(a): b for a, b in zip(drawing.contours, scaled.contours, strict=True)}

    def shapes(contours: Sequence[Contour]) -> list[Shape]:
        joined, members = chain_members([as_scaled[id(c)] for c in contours], joint_mm)
        cut = as_cut(joined, close_gap, joint_mm)[0]  # a line drawn twice: one open line
        out = [Shape(False, None)] * len(contours)
        for drawn, chain, pieces in zip(joined, cut, members, strict=True):
            circle = None
            if circle_of(chain) is not None:  # its pieces are arcs of one centre and radius
                first = contours[pieces[0]].segments[0]
                assert isinstance(first, Arc)
                circle = (first.centre, 2.0 * first.radius)
            shape = Shape(chain.closed, circle, drawn if chain.closed else None)
            for i in pieces:
                out[i] = shape
        return out

    return shapes


def _as_scaled(chosen: Selected, drawing: Drawing, scaled: Drawing) -> Selected:
    """A selection made on ``drawing`` (its own mm: a ``diameter`` as drawn), as ``scaled``.

    ``scaled`` is ``drawing`` after ``scale``/``fit``: the same contours, in order.
    """
    if scaled is drawing:
        return chosen
    contours = {id(a): b for a, b in zip(drawing.contours, scaled.contours, strict=True)}
    marks = {id(a): b for a, b in zip(drawing.marks, scaled.marks, strict=True)}
    picked = chosen.drawing
    return Selected(
        Drawing(
            tuple(contours[id(c)] for c in picked.contours),
            picked.source,
            picked.warnings,
            tuple(marks[id(m)] for m in picked.marks),
        ),
        tuple(contours[id(c)] for c in chosen.construction),
        chosen.chains,  # made of the scaled contours already
    )


def _cuts_alike(a: Operation, b: Operation) -> bool:
    """Whether ``a`` and ``b`` cut a path alike: same type, tool, side and planning options.

    A contour ``b`` selects on the path of one ``a`` cut is then cut again to the same
    depth with the same tool (a fill and its outline put in two operations by their
    colours); drills count their holes apart.
    """
    return a.type != "drill" and (a.type, a.tool, a.side, a.plan) == (
        b.type,
        b.tool,
        b.side,
        b.plan,
    )


def _where(job: Job, op: Operation, number: int) -> str:
    """How messages name an operation (the shorthand is the command's options)."""
    if job.shorthand:
        return "the options"
    name = f" ({op.name!r})" if op.name else ""
    return f"operation {number}{name}"


def _operation_options(
    target: Target,
    op: Operation,
    setup: PlanOptions,
    here: tuple[float, float, float | None],
    last: bool,
) -> PlanOptions:
    """``op``'s planning options for planning it alone, from where the tool is."""
    shared = {
        "scale": 1.0,
        "fit": None,
        "placement": "drawing",
        "translate": (0.0, 0.0),
        "end_position": setup.end_position if last else None,
        "origin": (here[0], here[1]),
        "clearance_z": setup.clearance_z,
        "chain_tolerance": setup.chain_tolerance,
        "close_gap": setup.close_gap,
        "tolerance": setup.tolerance,
    }
    plan = dataclasses.replace(op.plan, **shared)  # type: ignore[arg-type]
    return plan_options(target, plan)


def _plan_operation(
    drawing: Drawing,
    op: Operation,
    tool: Tool,
    options: PlanOptions,
    target: Target,
    here: tuple[float, float, float | None],
    where: str,
    progress: Progress,
    cut_before: Sequence[tuple[str, Sequence[Contour]]] = (),
) -> _Planned:
    """The moves of one operation, in drawing coordinates (scaled, not yet placed).

    ``cut_before``: the paths of the earlier operations that cut alike, by name
    (:func:`~camtool.toolpath.plan.plan_unplaced`).
    """
    if op.type == "drill":
        return _drill(drawing, op, tool, options, here, where)
    from camtool.toolpath.plan import plan_unplaced

    if not drawing.contours:
        raise InputError(f"{where} selects only points, which only a drill operation drills")
    try:
        planned = plan_unplaced(
            drawing,
            options,
            target.machine,
            helix=target.post.helix,
            progress=progress,
            cut_before=cut_before,
        )
    except (InputError, ToolpathError, UsageError) as exc:
        if where == "the options":
            raise
        # said of the job's operation, in its keys (tabs, tab_width), not post's flags
        raise type(exc)(f"{where}: {as_keys(str(exc))}") from None
    program = planned.program
    # said in post's flags: in the job's keys, of its operation
    flags = {f.message for f in options.ineffective()} if where != "the options" else set()
    return _Planned(
        list(program.moves),
        [],
        [f"{where}: {as_keys(w)}" if w in flags else w for w in program.warnings],
        planned.report,
        planned.placed,
        left_out=planned.left_out,
        paths=planned.paths,
    )


def _drill(
    drawing: Drawing,
    op: Operation,
    tool: Tool,
    options: PlanOptions,
    here: tuple[float, float, float | None],
    where: str,
) -> _Planned:
    """A drill operation (:func:`camtool.jobs.drill.drill_moves`) as a planned operation."""
    moves, commands, holes = drill_moves(drawing, op, tool, options, here, where)
    placed = Drawing(drawing.contours, drawing.source, (), drawing.marks)
    return _Planned(moves, commands, [], None, placed, holes=holes)


def _tool_change(
    index: int,
    after: int,
    tool: Tool,
    loaded: int | None,
    output: OutputOptions,
    target: Target,
) -> list[tuple[int, Command]]:
    """Spindle off (when a tool turns), the change, the spindle on for the new tool.

    The change goes before move ``index``, the spindle start ``after`` moves later (1:
    after the operation's rise to clearance, 0: at once).
    """
    rpm = _rpm(tool, output, target)
    out: list[tuple[int, Command]] = []
    if loaded is not None and rpm:
        out.append((index, Spindle("off")))
    out.append((index, ToolChange(tool.id, tool.describe())))
    if rpm:
        out.append((index + after, Spindle("cw", rpm)))
        if output.spindle_dwell_s > 0:
            out.append((index + after, Dwell(output.spindle_dwell_s)))
    return out


def _rpm(tool: Tool, output: OutputOptions, target: Target) -> float:
    if tool.rpm is not None:
        return tool.rpm
    if output.spindle_rpm is not None:
        return output.spindle_rpm
    return target.spindle_rpm or 0.0


def _spindle_around(program: Program, output: OutputOptions, target: Target) -> Program:
    """The shorthand's spindle: on after the first rise, off after the last move.

    :meth:`~camtool.model.program.Program.with_spindle` places it.
    """
    rpm = target.spindle_rpm if output.spindle_rpm is None else output.spindle_rpm
    if not rpm or any(isinstance(c, Spindle) for _, c in program.commands):
        return program
    return program.with_spindle(rpm, dwell_s=output.spindle_dwell_s)


def _end_at(moves: list[Move], options: PlanOptions) -> None:
    """The job's ``end_position`` rapid, at clearance, when its last operation wrote none.

    The last operation's plan ends the program there; a drill operation's cycles, and an
    operation each of whose contours an earlier one cut, plan no such move. The rapid
    goes last, as :func:`~camtool.toolpath.plan.place_program` expects it (it keeps it
    where it was asked, in work coordinates, as the plan's own).
    """
    from camtool.toolpath.plan import is_end_move

    if options.end_position is None or not moves or is_end_move(moves[-1], options):
        return
    last = moves[-1]
    z = _z_of(moves)
    if z is not None and z < options.clearance:
        moves.append(Rapid(last.x, last.y, options.clearance, contour=0))
        z = options.clearance
    moves.append(Rapid(*options.end_position, z, contour=0))


def _numbers(offset: int, moves: Sequence[Move]) -> tuple[int, int]:
    """An operation's ``(first, last)`` contour numbers, ``(0, -1)`` when it cuts none."""
    last = _last_contour(moves)
    return (offset + 1, last) if last > offset else (0, -1)


def _last_contour(moves: Sequence[Move]) -> int:
    return max((m.contour for m in moves), default=0)


def _join(
    moves: list[Move], commands: list[tuple[int, Command]], planned: _Planned, offset: int
) -> None:
    """Append an operation's moves (contours renumbered after ``offset``) and commands.

    The operation's first move is its rise to clearance where the tool stands. When the
    last operation left the tool there at that height and no command (a tool change)
    comes between, it moves nothing and is left out.
    """
    new = planned.moves
    skip = 0
    if moves and new and not any(i == len(moves) for i, _ in commands):
        first, last = new[0], moves[-1]
        still = (first.x, first.y) == (last.x, last.y) and first.z == _z_of(moves)
        if isinstance(first, Rapid) and still and not any(i == 0 for i, _ in planned.commands):
            skip = 1
    base = len(moves) - skip
    rest: Sequence[Move] = new[skip:]
    if offset:  # contours numbered after the operations before (the first: no copy)
        rest = [
            dataclasses.replace(m, contour=m.contour + offset) if m.contour else m for m in rest
        ]
    moves.extend(rest)
    commands.extend((i + base, c) for i, c in planned.commands)


def _z_of(moves: Sequence[Move]) -> float | None:
    for move in reversed(moves):
        if move.z is not None:
            return move.z
    return None


def _position(
    moves: Sequence[Move], here: tuple[float, float, float | None]
) -> tuple[float, float, float | None]:
    if not moves:
        return here
    z = _z_of(moves)
    return (moves[-1].x, moves[-1].y, z if z is not None else here[2])


def _start(moves: Sequence[Move], first: int, setup: PlanOptions) -> tuple[float, float, float]:
    """Where the tool stands before ``moves[first]`` (Z 0 when no Z was written yet)."""
    if first == 0:
        return (*setup.origin, 0.0)
    z = _z_of(moves[:first])
    return (moves[first - 1].x, moves[first - 1].y, 0.0 if z is None else z)


def feed_time_s(
    moves: Sequence[Move], target: Target, *, start: tuple[float, float, float]
) -> float:
    """The time of ``moves`` at their programmed feeds, s (Z moves counted).

    Rapids count at the profile's ``max_rate_mm_min`` (``[machine.timing]``) where it has
    one, else not at all; acceleration is not counted. A header estimate: ``verify``
    simulates the controller's own timing.
    """
    rate = target.machine.timing.get("max_rate_mm_min")
    x, y, z = start
    total = 0.0
    for move in moves:
        nz = z if move.z is None else move.z
        xy = (
            arc_length((x, y), (move.x, move.y), (move.cx, move.cy), move.clockwise)
            if isinstance(move, ArcMove)
            else math.dist((x, y), (move.x, move.y))
        )
        length = math.hypot(xy, nz - z)
        if isinstance(move, Rapid):
            if rate:
                total += length / float(rate) * 60.0
        elif move.feed_mm_min > 0:
            total += length / move.feed_mm_min * 60.0
        x, y, z = move.x, move.y, nz
    return total


def _placement(drawing: Drawing, setup: PlanOptions, shift: Point) -> tuple[float, float, float]:
    """``(k, dx, dy)``: the program's point of a drawing point ``p`` is ``k·p + (dx, dy)``."""
    from camtool.toolpath.plan import scaling

    k, dx, dy = scaling(drawing, setup) if drawing.contours or drawing.marks else (1.0, 0.0, 0.0)
    return (k, dx + shift[0], dy + shift[1])


def _shifted(runs: list[OperationRun], placed: Drawing, shift: Point) -> list[OperationRun]:
    """``runs`` placed by ``shift`` (mm), their contours and marks taken from ``placed``.

    ``placed`` is the runs' drawings joined in order and shifted (:func:`place_program`):
    each run's part of it is that run's drawing shifted, so it is not shifted again.
    """
    if shift == (0.0, 0.0):
        return runs
    out, contours, marks = [], 0, 0
    for run in runs:
        own = run.placed
        moved = Drawing(
            placed.contours[contours : contours + len(own.contours)],
            own.source,
            own.warnings,
            placed.marks[marks : marks + len(own.marks)],
        )
        contours, marks = contours + len(own.contours), marks + len(own.marks)
        report = run.report
        if report is not None:
            report = dataclasses.replace(report, work_shift=shift)
        out.append(dataclasses.replace(run, placed=moved, report=report))
    return out


def refuse_operation_options(given: list[str]) -> None:
    """Refuse per-operation options given on the command line with ``--job``.

    Raises:
        UsageError: ``given`` (their flags) is not empty.
    """
    if given:
        raise UsageError(
            f"{', '.join(given)}: with --job, each operation has its own; put them in the job "
            "file's [[operations]] or [[tools]] (with --job the command line may give "
            "--origin, --translate, --scale or --fit, --clearance-z, --end-position, "
            "--tolerance, --chain-tolerance and --close-gap)"
        )
