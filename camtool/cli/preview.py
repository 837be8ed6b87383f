"""``camtool preview``: draw a drawing, a program, or a program over a drawing (SVG or PNG).

INPUT is read by its ending: a drawing (``.dxf .svg .csv .txt .xy .m``), or a
program (:func:`camtool.jobs.inputs.preview_inputs`). A program is read with the
``--target``'s own reader when its ending is one that target writes or is not a
G-code ending (``logo.pic``), else a G-code file (``.ngc .nc .gcode .tap ...``)
goes through the G-code importer (no target needed). ``-`` reads code in the
target's dialect from stdin.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from camtool.cli.common import (
    MACHINE,
    import_options,
    import_settings,
    number_range,
    picture_ahead,
    publishes,
    say_written,
    warn,
    write_output,
)
from camtool.model.errors import UsageError
from camtool.toolpath.options import MAX_TOOL_DIAMETER_MM

if TYPE_CHECKING:
    from camtool.model.program import Program
    from camtool.model.shapes import Drawing
    from camtool.post.base import Target
    from camtool.verify.verifier import Verification


@click.command()
@click.argument("input_name", metavar="INPUT")
@click.option(
    "-o",
    "--output",
    default=None,
    metavar="P.svg|P.png|-",
    help="Picture to write; the ending picks SVG or PNG, '-' writes SVG to stdout "
    "[default: INPUT's name with .preview.svg, beside it].",
)
@click.option("--target", "-t", default=None, metavar="NAME", help="The machine and dialect.")
@click.option(
    "--program",
    "program_name",
    default=None,
    metavar="CODE",
    help="A program to draw over the drawing INPUT (same coordinates).",
)
@click.option("--verify", "verify_too", is_flag=True, help="Simulate the program on the target.")
@MACHINE
@click.option(
    "--tool-diameter",
    type=number_range(min=0, max=MAX_TOOL_DIAMETER_MM),
    default=0.0,
    metavar="MM",
    help="Draw the tool width along the cuts (and sweep the trace with it for --verify).",
)
@click.option("--title", default=None, metavar="TEXT", help="First title line [default: INPUT].")
@import_options
@publishes
def preview(
    input_name: str,
    output: str | None,
    target: str | None,
    program_name: str | None,
    verify_too: bool,
    machine_file: Path | None,
    tool_diameter: float,
    title: str | None,
    **options: Any,
) -> None:
    """Draw INPUT (a drawing or a program) as a picture a person can check before cutting.

    Cuts in blue, rapids dashed yellow, each contour's start, direction and
    order, the tool width, the target's work area, a scale bar and a title with
    the part size and the estimated time. With --verify the program is simulated
    on the target and the picture adds the tool-centre trace coloured by its
    deviation in µm, the worst point and a zoom inset on it.
    """
    from camtool.cli.progress import StageReporter
    from camtool.jobs.inputs import default_preview_path, preview_inputs
    from camtool.jobs.output import check_paths
    from camtool.model.progress import Step
    from camtool.preview import preview_format, render_preview

    out = output or default_preview_path(input_name)
    preview_format(".svg" if out == "-" else out)
    check_paths(
        [("the input", input_name), ("the --program", program_name)],
        [("-o", out)],
        target=target,
        machine_file=machine_file,
    )
    load_picture = click.get_current_context().with_resource(picture_ahead(out))
    load_picture()  # matplotlib loads while this process reads the inputs
    chosen = _target(target, machine_file)
    progress = click.get_current_context().with_resource(StageReporter())
    progress(Step("reading", name=Path(program_name or input_name).name))
    drawing, program = preview_inputs(input_name, program_name, chosen, import_settings(options))
    said = [
        *(drawing.warnings if drawing is not None else ()),
        *(program.warnings if program else ()),
    ]
    warn(list(dict.fromkeys(said)))  # what the picture rests on (units assumed, skipped)
    verification = (
        _verify(program, drawing, chosen, tool_diameter, program_name or input_name, said)
        if verify_too
        else None
    )
    shown = title or (f"{program_name} over {input_name}" if program_name else input_name)
    data = render_preview(
        ".svg" if out == "-" else out,
        program=program,
        drawing=drawing,
        verification=verification,
        target=chosen,
        edge_radius_mm=tool_diameter / 2.0,
        title=shown,
        progress=progress,
    )
    progress.close()
    write_output(data, out)
    if out != "-":
        say_written(f"camtool: wrote preview {out}")


def _target(name: str | None, machine_file: Path | None) -> Target | None:
    if name is None:
        if machine_file is not None:
            raise UsageError("--machine needs --target (the profile is laid over the target's)")
        return None
    from camtool.jobs.pipeline import load_target_checked

    return load_target_checked(name, machine_file=machine_file)


def _verify(
    program: Program | None,
    drawing: Drawing | None,
    target: Target | None,
    tool_diameter: float,
    source: str,
    said: list[str],
) -> Verification:
    """The program simulated on ``target``; its warnings printed but for those ``said``."""
    if target is None or program is None:
        raise UsageError(
            "--verify simulates a program on a machine: give a program (INPUT or --program) "
            "and --target NAME"
        )
    from camtool.verify.verifier import verify_program

    v = verify_program(
        program,
        target.machine,
        name=target.name,
        against=drawing,
        tool_diameter=tool_diameter,
        source=source,
    )
    warn([w for w in v.warnings if w not in said])
    click.echo(
        f"camtool: verified on {target.name}: max deviation {v.deviation.max_um:.2f} µm, "
        f"≈ {v.time_s:.1f} s",
        err=True,
    )
    return v
