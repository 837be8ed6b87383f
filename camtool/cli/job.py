"""``camtool job``: job files (the operations and tools that make a part)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import click

from camtool.cli.common import (
    MACHINE,
    import_options,
    import_settings,
    number_range,
    say_written,
    warn,
    write_output,
)
from camtool.model.errors import UsageError
from camtool.toolpath.options import MIN_TOOL_DIAMETER_MM


@click.group()
def job() -> None:
    """Job files: the operations and tools that make a part (docs/jobs.md)."""


@job.command("init")
@click.argument("drawing", metavar="DRAWING")
@click.option(
    "-o",
    "--output",
    default="-",
    metavar="JOB.toml",
    help="Where to write the job; '-' (default) is stdout. An existing file (a job you may "
    "have edited) is refused without --force.",
)
@click.option("--force", is_flag=True, help="Replace an existing -o file.")
@click.option(
    "--thickness",
    type=number_range(min=0, min_open=True, max=1000),
    default=3.0,
    show_default=True,
    metavar="MM",
    help="The stock's thickness: profiles cut through it, pockets half way.",
)
@click.option(
    "--tool-diameter",
    type=number_range(min=MIN_TOOL_DIAMETER_MM, max=100),
    default=3.0,
    show_default=True,
    metavar="MM",
    help="The end mill's diameter.",
)
@click.option(
    "--target",
    "-t",
    default=None,
    metavar="NAME",
    help="The machine the job is for: a drawing larger than its travel is scaled to fit "
    "(said in the job).",
)
@MACHINE
@import_options
def init(
    drawing: str,
    output: str,
    force: bool,
    thickness: float,
    tool_diameter: float,
    target: str | None,
    machine_file: Path | None,
    **options: Any,
) -> None:
    """Write a first job for DRAWING: one operation per layer, each guess commented.

    Small circles are drilled, closed contours profiled (outside for the outermost, inside
    for a layer of holes), a layer named for a pocket pocketed; open contours and
    construction (centre lines, construction and dimension layers) are left out.
    """
    from camtool.jobs.init import initial_job
    from camtool.jobs.inputs import read_input
    from camtool.jobs.output import check_paths

    check_paths(
        [("the input", drawing)], [("-o", output)], target=target, machine_file=machine_file
    )
    if output != "-" and os.path.lexists(output) and not force:
        raise UsageError(
            f"-o {output} already exists: a job you may have edited by hand would be replaced; "
            "give another -o, or --force to replace it"
        )
    travel, no_z = None, ""
    if target is not None:
        from camtool.jobs.pipeline import load_target_checked

        machine = load_target_checked(target, machine_file=machine_file).machine
        travel, no_z = machine.travel_mm, ("" if machine.has_z else target)
    drawn = read_input(drawing, import_settings(options))
    warn(list(drawn.warnings))  # what the guesses below rest on (units assumed, skipped)
    text = initial_job(
        drawn, thickness_mm=thickness, tool_diameter=tool_diameter, travel_mm=travel, no_z=no_z
    )
    write_output(text, output)
    if output != "-":
        count = sum(line.startswith("[[operations]]") for line in text.splitlines())
        say_written(
            f"camtool: wrote a job of {count} operation(s) to {output}; read it, then: "
            f"camtool post {drawing} -t TARGET --job {output}"
        )
