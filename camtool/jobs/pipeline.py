"""The main job as one library call: drawing file → toolpath → code for a target."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.importers import read_drawing, read_drawing_bytes
from camtool.importers.options import ImportOptions
from camtool.jobs.by_hand import (
    changed_before_cutting,
    idle_changes,
    loaded_by_hand,
    own_stops_dropped,
    per_tool,
)
from camtool.jobs.header import HEADER_CHARS, carried_notes, job_notes
from camtool.jobs.inputs import is_program_file
from camtool.jobs.run import OutputOptions, PostJob, run_job
from camtool.model.errors import InputError, TooLargeError, UsageError
from camtool.model.program import Move, Program, ToolChange
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import BBox, Drawing
from camtool.post.base import Target, plane_chords
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions, drawing_only

if TYPE_CHECKING:
    from camtool.importers.gcode_target import Reading
    from camtool.jobs.job import Job
    from camtool.jobs.run import OperationRun
    from camtool.toolpath.plan import PlanReport
    from camtool.verify.verifier import Part, Verification


def load_target_checked(name: str, *, machine_file: Path | str | None = None) -> Target:
    """The target ``name`` (:func:`camtool.post.registry.load_target`), its motion names checked.

    Every name the machine profile gives in ``[machine.motion]`` (``line``,
    ``arc``, ``chords``) and its ``[machine.timing]`` table are resolved now, in
    the verifier's library and every installed target's ``MOTION``, so that a
    misspelt name or a value out of range in a target file or a ``--machine`` file
    is refused before any code is written, not only when the code is verified.
    (Profiles take any name since targets bring their own.) A built-in target
    without ``machine_file`` is not re-checked: its profile is tested with camtool.

    Raises:
        UsageError: no such target.
        InputError: the target or machine file is invalid, or names an unknown
            interpolator or chord rule (the message names the file and lists the
            valid names).
    """
    target = load_target(name, machine_file=machine_file)
    if target.origin == "builtin" and machine_file is None:
        return target
    from camtool.verify.motion import library

    try:
        library(target.machine).check(target.machine)
    except InputError as exc:
        source = machine_file if machine_file is not None else name
        raise InputError(f"{source}: {exc}") from exc
    return target


def post_file(
    path: str | Path,
    target_name: str,
    plan: PlanOptions | None = None,
    output: OutputOptions | None = None,
    *,
    machine_file: Path | None = None,
    import_options: ImportOptions | None = None,
    progress: Progress = no_progress,
    job: Job | None = None,
) -> PostJob:
    """Load the target called ``target_name`` and post the file at ``path`` (see :func:`post_path`).

    Args:
        path: a drawing, or an existing G-code program.
        target_name: a built-in target or a target ``.toml`` path.
        plan: the planning options (``None``: the defaults, the target's feed).
        output: how the program is written (``None``: the defaults).
        machine_file: TOML file laid over the target's machine profile.
        import_options: how the drawing is read (layers, units…).
        progress: told the stages as the job goes (see :func:`post_path`).
        job: the operations and tools to run (``None``: ``plan`` is the one operation).

    Raises:
        CamtoolError: from any stage, with its exit code.
    """
    target = load_target_checked(target_name, machine_file=machine_file)
    return post_path(
        path, target, plan, output, import_options=import_options, progress=progress, job=job
    )


def post_path(
    path: str | Path,
    target: Target,
    plan: PlanOptions | None = None,
    output: OutputOptions | None = None,
    *,
    import_options: ImportOptions | None = None,
    progress: Progress = no_progress,
    verifying: bool = False,
    job: Job | None = None,
) -> PostJob:
    """Post the file at ``path``: a drawing is planned, a G-code program re-posted.

    A program (by its ending, :func:`camtool.jobs.inputs.is_program_file`) is already a toolpath:
    only ``plan.feed_mm_min`` and ``output`` apply (:func:`post_program`). A drawing's
    curves are fitted for the size ``plan`` gives it (:func:`sized`), and a drawing
    whose toolpath cannot fit the machine's travel is refused as soon as it is read
    (:func:`travel_check`).

    Args:
        path: a drawing (DXF, SVG, points) or an existing G-code program.
        target: the target to write for.
        plan: the planning options (``None``: the defaults, the target's feed).
        output: how the program is written (``None``: the defaults).
        import_options: how the drawing is read (layers, units…; its ``scale`` and
            ``fit`` are ``plan``'s).
        progress: told the stages (:class:`~camtool.model.progress.Step`) as the job goes:
            ``reading`` (and for an SVG ``fitting`` and ``contours``,
            :func:`camtool.importers.read_drawing`), ``planning`` and ``writing``
            (:func:`post_drawing`); a program: ``reading`` and ``writing``. It changes
            nothing in the job.
        verifying: the caller verifies the job against its drawing next (``post
            --verify``, ``--preview``): while this process waits for the offsets' child
            to load OpenCASCADE, it loads what that comparison will
            (:func:`camtool.verify.drawing_compare.comparison_preloads`). Only the time depends
            on it.
        job: the operations and tools to run (``post --job``); ``None``: ``plan`` is
            the one operation.

    Raises:
        UsageError: a planning option (offset, tool diameter, scale, depth, order...)
            given for a program; it is refused, not ignored.
        CamtoolError: from any stage, with its exit code.
    """
    plan = plan if plan is not None else PlanOptions()
    if not is_program_file(path):
        from camtool.accel.cores import meanwhile
        from camtool.toolpath.compensate import offsets_ahead

        shared = plan if job is None else job.setup.plan
        with offsets_ahead(plan if job is None else _offsetting(job)):
            drawing = read_drawing(
                path,
                sized(import_options, shared, job),
                progress=progress,
                check=travel_check(plan, target) if job is None else None,
            )
            with meanwhile(_preloads(drawing) if verifying else []):
                layers = import_options.layers if import_options is not None else None
                return post_drawing(
                    drawing, target, plan, output, progress=progress, layers=layers, job=job
                )
    refuse_planning(path, drawing_only(plan.given()) + (["--job"] if job is not None else []))
    from camtool.importers.gcode import read_gcode

    progress(Step("reading", name=Path(path).name))
    program = read_gcode(path, reading=reading_for(target, plan))
    head = ""
    if Path(path).is_file():  # read just now: its header, for the notes (a pipe is read once)
        with Path(path).open("rb") as file:
            head = file.read(HEADER_CHARS).decode("utf-8", "replace")
    return post_program(
        program,
        target,
        output,
        feed_mm_min=plan.feed_mm_min,
        tolerance_mm=plan.tolerance,
        source=str(path),
        progress=progress,
        carried=carried_notes(head),
    )


def _offsetting(job: Job) -> PlanOptions:
    """An operation of ``job`` that offsets for its tool (to start OpenCASCADE early), if any."""
    for op in job.operations:
        if op.plan.offset != "on":
            return op.plan
    return job.operations[0].plan


def _preloads(drawing: Drawing) -> list[Callable[[], object]]:
    """What verifying a job planned from ``drawing`` will load, to load while waiting."""
    from camtool.verify.drawing_compare import comparison_preloads

    return comparison_preloads(drawing)


def post_bytes(
    data: bytes,
    name: str,
    target: Target,
    plan: PlanOptions | None = None,
    output: OutputOptions | None = None,
    *,
    import_options: ImportOptions | None = None,
    job: Job | None = None,
    kind: str | None = None,
    progress: Progress = no_progress,
) -> PostJob:
    """Post a file given as its bytes, as :func:`post_path` posts the file ``name``.

    For a process that does not share the file's disk (a batch's Dask worker), and for
    standard input: the kind is chosen by ``name``'s ending (or ``kind``, an ending such
    as ``.svg``), and messages, warnings and the program's notes name ``name``, so the
    job is the one :func:`post_path` makes from the file.

    Args:
        data: the file's bytes.
        name: the file's name as the user gave it (only its ending and text are used).
        target: the target to write for.
        plan: the planning options (``None``: the defaults, the target's feed).
        output: how the program is written (``None``: the defaults).
        import_options: how the drawing is read (layers, units…).
        job: the operations and tools to run (``None``: ``plan`` is the one operation).
        kind: the file's ending when ``name`` has none (``<stdin>``).
        progress: told the stages, as by :func:`post_path`.

    Raises:
        UsageError: a planning option given for a program (see :func:`post_path`).
        CamtoolError: from any stage, with its exit code.
    """
    plan = plan if plan is not None else PlanOptions()
    suffix = kind if kind is not None else Path(name).suffix
    if not is_program_file(f"x{suffix}"):
        shared = plan if job is None else job.setup.plan
        options = sized(import_options, shared, job)
        check = travel_check(plan, target) if job is None else None
        progress(Step("reading", name=name))
        drawing = read_drawing_bytes(data, name=name, suffix=suffix, options=options, check=check)
        layers = import_options.layers if import_options is not None else None
        return post_drawing(
            drawing, target, plan, output, progress=progress, layers=layers, job=job
        )
    refuse_planning(name, drawing_only(plan.given()) + (["--job"] if job is not None else []))
    from camtool.importers.gcode import read_gcode_bytes

    progress(Step("reading", name=name))
    return post_program(
        read_gcode_bytes(data, source=name, reading=reading_for(target, plan)),
        target,
        output,
        feed_mm_min=plan.feed_mm_min,
        tolerance_mm=plan.tolerance,
        source=name,
        progress=progress,
        carried=carried_notes(data[:HEADER_CHARS].decode("utf-8", "replace")),
    )


def reading_for(target: Target, plan: PlanOptions) -> Reading:
    """How a program posted to ``target`` is read: ``--feed``, the target's offsets, its start."""
    from camtool.importers.gcode_target import Reading

    post = target.post
    return Reading(
        plan.feed_mm_min,
        post.length_offsets,
        post.work_offsets,
        known_start=True,
        path_controls=post.path_controls,
    )


def sized(
    options: ImportOptions | None, plan: PlanOptions, job: Job | None = None
) -> ImportOptions:
    """``options`` (``None``: the defaults) for a drawing planned with ``plan``.

    With the scale planning gives the drawing (``plan.scale``, ``plan.fit``), so that
    its curves are fitted within the tolerance at that size, in the program
    (:meth:`~camtool.importers.options.ImportOptions.curve_tolerance`); and with the
    layers ``job``'s operations name read even where the drawing hides them
    (:attr:`~camtool.importers.options.ImportOptions.shown`).
    """
    base = options if options is not None else ImportOptions()
    shown = (
        ()
        if job is None
        else tuple(name for op in job.operations for name in (op.select.layers or ()))
    )
    return dataclasses.replace(base, scale=plan.scale, fit=plan.fit, shown=shown)


def travel_check(plan: PlanOptions, target: Target) -> Callable[[BBox], None] | None:
    """The check of a drawing's size against the travel as it is read, or ``None``.

    Only where the toolpath passes within the chaining and fitting tolerances of every
    point of the drawing: ``--offset on`` (each contour cut on its line), without ``--fit``
    (which scales the drawing into a box). Then
    :func:`~camtool.toolpath.placement.too_large_drawing` refuses a drawing larger than
    the travel as soon as the importer knows its extent, before its curves are fitted.
    An outside offset cuts only the contours that are closed once chained (an open one is
    left out, said in a warning), which the importer does not know: its drawing is judged
    once read, before planning (:func:`camtool.jobs.travel.refuse_too_large`); inside
    offsets and pockets, whose cuts can vanish, after planning only, as every program is.
    """
    if plan.fit is not None or plan.offset != "on":
        return None
    from camtool.geometry.chain import joint_distance
    from camtool.toolpath.placement import Placing, too_large_drawing

    machine = target.machine
    slack = joint_distance(plan.chain_tolerance) + plan.tolerance
    margin = 2.0 * plan.lead_in
    placing = Placing(plan.placement, plan.translate, (margin, margin))

    def check(box: BBox) -> None:
        too_large_drawing(box, machine, placing, scale=plan.scale, slack_mm=slack)

    return check


def refuse_planning(path: str | Path, given: list[str]) -> None:
    """Refuse planning options (``given``: their flags) for the G-code program at ``path``.

    Raises:
        UsageError: ``given`` is not empty; the message names the options.
    """
    if given:
        raise UsageError(
            f"{path} is already a toolpath (G-code): {', '.join(given)} "
            f"{'only applies' if len(given) == 1 else 'only apply'} to drawings; plan it in "
            "the program that wrote it"
        )


def post_program(
    program: Program,
    target: Target,
    output: OutputOptions | None = None,
    *,
    feed_mm_min: float | None = None,
    tolerance_mm: float | None = None,
    source: str = "",
    progress: Progress = no_progress,
    carried: tuple[str, ...] = (),
) -> PostJob:
    """Re-post an existing program (e.g. G-code another CAM wrote) for a target.

    No planning: the program is already a toolpath. ``feed_mm_min``, when given,
    replaces the feed of every cutting move (the program's own feeds are kept
    otherwise). Arcs in the ZX and YZ planes (G18/G19) stay arcs for a target that
    writes them; for any other they become chords within ``tolerance_mm``
    (``--tolerance``; ``None``: the machine's chord tolerance), with a warning
    (:func:`camtool.post.base.plane_chords`). For a target without a Z axis (depth set
    by hand, UNAM-GMM S000-08) Z is dropped with a warning: Z-only moves go, XY moves keep their
    kind, as the thesis users edited VisiCAM output by hand (UNAM-GMM §3.8).
    ``output.fmt`` is the dialect's output format (default: its first);
    ``output.spindle_rpm`` > 0 starts the spindle (after a first Z-only rapid:
    :meth:`~camtool.model.program.Program.with_spindle`) and stops it after the last
    (when the program has no spindle commands of its own), waiting
    ``output.spindle_dwell_s`` seconds after it starts. ``source`` (the input's file
    name) goes into the job notes (:func:`job_notes`) unless the program has notes, and
    ``carried`` after them: the notes of the input's camtool header
    (:func:`~camtool.jobs.header.carried_notes`), which still hold as nothing moves.
    Nothing is added to the program's motion: no move to X0 Y0, no clearance move.
    A program that changes tools more than once before any cut with another tool (its
    first change may follow rapids, as pcb2gcode's retract to the tool change height) is
    written one program per tool for a target that cannot change tools (``pieces``: the
    rapids are the first program's); a tool change or stop the target cannot write
    otherwise is refused, never dropped.
    ``progress`` is told the ``writing`` stage (``total``: the program's moves).

    Raises:
        CamtoolError: whatever the target cannot express (names the block).
    """
    from camtool.model.program import Rapid

    output = output if output is not None else OutputOptions()
    if feed_mm_min is not None:
        moves = tuple(
            m if isinstance(m, Rapid) else dataclasses.replace(m, feed_mm_min=feed_mm_min)
            for m in program.moves
        )
        program = dataclasses.replace(program, moves=moves)
    if tolerance_mm is not None:
        program = dataclasses.replace(program, tolerance_mm=tolerance_mm)
    program, chorded = plane_chords(program, target, tolerance_mm)
    if chorded:
        program = dataclasses.replace(program, warnings=(*program.warnings, chorded))
    if not target.machine.has_z:
        program = _flatten(program, target.name)
    if not program.notes:
        program = dataclasses.replace(program, notes=job_notes(source, target, carried=carried))
    program = _with_spindle(program, output.spindle_rpm, output.spindle_dwell_s)
    progress(Step("writing", 0, len(program.moves), target.name))
    changes = sum(isinstance(c, ToolChange) for _, c in program.commands)
    cuts_first = changes > 0 and not changed_before_cutting(program)
    if target.post.tool_changes == "none" and (changes > 1 or cuts_first):
        idle = idle_changes(program)
        if idle:
            tools = ", ".join(f"T{c.tool}" for c in idle)
            note = f"no program for {tools}: the program cuts nothing after changing to it"
            program = dataclasses.replace(program, warnings=(*program.warnings, note))
        gone = {id(c) for c in idle}
        busy = dataclasses.replace(  # without the changes after which nothing is cut
            program, commands=tuple((i, c) for i, c in program.commands if id(c) not in gone)
        )
        if cuts_first and len(idle) == changes:  # one tool cuts, the one loaded at the start
            own = own_stops_dropped(program.commands)[0]
            alone = tuple((i, c) for i, c in own if not isinstance(c, ToolChange))
            program = dataclasses.replace(program, commands=alone)
        elif changes - len(idle) == 1 and changed_before_cutting(busy):
            program = busy  # one tool cuts, loaded before any cut: its program is -o's
        else:
            pieces = per_tool(program, target, output.fmt)  # one program per tool
            return PostJob(None, program, target, pieces[0].result, None, 0.0, pieces=pieces)
    program = loaded_by_hand(program, target)
    if target.post.tool_changes == "stop":  # the change is written as a stop: its own is that
        kept, stopped = own_stops_dropped(program.commands)
        said = [  # what the own stop said (a (MSG, ...) before it) goes with the change
            (i, _said_with(c, stopped.get(id(c), "")) if isinstance(c, ToolChange) else c)
            for i, c in kept
        ]
        program = dataclasses.replace(program, commands=tuple(said))
    elif target.post.tool_changes == "code" and not target.post.stops:
        kept, stopped = own_stops_dropped(program.commands)
        if stopped:  # the machine changes the tool itself: nothing to pause for
            note = (
                f"{len(stopped)} stop(s) right after a tool change (M6 then M0: a pause to "
                f"change the tool by hand) not written: {target.name} changes tools itself "
                "and has no stop"
            )
            program = dataclasses.replace(
                program, commands=tuple(kept), warnings=(*program.warnings, note)
            )
    return PostJob(None, program, target, target.emit(program, fmt=output.fmt), None, 0.0)


def _with_spindle(program: Program, rpm: float | None, dwell_s: float = 0.0) -> Program:
    """``program`` with spindle on/off around it when ``rpm`` > 0 and it has none.

    ``dwell_s`` > 0 waits after the spindle starts (``--spindle-dwell``).
    """
    from camtool.model.program import Spindle

    if not rpm or any(isinstance(c, Spindle) for _, c in program.commands):
        return program
    return program.with_spindle(rpm, dwell_s=dwell_s)


def _flatten(program: Program, target: str) -> Program:
    """The program without Z (see :func:`post_program`); unchanged when it has none.

    A cut that starts and ends above the stock (Z > 0) in a program that cuts at or
    below Z 0 is travel at the feed (a retract done with ``G1``, a move between
    cuts): without Z it would cut, so it is written as a rapid, the target's travel.
    """
    from camtool.model.program import Rapid

    depths = {m.z for m in program.moves if m.z is not None}
    if not depths:
        return program
    above = _feeds_above_stock(program)
    travel = 0  # the cuts above the stock written as rapids
    here = program.origin
    moves: list[Move] = []
    lines: list[int] = []  # the input line of each kept move, for messages
    new_index = []  # old move index -> index in the flattened program
    for i, move in enumerate(program.moves):
        new_index.append(len(moves))
        if (move.x, move.y) == here and not hasattr(move, "cx"):
            continue  # a Z-only move
        if i in above:
            moves.append(Rapid(move.x, move.y, contour=move.contour))
            travel += 1
        else:
            moves.append(dataclasses.replace(move, z=None))
        if program.lines:
            lines.append(program.lines[i])
        here = (move.x, move.y)
    new_index.append(len(moves))
    commands = tuple((new_index[i], c) for i, c in program.commands)
    dropped = len(program.moves) - len(moves)
    warning = (
        f"{target} has no Z axis: {dropped} Z-only move(s) dropped and Z removed from the "
        f"others ({len(depths)} Z level(s) in the program); set the depth by hand"
    )
    if travel:
        warning += (
            f"; {travel} cut(s) above the stock (Z > 0 all along: travel at the feed) "
            "written as rapids, since without Z they would cut"
        )
    return dataclasses.replace(
        program,
        moves=tuple(moves),
        warnings=(*program.warnings, warning),
        lines=tuple(lines),
        commands=commands,
    )


def _feeds_above_stock(program: Program) -> set[int]:
    """Indices of the cuts that start and end above Z 0, if the program cuts at or below it.

    A program that never cuts at or below Z 0 has its zero elsewhere (on the machine's
    bed): none is taken for travel then. A move whose start height is not known yet is
    not taken either.
    """
    from camtool.model.program import Rapid

    z: float | None = None
    above: set[int] = set()
    cuts_below = False
    for i, move in enumerate(program.moves):
        end = move.z if move.z is not None else z
        if not isinstance(move, Rapid):
            if z is not None and end is not None and z > 0 and end > 0:
                above.add(i)
            elif end is not None and (end <= 0 or (z is not None and z <= 0)):
                cuts_below = True
        z = end
    return above if cuts_below else set()


def post_drawing(
    drawing: Drawing,
    target: Target,
    plan: PlanOptions | None = None,
    output: OutputOptions | None = None,
    *,
    progress: Progress = no_progress,
    layers: tuple[str, ...] | None = None,
    job: Job | None = None,
) -> PostJob:
    """Plan a drawing and post it for a target: the one-operation job of ``plan``.

    ``plan`` is :meth:`~camtool.jobs.job.Job.single`'s shorthand, run by
    :func:`camtool.jobs.run.run_job` as every job is.

    Args:
        drawing: the imported drawing, mm.
        target: the target (see :func:`camtool.post.registry.load_target`).
        plan: the planning options (``offset``, ``tool_diameter``, ``feed_mm_min`` —
            ``None`` takes the target's —, ``tolerance``, ``scale``, ``fit``,
            ``depth``, ``order``...); ``None``: the defaults.
        output: the output format and spindle (``None``: the defaults; the spindle
            speed then is the target's ``spindle_rpm``, which may be none).
        progress: told the ``planning`` stage (``total``: the drawing's contours), the
            ``offsetting`` stage within it (:func:`~camtool.toolpath.plan.plan_drawing`) and
            the ``writing`` stage (``total``: the program's moves; ``name``: the target).
        layers: the layers ``--layers`` named (``None``: all): their construction
            geometry (centre lines...) is cut too, as asked by name.
        job: a job of operations and tools to run instead of ``plan``'s one operation.

    Raises:
        TooLargeError: the toolpath is larger than the travel; with the drawing's
            :attr:`~camtool.model.shapes.Drawing.size_note` when it has one.
        CamtoolError: from any stage, with its exit code.
    """
    from camtool.jobs.job import Job

    if job is None:
        job = Job.single(plan if plan is not None else PlanOptions(), layers)
    try:
        return run_job(drawing, target, job, output, progress=progress)
    except TooLargeError as exc:
        if not drawing.size_note:
            raise
        raise TooLargeError(f"{exc}; {drawing.size_note}") from None


def verify_job(
    job: PostJob,
    *,
    budget: bool = True,
    budget_now: Progress | None = None,
    progress: Progress = no_progress,
) -> Verification:
    """Verify what ``job`` emitted: read its code back and simulate it against its drawing.

    The plan's findings go along, so features the planner reported it cannot cut
    with this tool are measured apart (:func:`camtool.verify.verifier.verify_program`),
    and so does the unrounded plan, so that the error budget knows what rounding
    the emitted numbers costs (``budget=False``: no error budget; ``budget_now``: it
    is computed now, told to that progress callback, as ``verify_program`` says;
    ``progress``: where the whole program's verification is).

    A job of several operations is verified whole (deviation, contours, time), and each
    operation again alone against the drawing it cuts, with its own tool
    (:attr:`~camtool.verify.verifier.Verification.parts`, :func:`verify_operation`).

    Raises:
        CamtoolError: the target cannot read its own code back, or its machine
            profile is invalid for the verifier.
    """
    from camtool.verify.not_cut import CHAIN_JOIN_MM
    from camtool.verify.verifier import verify_code

    several = len(job.operations) > 1
    code = job.result.code
    if job.pieces:  # one program per tool: their moves, one after the other
        code = job.target.emit(_without_changes(job.program)).code
    whole = verify_code(
        code,
        job.target,
        source=f"<{job.target.name} code>",
        against=None if several else job.cut,
        tool_diameter=2.0 * job.edge_radius_mm,
        findings=job.plan.placed_findings() if job.plan is not None else (),
        planned=job.program,
        budget=budget,
        budget_now=budget_now,
        joint_mm=job.plan.joint_mm if job.plan is not None else CHAIN_JOIN_MM,
        progress=progress,
    )
    if not several:
        return whole
    # an operation left with nothing (each contour cut by an earlier one) has no code
    parts = tuple(verify_operation(job, r) for r in job.operations if r.moves[0] < r.moves[1])
    return dataclasses.replace(whole, parts=parts)


def _said_with(change: ToolChange, message: str) -> ToolChange:
    """``change`` saying ``message`` (its dropped own stop's) where it says nothing itself."""
    if not message or change.description:
        return change
    return dataclasses.replace(change, description=message)


def _without_changes(program: Program) -> Program:
    """``program`` without its tool changes and their own stops, as :func:`per_tool` wrote it.

    The moves of a job written per tool, one program after the other.
    """
    kept = own_stops_dropped(program.commands)[0]
    commands = tuple((i, c) for i, c in kept if not isinstance(c, ToolChange))
    return dataclasses.replace(program, commands=commands)


def verify_operation(job: PostJob, run: OperationRun) -> Part:
    """One operation of ``job`` written alone, read back, simulated and compared with its drawing.

    The operation's moves and commands, from where the job left the tool, are written
    for the job's target as they are in the job's program; the machined edge is its
    tool's (a drill's hole is the drill's diameter about its centre).
    """
    from camtool.verify.not_cut import CHAIN_JOIN_MM
    from camtool.verify.verifier import Part, verify_code

    first, end = run.moves
    program = job.program
    here = (
        program.origin if first == 0 else (program.moves[first - 1].x, program.moves[first - 1].y)
    )
    commands = tuple(
        (i - first, c)
        for i, c in program.commands
        if first <= i < end and not isinstance(c, ToolChange)
    )
    alone = Program(program.moves[first:end], here, commands=commands)
    code = job.target.emit(alone).code
    v = verify_code(
        code,
        job.target,
        source=f"<{job.target.name} code of {run.label}>",
        against=run.cut,
        tool_diameter=2.0 * run.edge_radius_mm,
        findings=run.report.placed_findings() if run.report is not None else (),
        planned=alone,
        budget=False,
        joint_mm=run.report.joint_mm if run.report is not None else CHAIN_JOIN_MM,
    )
    return Part(f"{run.label} T{run.tool.id}", run.moves, v)


def report_json(v: Verification, plan: PlanReport | None = None) -> str:
    """The verify report of ``v`` as indented JSON text with a final newline.

    ``plan`` (what planning found, when the code was planned here) adds a ``plan``
    key (:func:`camtool.verify.report.report_dict`).
    """
    import json

    from camtool.verify.report import report_dict

    # json.dumps(indent=2)'s text, joined 8 192 pieces at a time: dumps keeps every piece
    # (a few characters each) until the end, ~15x the text for a report of many contours
    parts, pieces = [], []
    for piece in json.JSONEncoder(indent=2).iterencode(report_dict(v, plan)):
        pieces.append(piece)
        if len(pieces) == 8192:
            parts.append("".join(pieces))
            pieces.clear()
    parts.append("".join(pieces))
    return "".join(parts) + "\n"
