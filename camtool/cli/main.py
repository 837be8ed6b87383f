"""The ``camtool`` command line: thin click wrappers over the library.

stdout carries data only; messages go to stderr. Exit codes: 0 ok, 1 error,
2 usage, 3 unreadable or invalid input, 4 verified error over the limit.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from camtool.cli.batch import batch
from camtool.cli.calibrate import calibrate
from camtool.cli.common import (
    JOB,
    MACHINE,
    NUMBER,
    chain_tolerance_option,
    import_options,
    import_settings,
    number_range,
    output_settings,
    picture_ahead,
    plan_settings,
    post_options,
    publishes,
    read_job,
    refuse_operation_flags,
    say_written,
    warn,
    write_output,
)
from camtool.cli.job import job
from camtool.cli.preview import preview
from camtool.cli.send import send, simulate_device
from camtool.model.errors import (
    CamtoolError,
    InputError,
    UsageError,
    VerifyLimitError,
    out_of_memory,
    readable,
)
from camtool.model.version import __version__
from camtool.toolpath.options import MAX_TOOL_DIAMETER_MM

if TYPE_CHECKING:
    from collections.abc import Callable

    from camtool.cli.progress import StageReporter
    from camtool.jobs.run import PostJob
    from camtool.model.shapes import Drawing
    from camtool.post.registry import TargetEntry
    from camtool.toolpath.plan import PlanReport
    from camtool.verify.verifier import Verification


def _verify_outputs(command: Callable[..., None]) -> Callable[..., None]:
    """The options every verifying command shares (--report, --preview, --max-error-um, ...)."""
    command = click.option(
        "--no-budget",
        is_flag=True,
        help="Skip the error budget (it re-simulates the program once per error source).",
    )(command)
    command = click.option(
        "--strict",
        is_flag=True,
        help="--max-error-um also counts the features the planner reported it cannot cut "
        "as drawn with this tool (tight corners, regions narrower than the tool).",
    )(command)
    command = click.option(
        "--max-error-um",
        type=number_range(min=0),
        default=None,
        metavar="N",
        help="Exit with code 4 when the predicted error of what was cut exceeds N µm (for CI); "
        "also when a drawing given to compare with does not overlap the program.",
    )(command)
    command = click.option(
        "--preview",
        default=None,
        metavar="P.png|P.svg",
        help="Draw the nominal path and the simulated one, coloured by deviation.",
    )(command)
    return click.option(
        "--report",
        default=None,
        metavar="R.json",
        help="Write the verify report as JSON ('-' for stdout).",
    )(command)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="camtool")
def cli() -> None:
    """camtool: drawings to machine code for small and legacy CNC machines.

    Lengths are in mm and feeds in mm/min unless an option says otherwise.
    """


@cli.command()
@click.argument("drawing", metavar="DRAWING")
@click.option(
    "--target",
    "-t",
    required=True,
    metavar="NAME",
    help="Machine and dialect to write for (see `camtool targets`), or a target .toml file.",
)
@click.option(
    "-o",
    "--output",
    default="-",
    metavar="FILE",
    help="Where to write the program; '-' (default) is stdout.",
)
@JOB
@post_options
@MACHINE
@import_options
@click.option("--verify", "verify_too", is_flag=True, help="Verify the emitted code (see verify).")
@_verify_outputs
@publishes
def post(
    drawing: str,
    target: str,
    output: str,
    job_file: Path | None,
    machine_file: Path | None,
    verify_too: bool,
    report: str | None,
    preview: str | None,
    max_error_um: float | None,
    strict: bool,
    no_budget: bool,
    **options: Any,
) -> None:
    """Import DRAWING (.dxf, .svg, .svgz, a point list), plan it, write it for a target.

    DRAWING may also be an existing G-code program (.ngc, .nc, .gcode, .tap ...):
    it is already a toolpath, so it is re-posted as it is, only --feed applies.
    '-' reads a drawing from stdin, its kind told by its content.

    With --verify (implied by --report, --preview or --max-error-um) the written
    code is read back and simulated on the target's machine, as `verify` does.

    A job still running after 2 s says on stderr what it is doing, a line per stage.
    """
    from camtool.cli.progress import StageReporter
    from camtool.jobs.inputs import STDIN, drawing_kind, is_program_file
    from camtool.jobs.output import check_paths
    from camtool.jobs.pipeline import (
        load_target_checked,
        post_bytes,
        post_path,
        refuse_planning,
        verify_job,
    )
    from camtool.model.progress import Step
    from camtool.toolpath.options import drawing_only

    check_paths(
        [("the input", drawing), ("the --job file", job_file)],
        [("-o", output), ("--report", report), ("--preview", preview)],
        target=target,
        machine_file=machine_file,
    )
    _check_preview(preview)
    chosen = load_target_checked(target, machine_file=machine_file)
    output_options = output_settings(options)
    chosen.post.check_format(output_options.fmt)
    settings = import_settings(options)
    if drawing != "-" and is_program_file(drawing):
        given = drawing_only(options) + (["--job"] if job_file is not None else [])
        refuse_planning(drawing, given)  # before checking them
    refuse_operation_flags(job_file)
    plan = plan_settings(options)
    job_spec = None if job_file is None else read_job(job_file, plan)
    verifying = bool(verify_too or report or preview or max_error_um is not None)
    load_picture = click.get_current_context().with_resource(picture_ahead(preview))
    progress = click.get_current_context().with_resource(StageReporter())
    try:
        if drawing == "-":
            data = sys.stdin.buffer.read()
            kind = drawing_kind(data, "if it is RS-274 G-code, save it as FILE.nc and post that")
            job = post_bytes(
                data,
                STDIN,
                chosen,
                plan,
                output_options,
                import_options=settings,
                job=job_spec,
                kind=kind,
                progress=progress,
            )
        else:
            job = post_path(
                drawing,
                chosen,
                plan,
                output_options,
                import_options=settings,
                progress=progress,
                verifying=verifying,
                job=job_spec,
            )
    finally:
        progress.close()
    warn(job.warnings)
    if job.plan is not None:
        for line in job.plan.notes():
            click.echo(f"camtool: {line}", err=True)
    if isinstance(job.result.code, bytes) and output == "-" and sys.stdout.isatty():
        raise UsageError(
            f"{chosen.name} writes binary code: give -o FILE{chosen.post.suffix} or "
            "pipe stdout (or choose a text --format)"
        )
    if job.pieces:
        _write_pieces(job, output, [("the input", drawing), ("the --job file", job_file)])
    else:
        write_output(job.result.code, output)
        _earlier_pieces(output, [])
    if output != "-" and not job.pieces:
        say_written(f"camtool: wrote {job.result.blocks} blocks for {chosen.name} to {output}")
    if verifying:
        progress(Step("verifying", 0, job.result.blocks, chosen.name))
        load_picture()  # matplotlib, on the core the verification's start leaves idle
        verified = verify_job(job, budget=not no_budget, budget_now=progress, progress=progress)
        _measure_budget(verified, progress)
        _finish_verification(
            verified,
            report,
            preview,
            max_error_um,
            drawing=job.placed,
            edge_radius_mm=job.edge_radius_mm,
            plan=job.plan,
            strict=strict,
            said=job.warnings,
            job=job,
        )


@cli.command()
@click.argument("code", metavar="CODE")
@click.option(
    "--target", "-t", required=True, metavar="NAME", help="The target CODE was written for."
)
@click.option(
    "--against",
    metavar="DRAWING",
    default=None,
    help="Compare the machined edge with this drawing (same coordinates as the code).",
)
@click.option(
    "--tool-diameter",
    type=number_range(min=0, max=MAX_TOOL_DIAMETER_MM),
    default=0.0,
    show_default=True,
    metavar="MM",
    help="Tool diameter; the machined edge is the simulated path swept by half of it.",
)
@MACHINE
@_verify_outputs
@publishes
def verify(
    code: str,
    target: str,
    against: str | None,
    tool_diameter: float,
    machine_file: Path | None,
    report: str | None,
    preview: str | None,
    max_error_um: float | None,
    strict: bool,
    no_budget: bool,
) -> None:
    """Read CODE (a program file, or '-' for stdin) back and predict the machined error.

    The code is parsed with the target's reader, turned into motor steps, run
    through the machine's own interpolator, backlash and compensation, and the
    simulated tool path is measured against the programmed one (and the drawing).
    A one-screen summary goes to stderr.
    """
    from camtool.cli.progress import StageReporter
    from camtool.jobs.inputs import check_not_drawing, read_code, read_input
    from camtool.jobs.output import check_paths
    from camtool.jobs.pipeline import load_target_checked
    from camtool.link.plan import controller_refusal
    from camtool.model.progress import Step
    from camtool.verify.verifier import verify_code

    check_paths(
        [("the program", code), ("the --against drawing", against)],
        [("--report", report), ("--preview", preview)],
        target=target,
        machine_file=machine_file,
    )
    _check_preview(preview)
    chosen = load_target_checked(target, machine_file=machine_file)
    check_not_drawing(code, chosen, "verify PROGRAM, with --against {name} to compare")
    text = read_code(code, binary=chosen.post.binary)
    drawing = read_input(against) if against is not None else None
    if drawing is not None:
        warn([f"--against: {w}" for w in drawing.warnings])  # what the comparison rests on
    skipped = None
    if drawing is not None and isinstance(text, str):
        skipped = _job_not_compared(text, chosen.name)
        if skipped is None:
            drawing, tool_diameter = _as_posted(text, drawing, tool_diameter)
        else:
            drawing = None
    progress = click.get_current_context().with_resource(StageReporter())
    load_picture = click.get_current_context().with_resource(picture_ahead(preview))
    load_picture()  # matplotlib, on the core the verification's start leaves idle
    progress(Step("verifying", 0, 0, chosen.name))
    v = verify_code(
        text,
        chosen,
        source=code,
        against=drawing,
        tool_diameter=tool_diameter,
        budget=not no_budget,
        budget_now=progress,
        progress=progress,
    )
    if skipped is not None:
        v = dataclasses.replace(v, against_skipped=skipped, warnings=(*v.warnings, skipped))
    _measure_budget(v, progress)
    refused = controller_refusal(text, chosen, code)
    if refused is not None:  # the program verifies, and the controller would stop at it
        said = f"{refused}; camtool send refuses the program, sending nothing"
        v = dataclasses.replace(v, warnings=(*v.warnings, said))
    _finish_verification(
        v,
        report,
        preview,
        max_error_um,
        drawing=drawing,
        edge_radius_mm=tool_diameter / 2.0,
        strict=strict,
    )


def _job_not_compared(code: str, target: str) -> str | None:
    """Why the --against drawing of a job's program is not compared (``None``: not a job's).

    Each operation of a job file cuts what its selection keeps with its own tool; the
    program records neither, so the distance of its cuts to the whole drawing (centre lines
    and construction included, at the tool centre) would be read as machining error.
    ``post --job --verify`` compares each operation with what it cuts.
    """
    from camtool.jobs.header import read_job

    job = read_job(code)
    if job is None:
        return None
    name, count = job
    operations = f"{count} operation{'s' if count != 1 else ''}"
    return (
        f"--against: the program is the job {name or 'of the command line'} ({operations}), "
        "each operation cutting what it selects with its own tool, which the program does "
        f"not record; `camtool post DRAWING -t {target} --job {name or 'FILE.toml'} "
        "--verify` compares each with what it cuts; not compared"
    )


def _as_posted(code: str, drawing: Drawing, tool_diameter: float) -> tuple[Drawing, float]:
    """The --against drawing placed, and the tool, as camtool's header in ``code`` records.

    A program camtool posted with ``--fit``/``--scale``/``--origin``/``--translate`` says
    where the drawing went (``placement: scale K, shift X Y mm``); without it the
    drawing would be compared where it was drawn, and the registration mistake reported
    as machining error. An offset cut (``offset outside``, ``inside`` or ``pocket``) cuts
    no open contour: those the planner leaves out (chained at the header's
    ``--chain-tolerance`` and ``--close-gap``, else the defaults,
    :func:`camtool.toolpath.plan.chained`) are not compared. A ``--tool-diameter`` of 0
    takes the header's tool.
    """
    from camtool.jobs.header import read_chaining, read_offset, read_placement
    from camtool.toolpath.options import PlanOptions
    from camtool.toolpath.plan import chained

    placement = read_placement(code)
    if placement is not None:
        k, dx, dy = placement
        drawing = drawing.transformed(k, dx, dy)
        click.echo(
            f"camtool: --against: the drawing placed as the program's header says "
            f"(scale {k:g}, shift X{dx:g} Y{dy:g} mm)",
            err=True,
        )
    drawing = _as_selected(code, drawing)
    offset = read_offset(code)
    if offset is None:
        return drawing, tool_diameter
    side, recorded = offset
    plan = PlanOptions(offset=side, tool_diameter=recorded)
    chaining = read_chaining(code)
    if chaining is not None:  # post's --chain-tolerance and --close-gap
        plan = dataclasses.replace(plan, chain_tolerance=chaining[0], close_gap=chaining[1])
    _, _, left_out, _ = chained(drawing.contours, plan)
    if left_out and len(left_out) < len(drawing.contours):
        drawing = drawing.without(left_out)
        click.echo(
            f"camtool: --against: {len(left_out)} open contour(s) of the drawing not compared: "
            f"the program's header says offset {side}, which cuts only closed contours",
            err=True,
        )
    if tool_diameter == 0:
        click.echo(
            f"camtool: --against: tool diameter {recorded:g} mm, as the program's header "
            "says (give --tool-diameter to change it)",
            err=True,
        )
        return drawing, recorded
    return drawing, tool_diameter


def _as_selected(code: str, drawing: Drawing) -> Drawing:
    """The --against drawing without what ``post`` did not cut: its selection, as recorded.

    ``post``'s one operation cuts the layers ``--layers`` named (the header's ``layers:``
    line), else every layer, and never construction it was not asked for by name (centre
    and hidden lines, dimension layers: :func:`camtool.jobs.selection.construction_reason`).
    A job's program and another tool's have no such header: nothing is left out here. A
    re-posted program has the header of the program it came from
    (:func:`camtool.jobs.header.carried_notes`).

    Raises:
        UsageError: the header names a layer the drawing does not have (another drawing,
            or a name the program's comments could not hold): nothing could be compared
            as it was cut.
    """
    from camtool.jobs.header import read_layers, read_single
    from camtool.jobs.job import Selection
    from camtool.jobs.selection import construction_reason, matches

    if not read_single(code):
        return drawing
    layers = read_layers(code)
    if layers is not None:
        layers, missing = _recorded_layers(layers, {c.layer for c in drawing.contours})
        if missing:
            raise UsageError(
                f"--against: the program's header says it was posted with --layers "
                f"{','.join(layers)}, and the drawing has no layer {missing!r} (its layers: "
                f"{', '.join(sorted({c.layer for c in drawing.contours}))}); give the "
                "drawing the program was posted from, or verify without --against"
            )
    selection = Selection(layers=layers)
    left = frozenset(
        i
        for i, c in enumerate(drawing.contours)
        if not matches(c, selection) or construction_reason(c, selection) is not None
    )
    if left and len(left) < len(drawing.contours):
        why = f"not on its layers {', '.join(layers)}" if layers else "construction"
        click.echo(
            f"camtool: --against: {len(left)} contour(s) of the drawing not compared: "
            f"the program's header says post cut none of them ({why})",
            err=True,
        )
        return drawing.without(left)
    return drawing


def _recorded_layers(recorded: tuple[str, ...], have: set[str]) -> tuple[tuple[str, ...], str]:
    """The drawing's layers among ``have`` that the header's names ``recorded`` stand for.

    A name is as the program's comments hold it (:func:`comment_text`: any case, non-ASCII
    as ``?``, parentheses as brackets; the last one cut short with ``...`` on a long
    line), so each layer is compared in that form. Returns ``(layers, "")``, or
    ``(recorded, name)`` with the first recorded name no layer stands for.
    """
    from camtool.post.wordaddress_spec import comment_text

    held = {layer: comment_text(layer).casefold() for layer in have}
    found: list[str] = []
    for name in recorded:
        key = name.casefold()
        if key.endswith("..."):
            hits = [layer for layer, text in held.items() if text.startswith(key[:-3])]
        else:
            hits = [layer for layer, text in held.items() if text == key]
        if not hits:
            return recorded, name
        found.extend(sorted(hits))
    return tuple(dict.fromkeys(found)), ""


def _write_pieces(job: PostJob, output: str, inputs: list[tuple[str, Any]]) -> None:
    """Write a job split per tool: ``-o part.nc`` → ``part.T1.nc``, ``part.T2.nc``...

    Raises:
        UsageError: the output is stdout (several programs need file names), or a
            piece's file would overwrite an input.
    """
    from camtool.jobs.output import check_outputs

    name = job.target.name
    if output == "-":
        suffix = job.target.post.suffix
        names = ", ".join(piece.path(f"FILE{suffix}") for piece in job.pieces)
        raise UsageError(
            f"{name} cannot change tools, so this program of {len(job.pieces)} tools is "
            f"{len(job.pieces)} programs, one per tool: give -o FILE{suffix} "
            f"(they are written as {names})"
        )
    paths = [piece.path(output) for piece in job.pieces]
    check_outputs(inputs, [("-o", p) for p in paths])
    for piece, path in zip(job.pieces, paths, strict=True):
        write_output(piece.result.code, path)
    _earlier_pieces(output, paths)
    order = ", then ".join(
        f"{p} ({piece.tool})" for piece, p in zip(job.pieces, paths, strict=True)
    )
    zero = "; set Z zero for each tool before its program" if job.target.machine.has_z else ""
    say_written(
        f"camtool: {name} cannot change tools: wrote one program per tool, run {order}{zero}"
    )


def _earlier_pieces(output: str, written: list[str]) -> None:
    """Warn of the programs per tool an earlier run left beside ``-o output`` (not stdout)."""
    from camtool.jobs.by_hand import earlier_pieces

    message = None if output == "-" else earlier_pieces(output, written)
    if message is not None:
        warn([message])


def _check_preview(preview: str | None) -> None:
    """Refuse a ``--preview`` file that is neither ``.png`` nor ``.svg``, before any work.

    Raises:
        UsageError: the ending names no preview format (nothing is written).
    """
    if preview is not None:
        from camtool.preview import preview_format

        preview_format(preview)


def _measure_budget(v: Verification, progress: StageReporter) -> None:
    """Compute ``v``'s error budget now, its sources told to ``progress`` (a long one shows).

    A budget that fails is left to fail where it did before (in the summary), so the
    warnings and the error come out as they always have.
    """
    try:
        v.measure_budget(progress)
    except CamtoolError:
        pass
    finally:
        progress.close()


def _finish_verification(
    v: Verification,
    report: str | None,
    preview: str | None,
    max_error_um: float | None,
    *,
    drawing: Drawing | None = None,
    edge_radius_mm: float = 0.0,
    plan: PlanReport | None = None,
    strict: bool = False,
    said: tuple[str, ...] = (),
    job: PostJob | None = None,
) -> None:
    """Summary to stderr, then the report and preview files, then the limit check.

    The report gets a ``plan`` key (what planning found) when the code was planned here;
    warnings in ``said`` (already printed by ``post``) are not printed again; ``job``: the
    post that made ``v``, whose operations the preview colours.
    The limit judges what was cut as drawn; ``strict`` adds the features the planner
    reported it cannot cut with this tool. A drawing that was given but not compared
    (it does not overlap the program) fails the limit: it cannot pass unjudged.
    """
    from camtool.jobs.pipeline import report_json
    from camtool.verify.report import summary_lines

    warn([w for w in v.warnings if w not in said])
    for line in summary_lines(v):
        click.echo(f"camtool: {line}", err=True)
    if report is not None:
        write_output(report_json(v, plan), report)
    if preview is not None:
        from camtool.preview import render_preview

        runs = job.operations if job is not None and len(job.operations) > 1 else ()
        picture = render_preview(
            preview,
            verification=v,
            drawing=drawing,
            edge_radius_mm=edge_radius_mm,
            # a job's operations in colours: drawn from its plan, where they are numbered
            program=job.program if job is not None and runs else None,
            sections=[(r.label, *r.moves) for r in runs] or None,
        )
        write_output(picture, preview)
    problem = None if max_error_um is None else v.over_limit(max_error_um, strict=strict)
    if problem is not None:
        raise VerifyLimitError(problem)


@cli.command()
@click.argument("drawing", metavar="DRAWING")
@click.option("--json", "as_json", is_flag=True, help="Write the report as JSON.")
@click.option(
    "--tolerance",
    type=NUMBER,
    default=0.001,
    show_default=True,
    metavar="MM",
    help="Curve-fit tolerance, and the limit of the duplicate, overlap and tiny-segment "
    "checks, mm.",
)
@chain_tolerance_option
@import_options
def inspect(drawing: str, as_json: bool, chain_tolerance: float, **options: Any) -> None:
    """Lint DRAWING before cutting (the report goes to stdout).

    Entities and contours by type and layer, bounding box, units, and what a
    machinist must fix: open contours, duplicates, zero-length and tiny segments,
    gaps just above the chaining tolerance, with their locations. Ends are chained
    as ``camtool post`` chains them (same --chain-tolerance).
    """
    from camtool.importers import bytes_as_file
    from camtool.importers.lint import inspect_drawing
    from camtool.jobs.inputs import STDIN, drawing_kind, is_program_file

    settings = import_settings(options)
    if drawing != "-" and is_program_file(drawing):
        raise InputError(
            f"{drawing}: a G-code program; inspect reads drawings. Read a program back with "
            f"`camtool verify {drawing} -t TARGET`, or draw it with `camtool preview {drawing}`"
        )
    if drawing != "-":
        report = inspect_drawing(drawing, settings, chain_tolerance=chain_tolerance)
        click.echo(json.dumps(report.to_json(), indent=2) if as_json else report.text(), nl=as_json)
        return
    data = sys.stdin.buffer.read()
    with bytes_as_file(data, drawing_kind(data), STDIN) as path:
        report = inspect_drawing(path, settings, chain_tolerance=chain_tolerance)
    text = json.dumps(report.to_json(), indent=2) if as_json else report.text()
    click.echo(text.replace(str(path), STDIN).replace(path.name, STDIN), nl=as_json)


@cli.command()
@click.option("--json", "as_json", is_flag=True, help="Write the list as JSON.")
def targets(as_json: bool) -> None:
    """List the targets camtool can write for (built in, then plugins).

    A plugin that fails to load is listed as broken with the reason.
    """
    from camtool.post.registry import list_targets

    rows = list_targets()
    if as_json:
        click.echo(json.dumps([_target_json(e) for e in rows], indent=2, ensure_ascii=False))
        return
    width = max(len(e.name) for e in rows)
    for e in rows:
        if e.target is None:
            click.echo(f"{e.name:<{width}}  BROKEN: {e.error}")
            continue
        line = f"{e.name:<{width}}  {e.target.description}"
        click.echo(line if e.origin == "builtin" else f"{line} [{e.origin}]")


def _target_json(entry: TargetEntry) -> dict[str, Any]:
    """One ``camtool targets --json`` row."""
    t = entry.target
    if t is None:
        return {"name": entry.name, "origin": entry.origin, "broken": entry.error}
    return {
        "name": entry.name,
        "description": t.description,
        "source": t.source,
        "origin": entry.origin,
        "machine": t.machine.name,
        "formats": dict(t.post.formats),
        "has_z": t.machine.has_z,
        "work_area_mm": list(t.machine.work_area_mm),
        "default_feed_mm_min": t.default_feed_mm_min,
    }


cli.add_command(preview)
cli.add_command(batch)
cli.add_command(calibrate)
cli.add_command(send)
cli.add_command(job)
cli.add_command(simulate_device)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; turn every error into a message and an exit code, never a traceback.

    Ctrl-C ends a command with exit code 130, SIGTERM with 143 (:class:`TerminateAsInterrupt`):
    each unwinds it, so a file half written is removed and the output left as it was.
    """
    from camtool.jobs.batch_stop import TerminateAsInterrupt

    try:
        with TerminateAsInterrupt():
            code = cli.main(args=argv, prog_name="camtool", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except click.ClickException as exc:
        exc.show()
        return int(exc.exit_code)
    except click.Abort as exc:
        return _aborted(exc)
    except CamtoolError as exc:
        click.echo(f"camtool: error: {readable(str(exc))}", err=True)
        return exc.exit_code
    except MemoryError as exc:
        click.echo(f"camtool: error: {out_of_memory(exc)}", err=True)
        return 1
    except Exception as exc:  # a bug: still a message, never a traceback
        if _interrupted(exc):
            return _aborted(exc)
        click.echo(
            f"camtool: internal error: {type(exc).__name__}: {exc} (please report it)", err=True
        )
        return 1
    return code if isinstance(code, int) else 0  # a command's ctx.exit(n) returns n here


def _aborted(exc: BaseException) -> int:
    """Say that Ctrl-C (exit code 130) or SIGTERM (143) stopped the command; its exit code."""
    from camtool.jobs.batch_stop import Terminated

    if _interrupted(exc, Terminated):
        click.echo("camtool: stopped (SIGTERM)", err=True)
        return 143
    click.echo("camtool: aborted", err=True)
    return 130


def _interrupted(exc: BaseException, kind: type[BaseException] = KeyboardInterrupt) -> bool:
    """Whether ``exc`` comes of Ctrl-C (a ``kind``, KeyboardInterrupt, in its chain of causes).

    ``kind=Terminated``: whether it comes of SIGTERM.

    A compiled kernel (numba) interrupted mid-call raises ``SystemError: ... returned a
    result with an exception set`` from the KeyboardInterrupt.
    """
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, kind):
            return True
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return False


if __name__ == "__main__":
    sys.exit(main())
