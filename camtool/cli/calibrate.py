"""``camtool calibrate``: a coupon to cut and measure, and a fit of the machine profile to it."""

from __future__ import annotations

import os
from pathlib import Path

import click

from camtool.cli.common import MACHINE, number_range, publishes, warn, write_output
from camtool.model.errors import UsageError

TARGET = click.option(
    "--target",
    "-t",
    required=True,
    metavar="NAME",
    help="Machine and dialect (see `camtool targets`), or a target .toml file.",
)


@click.group()
def calibrate() -> None:
    """Calibrate a machine profile: cut a coupon, measure it, fit the profile to it."""


@calibrate.command()
@TARGET
@click.option("-o", "--output", required=True, metavar="FILE", help="The coupon program.")
@click.option(
    "--sheet",
    default=None,
    metavar="FILE",
    help="Where the measurement sheet goes: FILE.md and FILE.csv (default: next to -o).",
)
@click.option(
    "--force",
    is_flag=True,
    help="Replace an existing sheet beside -o (without --sheet) instead of refusing.",
)
@MACHINE
@publishes
def coupon(
    target: str, output: str, sheet: str | None, force: bool, machine_file: Path | None
) -> None:
    """Write a calibration coupon for a target and its measurement sheet (.md and .csv).

    Without --sheet the sheet goes beside -o (part.gcode: part.md and part.csv); an
    existing file of that name is refused without --force, since the command line
    never named it.
    """
    from camtool.calibrate import make_coupon
    from camtool.jobs.output import check_paths
    from camtool.jobs.pipeline import load_target_checked

    if sheet is None and output == "-":
        raise UsageError("-o - writes the coupon to stdout: give --sheet FILE for the sheet")
    stem = Path(sheet if sheet is not None else output).with_suffix("")
    md, csv = f"{stem}.md", f"{stem}.csv"
    check_paths(
        [],
        [("-o", output), ("--sheet", md), ("--sheet", csv)],
        target=target,
        machine_file=machine_file,
    )
    taken = [name for name in (md, csv) if os.path.lexists(name)]
    if sheet is None and taken and not force:
        raise UsageError(
            f"{' and '.join(taken)} already exist beside -o {output}: the sheet would replace "
            "them; give --sheet FILE for another name, or --force to replace them"
        )
    files = make_coupon(
        load_target_checked(target, machine_file=machine_file),
        code_name=Path(output).name if output != "-" else "the coupon program",
        csv_name=Path(csv).name,
    )
    warn(list(files.warnings))
    write_output(files.code, output)
    write_output(files.markdown, md)
    write_output(files.csv, csv)
    click.echo(
        f"camtool: coupon of {len(files.coupon.features)} features, "
        f"{len(files.coupon.measures)} measures; sheet {md}, {csv}",
        err=True,
    )


@calibrate.command()
@TARGET
@click.argument("measured", metavar="MEASURED.csv")
@click.option("-o", "--output", required=True, metavar="M.toml", help="The --machine overlay.")
@click.option(
    "--hold",
    multiple=True,
    type=click.Choice(["steps", "backlash"]),
    help="Keep the profile's steps/mm or backlash instead of fitting it (repeatable).",
)
@click.option(
    "--max-correction",
    type=number_range(min=0, max=1000, min_open=True),
    default=20.0,
    show_default=True,
    metavar="PCT",
    help="Refuse a steps/mm correction larger than this, %.",
)
@MACHINE
@publishes
def fit(
    target: str,
    measured: str,
    output: str,
    hold: tuple[str, ...],
    max_correction: float,
    machine_file: Path | None,
) -> None:
    """Fit the target's profile to a filled-in sheet; write a --machine overlay.

    What the sheet cannot determine is refused, naming the rows to measure, unless
    --hold keeps the profile's value; the steps/mm settings to change are printed.
    """
    from camtool.calibrate import fit_sheet
    from camtool.calibrate.fit import overlay_toml, summary_lines
    from camtool.calibrate.sheet import read_sheet
    from camtool.jobs.output import check_paths
    from camtool.jobs.pipeline import load_target_checked

    check_paths(
        [("the sheet", measured)], [("-o", output)], target=target, machine_file=machine_file
    )
    text = read_sheet(measured)
    chosen = load_target_checked(target, machine_file=machine_file)
    result = fit_sheet(
        chosen, text, source=measured, hold=hold, max_correction=max_correction / 100
    )
    for line in summary_lines(result):
        click.echo(line, err=True)
    write_output(overlay_toml(result, source=Path(measured).name), output)
